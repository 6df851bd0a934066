//! Tangents of every joint element (multiplier terms included) against
//! central finite differences of their residuals, on random
//! configurations: rotations of each node up to about 1 rad away from the
//! reference, positions moved by up to 0.3 (model size ~1), random
//! multipliers and scalings. Tolerance 1e-6 of the largest tangent entry
//! (h = 1e-6: truncation ~1e-12·|third derivative|, round-off ~1e-10).

use super::latch::SpringLatch;
use super::types::{Coordinate, JointParameters, SliderCurve};
use super::*;
use crate::elements::testing::{eval, rate_errors, scaled_tangent_error, tangent_error};
use crate::elements::{ConstraintScaling, Element, EvalContext};
use crate::so3::{self, Mat3, Rotation, Vec3};
use crate::state::State;

/// Deterministic pseudo-random numbers in [−1, 1], for the tests of the
/// joints.
pub(super) struct Lcg(pub(super) u64);
impl Lcg {
    pub(super) fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    pub(super) fn vec(&mut self, s: f64) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next()) * s
    }
}

fn ctx() -> EvalContext<'static> {
    EvalContext {
        time: 0.4,
        curves: &[],
        gravity: Vec3::zeros(),
        need: crate::elements::Need::STIFFNESS,
        dynamics: false,
        scaling: ConstraintScaling {
            force: (3.0, 2.0),
            moment: (5.0, 1.5),
            rate_time: 1.0,
        },
    }
}

/// Reference frames of two nodes and a joint triad.
fn reference(rng: &mut Lcg) -> (Vec<Vec3>, Vec<Rotation>, Mat3, Vec3) {
    let x = vec![rng.vec(1.0), rng.vec(1.0)];
    let q = vec![so3::exp(&rng.vec(2.0)), so3::exp(&rng.vec(2.0))];
    let e = so3::matrix(&so3::exp(&rng.vec(2.0)));
    (x, q, e, rng.vec(1.0))
}

/// A state of `e`'s nodes moved away from the reference, with random
/// coordinates, multipliers and internal variables.
fn moved(rng: &mut Lcg, x: &[Vec3], q: &[Rotation], e: &dyn Element) -> State {
    let x = x.iter().map(|x| x + rng.vec(0.3)).collect();
    let q = q.iter().map(|q| q * so3::exp(&rng.vec(0.6))).collect();
    let mut s = State::at_rest(0.4, x, q).with_unknowns(
        (0..e.n_coordinates()).map(|_| rng.next()).collect(),
        e.n_multipliers(),
        0,
    );
    s.multipliers.iter_mut().for_each(|v| *v = rng.next());
    s.internal = (0..e.n_internal()).map(|_| 0.2 * rng.next()).collect();
    s
}

fn check(e: &dyn Element, s: &State, what: &str) -> f64 {
    let err = tangent_error(e, &ctx(), s, 1e-6);
    assert!(err < 1e-6, "{what}: tangent error {err:.3e}");
    err
}

const TYPES: [JointType; 9] = [
    JointType::Revolute,
    JointType::Prismatic,
    JointType::Cylindrical,
    JointType::Spherical,
    JointType::Planar,
    JointType::Universal,
    JointType::Helical,
    JointType::Rigid,
    JointType::Glue,
];

#[test]
fn joint_tangents_match_finite_differences() {
    let mut rng = Lcg(7);
    let mut worst = 0.0f64;
    for t in TYPES {
        for grounded in [false, true] {
            if grounded && matches!(t, JointType::Rigid | JointType::Glue) {
                continue;
            }
            for _ in 0..16 {
                let (x, q, e, p) = reference(&mut rng);
                let ra = so3::matrix(&q[0]);
                let rb = so3::matrix(&q[1]);
                let b = (!grounded).then_some((&x[1], &rb));
                let pair = Pair::from_reference(&p, &e, (&x[0], &ra), b);
                let params = JointParameters {
                    lead: 0.05,
                    lock_rotations: true,
                    curve: None,
                };
                let j = Joint::new(1, t, 0, (!grounded).then_some(1), pair, params);
                let nn = if grounded { 1 } else { 2 };
                let s = moved(&mut rng, &x[..nn], &q[..nn], &j);
                let err = tangent_error(&j, &ctx(), &s, 1e-6);
                // entry by entry too, against the scale of its row and
                // column (measured at most 1.5e-9): the multiplier rows
                // and the geometric terms λ ∂B/∂q are far smaller than
                // the penalty p BᵀB
                let scaled = scaled_tangent_error(&j, &ctx(), &s, 1e-6);
                assert!(
                    scaled < 1e-6,
                    "{} (grounded {grounded}): entry-wise tangent error {scaled:.3e}",
                    t.name()
                );
                worst = worst.max(err);
                assert!(
                    err < 1e-6,
                    "{} (grounded {grounded}): tangent error {err:.3e}",
                    t.name()
                );
            }
        }
    }
    println!("worst joint tangent error {worst:.2e}");
}

#[test]
fn slider_tangents_match_finite_differences() {
    let mut rng = Lcg(11);
    let mut worst = 0.0f64;
    for spline in [false, true] {
        for _ in 0..16 {
            // a wavy curve of 5 nodes along x, the sliding node near it
            let mut x: Vec<Vec3> = (0..5)
                .map(|k| Vec3::new(k as f64 * 0.5, 0.2 * (k as f64).sin(), 0.0) + rng.vec(0.05))
                .collect();
            x.insert(0, Vec3::new(0.9, 0.1, 0.0));
            let q: Vec<Rotation> = (0..6).map(|_| so3::exp(&rng.vec(1.0))).collect();
            let a = rng.vec(0.1);
            let j = Joint::slider(2, 0, a, &[1, 2, 3, 4, 5], spline, 0.9);
            let mut s = moved(&mut rng, &x, &q, &j);
            // s inside the curve, away from the nodes' parameters
            s.coordinates[0] = 0.3 + 1.3 * (0.5 + 0.5 * rng.next());
            worst = worst.max(check(&j, &s, &format!("slider (spline {spline})")));
        }
    }
    println!("worst slider tangent error {worst:.2e}");
}

fn revolute_coordinate(
    rng: &mut Lcg,
    grounded: bool,
    c: Coordinate,
) -> (PairCoordinate, Vec<Vec3>, Vec<Rotation>) {
    let (x, q, e, p) = reference(rng);
    let ra = so3::matrix(&q[0]);
    let rb = so3::matrix(&q[1]);
    let b = (!grounded).then_some((&x[1], &rb));
    let nodes = if grounded { vec![0] } else { vec![0, 1] };
    (
        PairCoordinate {
            nodes,
            pair: Pair::from_reference(&p, &e, (&x[0], &ra), b),
            coordinate: c,
        },
        x,
        q,
    )
}

#[test]
fn driver_and_spring_tangents_match_finite_differences() {
    let mut rng = Lcg(5);
    let curves = [crate::curves::Curve::ramp()];
    let ctx = EvalContext {
        curves: &curves,
        ..ctx()
    };
    let coords = [
        Coordinate::Angle,
        Coordinate::Slide1,
        Coordinate::Slide3,
        Coordinate::Cardan1,
        Coordinate::Cardan2,
    ];
    let mut worst = 0.0f64;
    for c in coords {
        for grounded in [false, true] {
            for _ in 0..8 {
                let (src, x, q) = revolute_coordinate(&mut rng, grounded, c);
                let nn = src.nodes.len();
                let d = Driver::new(3, src.clone(), 0.7, 0);
                let s = moved(&mut rng, &x[..nn], &q[..nn], &d);
                let err = tangent_error(&d, &ctx, &s, 1e-6);
                assert!(err < 1e-6, "driver on {}: {err:.3e}", c.name());
                worst = worst.max(err);

                let table = Law::Table(vec![(-2.0, -3.0), (-0.1, -0.5), (0.3, 0.2), (2.0, 4.0)]);
                for law in [Law::Linear { k: 2.5, x0: 0.1 }, table] {
                    let sp = JointSpring::new(
                        4,
                        src.clone(),
                        Some(law),
                        Some(Law::Linear { k: 0.7, x0: 0.0 }),
                    );
                    let mut s = moved(&mut rng, &x[..nn], &q[..nn], &sp);
                    // nodes moving and spinning: the damper contributes too
                    s.velocity = (0..nn)
                        .map(|_| std::array::from_fn(|k| 30.0 * rng.next() + 10.0 * (k as f64)))
                        .collect();
                    s.acceleration = (0..nn)
                        .map(|_| std::array::from_fn(|_| 100.0 * rng.next()))
                        .collect();
                    let err = tangent_error(&sp, &ctx, &s, 1e-6);
                    assert!(err < 1e-6, "spring on {}: {err:.3e}", c.name());
                    worst = worst.max(err);
                    // in dynamics: the damper's force in the residual, its
                    // rate terms in the stiffness, ∂r/∂v = f_d' g gᵀ in the
                    // inertia matrix (steps 1e-3 in v and v̇: the residual
                    // is linear in v with a linear damping law)
                    let dynamic = EvalContext {
                        dynamics: true,
                        ..ctx
                    };
                    let err = tangent_error(&sp, &dynamic, &s, 1e-6);
                    let (ev, ea) = rate_errors(&sp, &dynamic, &s, 1e-3, 1e-3);
                    assert!(err < 1e-6, "spring-damper on {}: ∂r/∂q {err:.3e}", c.name());
                    assert!(ev < 1e-6, "spring-damper on {}: ∂r/∂v {ev:.3e}", c.name());
                    assert!(ea < 1e-6, "spring-damper on {}: ∂r/∂v̇ {ea:.3e}", c.name());
                    worst = worst.max(err).max(ev);
                }
            }
        }
    }
    println!("worst driver and joint-spring tangent error {worst:.2e}");
}

/// A latch, open (`kλ = 0`) and locked (`Φ = c − c_L`): its tangent, and
/// the gradient `B` of its coordinate that the impact uses, against
/// central differences (h = 1e-6; 1e-6 of the largest entry, as above).
#[test]
fn latch_tangents_and_gradient_match_finite_differences() {
    let mut rng = Lcg(11);
    let coords = [Coordinate::Angle, Coordinate::Slide1, Coordinate::Slide3];
    let mut worst = 0.0f64;
    for c in coords {
        for grounded in [false, true] {
            for _ in 0..8 {
                let (src, x, q) = revolute_coordinate(&mut rng, grounded, c);
                let nn = src.nodes.len();
                let latch = Latch::new(5, 1, src, 0.3, -1.0);
                let mut s = moved(&mut rng, &x[..nn], &q[..nn], &latch);
                let flag = latch.n_internal() - 1;
                for locked in [0.0, 1.0] {
                    s.internal[flag] = locked;
                    assert_eq!(latch.is_locked(&s), locked > 0.5);
                    let err = tangent_error(&latch, &ctx(), &s, 1e-6);
                    assert!(err < 1e-6, "latch on {} ({locked}): {err:.3e}", c.name());
                    worst = worst.max(err);
                }
                // B: ∂c/∂q along each local unknown; ċ = B v
                let (_, grad) = latch.rate(&s);
                let h = 1e-6;
                let largest = grad.iter().fold(1e-300f64, |a, g| a.max(g.abs()));
                for (k, g) in grad.iter().enumerate() {
                    let cp = latch.coordinate(&crate::elements::testing::moved(&s, &latch, k, h));
                    let cm = latch.coordinate(&crate::elements::testing::moved(&s, &latch, k, -h));
                    let fd = (cp - cm) / (2.0 * h);
                    assert!(
                        (fd - g).abs() < 1e-6 * largest,
                        "{}: ∂c/∂q{k} {g} vs {fd}",
                        c.name()
                    );
                    worst = worst.max((fd - g).abs() / largest);
                }
                assert!((latch.gap(&s) + (latch.coordinate(&s) - 0.3)).abs() < 1e-15);
            }
        }
    }
    println!("worst latch tangent and gradient error {worst:.2e}");
}

/// A spring latch, latched, on each branch of its law (within its dead
/// band, beyond either edge; and without backlash), with its dashpot: the
/// stiffness against central differences of the residual in `q` (with
/// the dashpot's rate terms in dynamics), `∂r/∂v = d g gᵀ` against
/// differences in the velocities (h = 1e-6 in q, 1e-3 in v: the residual
/// is linear in v; 1e-6 of the largest entry, as above). The points stay
/// 0.05 or more from the corners of the law, beyond the reach of the
/// differences. Released, it applies nothing.
#[test]
fn spring_latch_tangents_match_finite_differences_on_each_branch() {
    let mut rng = Lcg(17);
    let coords = [Coordinate::Angle, Coordinate::Slide1, Coordinate::Cardan2];
    let dynamic = EvalContext {
        dynamics: true,
        ..ctx()
    };
    let mut worst = 0.0f64;
    for c in coords {
        for grounded in [false, true] {
            for _ in 0..4 {
                let (src, x, q) = revolute_coordinate(&mut rng, grounded, c);
                let nn = src.nodes.len();
                // one-sided (acting where `acts · x > 0`) on its side and on
                // the free one
                for (backlash, offset, side, acts) in [
                    (0.2, 0.05, 0.0, None),
                    (0.2, 0.35, 1.0, None),
                    (0.2, -0.4, -1.0, None),
                    (0.0, 0.3, 1.0, None),
                    (0.0, -0.2, -1.0, None),
                    (0.2, 0.35, 1.0, Some(1.0)),
                    (0.2, -0.4, 0.0, Some(1.0)),
                    (0.0, -0.2, -1.0, Some(-1.0)),
                    (0.0, 0.3, 0.0, Some(-1.0)),
                ] {
                    let spring = SpringLatch {
                        stiffness: 3.0,
                        backlash,
                        damping: 0.7,
                        unlatch_load: Some(5.0),
                        side: acts,
                    };
                    let probe = Latch::new(5, 1, src.clone(), 0.0, 1.0).with_spring(spring);
                    let mut s = moved(&mut rng, &x[..nn], &q[..nn], &probe);
                    s.velocity = (0..nn)
                        .map(|_| std::array::from_fn(|k| 30.0 * rng.next() + 10.0 * (k as f64)))
                        .collect();
                    s.internal.iter_mut().skip(1).for_each(|v| *v = 0.0);
                    // c_L so that c − c_L = offset
                    let value = probe.coordinate(&s) - offset;
                    let latch = Latch::new(5, 1, src.clone(), value, 1.0).with_spring(spring);
                    assert_eq!(latch.n_multipliers(), 0);
                    let (_, r) = eval(&latch, &ctx(), &s);
                    assert!(r.iter().all(|&v| v == 0.0), "released: no stiffness");
                    latch.lock(&mut s);
                    let (xc, _, f) = latch.spring_state(&s);
                    assert!((xc - offset).abs() < 1e-12);
                    let (fs, _) = spring.spring_force(offset);
                    assert_eq!(fs == 0.0, side == 0.0);
                    let mut res = [0.0; 5];
                    latch.results(&ctx(), &s, &mut res);
                    assert_eq!((res[1], res[4]), (1.0, side));
                    assert_eq!(res[3], -f);
                    for (what, cx) in [("statics", ctx()), ("dynamics", dynamic)] {
                        let err = tangent_error(&latch, &cx, &s, 1e-6);
                        assert!(
                            err < 1e-6,
                            "spring latch on {} at x = {offset} ({what}): {err:.3e}",
                            c.name()
                        );
                        worst = worst.max(err);
                    }
                    let (ev, _) = rate_errors(&latch, &dynamic, &s, 1e-3, 1e-3);
                    assert!(ev < 1e-6, "spring latch on {}: ∂r/∂v {ev:.3e}", c.name());
                    worst = worst.max(ev);
                }
            }
        }
    }
    println!("worst spring-latch tangent error {worst:.2e}");
}

/// A node driver measures the node's own motion along a fixed direction.
#[test]
fn node_driver_coordinate_is_the_displacement_along_its_direction() {
    let x = Vec3::new(1.0, 2.0, 3.0);
    let r = so3::matrix(&so3::exp(&Vec3::new(0.3, -0.2, 0.5)));
    let dir = Vec3::new(0.0, 0.6, 0.8);
    let e = Mat3::from_columns(&[Vec3::x(), dir.cross(&Vec3::x()), dir]);
    let src = PairCoordinate {
        nodes: vec![0],
        pair: Pair::node_to_ground(&x, &r, &e),
        coordinate: Coordinate::Slide3,
    };
    let s = State::at_rest(
        0.0,
        vec![x + Vec3::new(0.5, 1.0, -2.0)],
        vec![so3::from_matrix(&r) * so3::exp(&Vec3::new(0.4, 0.1, 0.0))],
    );
    assert!((src.value(&s, 0.0) - (0.6 - 1.6)).abs() < 1e-14);
    // rotation about dir by 0.3 rad (applied in the global frame)
    let rot = PairCoordinate {
        coordinate: Coordinate::Angle,
        ..src
    };
    let s = State::at_rest(
        0.0,
        vec![x],
        vec![so3::exp(&(dir * 0.3)) * so3::from_matrix(&r)],
    );
    assert!((rot.value(&s, 0.0) - 0.3).abs() < 1e-14);
    let _ = eval;
    let _ = SliderCurve { spline: true };
}

/// The gap `g`, its gradient `B` against central differences, and the
/// tangent of a stop or contact, open (`kλ = 0`) and closed
/// (`Φ = g − g_c`), against central differences of its residual (h = 1e-6;
/// 1e-6 of the largest entry, as above). Returns the worst error.
fn check_stop(rng: &mut Lcg, stop: &Stop, s: &mut State, what: &str) -> f64 {
    let mut worst = 0.0f64;
    // internal variables after the unwrapped angle: contact, events, load
    // scale, the value held
    let first = usize::from(stop.is_angle());
    s.internal[first + 3] = stop.coordinate(s) + 0.1 * rng.next();
    for contact in [0.0, 1.0, 2.0] {
        s.internal[first] = contact;
        let err = tangent_error(stop, &ctx(), s, 1e-6);
        assert!(err < 1e-6, "{what} ({contact}): tangent error {err:.3e}");
        worst = worst.max(err);
    }
    let (rate, grad) = stop.rate(s);
    let h = 1e-6;
    let largest = grad.iter().fold(1e-300f64, |a, g| a.max(g.abs()));
    let mut from_grad = 0.0;
    for (k, g) in grad.iter().enumerate() {
        let cp = stop.coordinate(&crate::elements::testing::moved(s, stop, k, h));
        let cm = stop.coordinate(&crate::elements::testing::moved(s, stop, k, -h));
        let fd = (cp - cm) / (2.0 * h);
        assert!(
            (fd - g).abs() < 1e-6 * largest,
            "{what}: ∂g/∂q{k} {g} vs {fd}"
        );
        worst = worst.max((fd - g).abs() / largest);
        from_grad += g * s.velocity[stop.pair_nodes()[k / 6]][k % 6];
    }
    // ġ = B v (round-off)
    assert!(
        (rate - from_grad).abs() <= 1e-12 * (1.0 + rate.abs()),
        "{what}"
    );
    worst
}

/// Stops on joint coordinates, and contacts of a sphere with a plane and
/// of two spheres (docs/theory.md §16.5): tangents and gradients against
/// central differences, and the gaps against their definitions.
#[test]
fn stop_and_contact_tangents_match_finite_differences() {
    use super::stop::{Plane, Spheres};
    let mut rng = Lcg(17);
    let mut worst = 0.0f64;
    for c in [Coordinate::Angle, Coordinate::Slide1] {
        for grounded in [false, true] {
            for _ in 0..4 {
                let (src, x, q) = revolute_coordinate(&mut rng, grounded, c);
                let nn = src.nodes.len();
                let stop = Stop::new(5, 1, src, -0.4, 0.3, 0.5);
                let mut s = moved(&mut rng, &x[..nn], &q[..nn], &stop);
                let what = format!("stop on {}", c.name());
                worst = worst.max(check_stop(&mut rng, &stop, &mut s, &what));
            }
        }
    }
    for _ in 0..8 {
        let (x, q, _, p) = reference(&mut rng);
        let normal = rng.vec(1.0).normalize();
        let plane = Plane {
            node: 0,
            normal,
            point: p,
            radius: 0.3 * rng.next().abs(),
        };
        let stop = Stop::on_plane(6, plane, 0.5);
        let mut s = moved(&mut rng, &x[..1], &q[..1], &stop);
        s.velocity[0] = [rng.next(), rng.next(), rng.next(), 0.0, 0.0, 0.0];
        let g = normal.dot(&(s.x[0] - p)) - plane.radius;
        assert!((stop.coordinate(&s) - g).abs() < 1e-15);
        worst = worst.max(check_stop(&mut rng, &stop, &mut s, "plane"));

        let spheres = Spheres {
            nodes: [0, 1],
            radii: [0.1 * rng.next().abs(), 0.2 * rng.next().abs()],
        };
        let stop = Stop::between_spheres(7, spheres, 0.5);
        let mut s = moved(&mut rng, &x, &q, &stop);
        for v in s.velocity.iter_mut() {
            *v = [rng.next(), rng.next(), rng.next(), rng.next(), 0.0, 0.0];
        }
        let g = (s.x[1] - s.x[0]).norm() - spheres.radii[0] - spheres.radii[1];
        assert!((stop.coordinate(&s) - g).abs() < 1e-15);
        worst = worst.max(check_stop(&mut rng, &stop, &mut s, "spheres"));
    }
    println!("worst stop and contact tangent and gradient error {worst:.2e}");
}
