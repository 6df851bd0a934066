//! Unilateral contacts (src/joints/stop.rs, src/analysis/impact.rs,
//! docs/joints.md §6.4, docs/theory.md §16.5): a ball dropped on a plane
//! (the impact law, the loss of each impact, rest in persistent contact
//! without chattering, penetration), a ball dropped on a tilted plane
//! (the normal rate reversed, the tangential velocity kept, then sliding),
//! the release of a contact, two spheres colliding head-on (momentum, the
//! relative rate reversed), the results and events files, and the input
//! errors of `[[contacts]]`.

mod common;

use common::events::{error_of, run};
use unfold::analysis::{ContactInfo, ContactKind, IncrementInfo};
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::so3::Vec3;
use unfold::state::State;

const G: f64 = common::ball::G;
const MASS: f64 = common::ball::MASS;
const RADIUS: f64 = 0.1;

/// The event tolerance of a length in a model of one node (length scale
/// 1 m): 1e-8 m (docs/joints.md §6.3).
const GAP_TOLERANCE: f64 = 1e-8;

/// A ball of radius 0.1 m and mass 2 kg (a rigid body, inertia
/// 2/5 m r²) on the free node 1 at `x`, under gravity −z
/// (tests/common/ball.rs), with the contact `contact` and the tables
/// `extra`.
fn ball(end_time: f64, x: [f64; 3], contact: &str, extra: &str) -> String {
    let j = 0.4 * MASS * RADIUS * RADIUS;
    common::ball::dropped(
        end_time,
        &format!(
            r#"[[nodes]]
id = 1
x = [{}, {}, {}]

[[rigid_bodies]]
id = 1
node = 1
mass = {MASS}
inertia = [{j}, {j}, {j}]

[[contacts]]
id = 30
{contact}"#,
            x[0], x[1], x[2]
        ),
        extra,
    )
}

/// The contact of the model.
fn contact(model: &Model) -> &unfold::joints::Stop {
    model
        .elements
        .iter()
        .find_map(|e| e.as_stop())
        .expect("a contact")
}

/// The contact force `N`, `force` of the contact's results.
fn force(model: &Model, state: &State) -> f64 {
    let ctx = model.context(state.time, unfold::elements::Need::RESIDUAL);
    contact(model).load(&ctx, state)
}

fn translation(s: &State, node: usize) -> Vec3 {
    let v = s.velocity[node];
    Vec3::new(v[0], v[1], v[2])
}

/// The bouncing ball on a plane z = 0 (the sphere's gap is its height
/// minus its radius). Dropped with its lowest point 1 m above the plane,
/// it hits it at t₁ = √(2h/g) with v₀ = √(2gh); each impact returns e
/// times the approach rate (Newton's law, docs/theory.md §16.4) and
/// dissipates (1 − e²) ½ m v⁻² (LK3e; the ball does not spin: the contact
/// force passes through its centre). The rebounds accumulate at
/// t∞ = t₁ + (2 e v₀/g)/(1 − e); once a rebound would be below
/// v_min = √(2 g_tol g) the contact closes and holds the weight.
#[test]
fn a_ball_bounces_on_a_plane_and_comes_to_rest() {
    let e = 0.5;
    let h = 1.0;
    let (model, out, rec) = run(&ball(
        2.0,
        [0.0, 0.0, h + RADIUS],
        &format!(
            "type = \"plane\"\nnode = 1\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nradius = {RADIUS}\nrestitution = {e}"
        ),
        "",
    ));
    let v0 = (2.0 * G * h).sqrt();
    let t1 = (2.0 * h / G).sqrt();
    for c in &rec.contacts {
        eprintln!(
            "{:?} at t = {:.10}: rate {:.6e} -> {:.6e}, energy lost {:.6e}",
            c.kind, c.time, c.rate_before, c.rate_after, c.energy_lost
        );
    }
    eprintln!(
        "{} steps, {} retried to land on the events",
        out.steps, out.event_retries
    );
    let impacts: Vec<&ContactInfo> = rec
        .contacts
        .iter()
        .filter(|c| c.kind == ContactKind::Impact)
        .collect();
    assert!(impacts.len() >= 5, "{}", impacts.len());
    for c in &rec.contacts {
        // events.csv: the contact, no joint
        assert_eq!(c.stop, 30);
        assert_eq!(c.joint, None);
    }
    // the first impact: time and rate of the free fall (1e-6 relative:
    // the integration's error over the fall)
    assert!(
        (impacts[0].time - t1).abs() <= 1e-6 * t1,
        "{}",
        impacts[0].time
    );
    assert!(
        (impacts[0].rate_before + v0).abs() <= 1e-6 * v0,
        "{}",
        impacts[0].rate_before
    );
    for c in &impacts {
        // Newton's impact law: ġ⁺ = −e ġ⁻ (1e-6 relative, as asked of the
        // rebound)
        assert!(
            (c.rate_after + e * c.rate_before).abs() <= 1e-6 * c.rate_before.abs(),
            "{c:?}"
        );
        // the loss (1 − e²) ½ m v⁻² of the approach's kinetic energy, to
        // round-off (1e-10 relative)
        let loss = (1.0 - e * e) * 0.5 * MASS * c.rate_before.powi(2);
        assert!((c.energy_lost - loss).abs() <= 1e-10 * loss, "{c:?}");
        assert!(
            (c.kinetic_energy_drop - loss).abs() <= 1e-10 * loss,
            "{c:?}"
        );
        // landed on the plane within the event tolerance
        assert!(c.coordinate.abs() <= GAP_TOLERANCE, "{c:?}");
        // the impulse pushes the ball up: m (1 + e) |v⁻| (1e-10)
        let p = MASS * (1.0 + e) * c.rate_before.abs();
        assert!((c.impulse - p).abs() <= 1e-10 * p, "{c:?}");
    }
    // rest without chattering: the rebounds stop once they would be
    // slower than v_min or would not rise above g_tol from where the step
    // landed (docs/theory.md §16.4: log(v₀/v_min)/log(1/e) = 13.3, at
    // most 15 events), then one contact and nothing more
    let v_min = (2.0 * GAP_TOLERANCE * G).sqrt();
    assert!(rec.contacts.len() <= 15, "{}", rec.contacts.len());
    let last = rec.contacts.last().unwrap();
    assert_eq!(last.kind, ContactKind::Close);
    let rebound = e * last.rate_before.abs();
    let top = last.coordinate + rebound * rebound / (2.0 * G);
    assert!(rebound <= v_min || top <= GAP_TOLERANCE, "{rebound} {top}");
    // an impact keeps the ball open only with a rebound above both
    for c in &impacts {
        let rebound = c.rate_after;
        assert!(rebound > v_min && c.coordinate + rebound * rebound / (2.0 * G) > GAP_TOLERANCE);
    }
    // it closes at t∞ (the sum of the flights) within the flights cut
    // off: a rebound cut off is below v_cut = √(2 g · 2 g_tol) (a top
    // below g_tol from a landing at −g_tol at worst), and the flights it
    // would have begun last 2 v_cut/(g (1 − e)) ≈ 2.6e-4 s at most
    let t_rest = t1 + 2.0 * e * v0 / G / (1.0 - e);
    let v_cut = (4.0 * G * GAP_TOLERANCE).sqrt();
    let cut = 2.0 * v_cut / (G * (1.0 - e));
    eprintln!("closed at {}, t∞ = {t_rest}, bound {cut:.3e} s", last.time);
    assert!((last.time - t_rest).abs() <= cut, "{} {t_rest}", last.time);
    // penetration: no accepted state below −g_tol (the event tolerance)
    let c = contact(&model);
    let worst = rec
        .steps
        .iter()
        .fold(0.0f64, |m, (_, s)| m.max(-c.coordinate(s)));
    eprintln!("largest penetration {worst:.3e} m");
    assert!(worst <= GAP_TOLERANCE);
    // at rest: the contact force is the weight (1e-8 relative, the
    // constraint's convergence), the ball stays where it closed
    let after: Vec<_> = rec
        .steps
        .iter()
        .filter(|(i, _)| i.time > last.time)
        .collect();
    assert!(after.len() > 10, "{}", after.len());
    for (i, s) in after {
        let n = force(&model, s);
        assert!(
            (n - MASS * G).abs() <= 1e-8 * MASS * G,
            "t = {}: {n}",
            i.time
        );
        assert!(s.velocity[0][2].abs() <= 1e-8, "t = {}", i.time);
        assert!((c.coordinate(s) - last.coordinate).abs() <= 1e-12);
        assert!(c.coordinate(s).abs() <= GAP_TOLERANCE);
    }
    // the energy balance holds through the impacts (1e-6 of m g h)
    assert!(out.energies.balance_error.abs() <= 1e-6 * MASS * G * h);
}

/// A ball dropped from z₀ = 1 m (its centre) on the plane through the
/// origin tilted by α = 30° about x (normal n = (0, −sin α, cos α)),
/// frictionless. It falls vertically through d = z₀ − r/cos α to the
/// plane, v⁻ = (0, 0, −√(2gd)); the impact reverses the normal component
/// times e and keeps the tangential one: v⁺ = v⁻ − (1 + e)(n·v⁻) n
/// (Newton's law with the impulse along n). Its normal motion is then the
/// bouncing ball under g cos α; once the contact closes it slides down
/// the slope with the acceleration g sin α, the contact force m g cos α.
#[test]
fn a_ball_bounces_on_a_tilted_plane_and_slides_down() {
    let (e, alpha, z0) = (0.5, 30f64.to_radians(), 1.0);
    let n = Vec3::new(0.0, -alpha.sin(), alpha.cos());
    let (model, out, rec) = run(&ball(
        1.6,
        [0.0, 0.0, z0],
        &format!(
            "type = \"plane\"\nnode = 1\nnormal = [0.0, {}, {}]\nradius = {RADIUS}\nrestitution = {e}",
            n.y, n.z
        ),
        "",
    ));
    eprintln!(
        "{} events, {} steps; last {:?} at {}",
        rec.contacts.len(),
        out.steps,
        rec.contacts.last().map(|c| c.kind),
        rec.contacts.last().map_or(0.0, |c| c.time)
    );
    let d = z0 - RADIUS / alpha.cos();
    let v_minus = Vec3::new(0.0, 0.0, -(2.0 * G * d).sqrt());
    let first = &rec.contacts[0];
    assert_eq!(first.kind, ContactKind::Impact);
    // the approach rate n·v⁻ (1e-6 relative: the integration of the fall)
    let vn = n.dot(&v_minus);
    assert!(
        (first.rate_before - vn).abs() <= 1e-6 * vn.abs(),
        "{first:?}"
    );
    assert!((first.rate_after + e * first.rate_before).abs() <= 1e-6 * vn.abs());
    // the velocity after the impact (the state recorded at its step),
    // against v⁻ − (1 + e)(n·v⁻) n: 1e-6 of |v⁻|
    let after = &rec
        .steps
        .iter()
        .find(|(i, _)| i.time == first.time)
        .expect("the impact's step")
        .1;
    let v_plus = v_minus - n * ((1.0 + e) * vn);
    let v = translation(after, 0);
    eprintln!("v⁺ = {v:?}, expected {v_plus:?}");
    assert!((v - v_plus).norm() <= 1e-6 * v_minus.norm());
    // the tangential velocity is kept by the impact (frictionless):
    // against the exact one, 1e-6 of |v⁻|
    let tangential = |v: Vec3| v - n * n.dot(&v);
    assert!((tangential(v) - tangential(v_minus)).norm() <= 1e-6 * v_minus.norm());
    // the loss of each impact: (1 − e²) ½ m (n·v⁻)² (1e-10 relative)
    for c in rec
        .contacts
        .iter()
        .filter(|c| c.kind == ContactKind::Impact)
    {
        let loss = (1.0 - e * e) * 0.5 * MASS * c.rate_before.powi(2);
        assert!((c.energy_lost - loss).abs() <= 1e-10 * loss, "{c:?}");
    }
    // at rest on the plane: closed once, no chattering (≤ 15 events)
    let last = rec.contacts.last().unwrap();
    assert_eq!(last.kind, ContactKind::Close);
    assert!(rec.contacts.len() <= 15, "{}", rec.contacts.len());
    let sliding: Vec<&(IncrementInfo, State)> = rec
        .steps
        .iter()
        .filter(|(i, _)| i.time > last.time)
        .collect();
    assert!(sliding.len() > 10);
    let c = contact(&model);
    let down = Vec3::new(0.0, -alpha.cos(), -alpha.sin());
    for w in sliding.windows(2) {
        let ((i0, s0), (i1, s1)) = (w[0], w[1]);
        // the contact force m g cos α: 1e-6 relative (measured: within
        // 7.0e-7, alternating from step to step and decaying as ρ∞ⁿ, the
        // multiplier transient of index-3 integration as the steps double
        // to 0.1 s after the contact closed; its amplitude follows the
        // landing on the closing, whose tolerance is 1e-8 of the model's
        // size, the ball's 0.1 m radius: 1.7e-8 when the size of a
        // one-node model was taken as 1 m); the gap within the event
        // tolerance
        let f = force(&model, s1);
        assert!(
            (f - MASS * G * alpha.cos()).abs() <= 1e-6 * MASS * G,
            "t = {}: {f}",
            i1.time
        );
        assert!(c.coordinate(s1).abs() <= GAP_TOLERANCE);
        // the acceleration down the slope g sin α, from the velocities
        // (1e-6 relative: exact for a constant acceleration up to the
        // round-off of the differences)
        let a = down.dot(&(translation(s1, 0) - translation(s0, 0))) / (i1.time - i0.time);
        assert!(
            (a - G * alpha.sin()).abs() <= 1e-6 * G,
            "t = {}: {a}",
            i1.time
        );
        // no velocity across the plane
        assert!(n.dot(&translation(s1, 0)).abs() <= 1e-8);
    }
    let worst = rec
        .steps
        .iter()
        .fold(0.0f64, |m, (_, s)| m.max(-c.coordinate(s)));
    eprintln!("largest penetration {worst:.3e} m");
    assert!(worst <= GAP_TOLERANCE);
}

/// The ball resting on the plane at the start (closed without impact) is
/// pulled up by a force growing as 2 m g t: the contact force
/// N = m g (1 − 2t) falls to zero at t = 0.5, where the contact opens (a
/// release, located on N = 0 within 1e-6 of the largest force); the ball
/// then rises with z̈ = g (2t − 1): its gap is g (t − ½)³/3.
#[test]
fn a_contact_with_a_plane_is_released_when_its_force_vanishes() {
    let text = ball(
        0.7,
        [0.0, 0.0, RADIUS],
        &format!("type = \"plane\"\nnode = 1\nnormal = [0.0, 0.0, 1.0]\nradius = {RADIUS}"),
        &format!(
            "[[loads]]\nnode = 1\nforce = [0.0, 0.0, {}]\ncurve = \"ramp\"\n",
            2.0 * MASS * G
        ),
    );
    let (model, _, rec) = run(&text);
    assert_eq!(rec.contacts.len(), 1, "{:?}", rec.contacts);
    let c = &rec.contacts[0];
    assert_eq!(c.kind, ContactKind::Release);
    // N is linear in t: located to round-off (1e-9)
    assert!((c.time - 0.5).abs() <= 1e-9, "{}", c.time);
    let contact = contact(&model);
    for (i, s) in rec.steps.iter().filter(|(i, _)| i.time < 0.45) {
        let n = force(&model, s);
        assert!(
            (n - MASS * G * (1.0 - 2.0 * i.time)).abs() <= 1e-6 * MASS * G,
            "t = {}: {n}",
            i.time
        );
        assert!(contact.coordinate(s).abs() <= GAP_TOLERANCE);
    }
    // gap(0.7) = g (0.2)³/3 within the integration's error (1e-3
    // relative, error_tolerance left at its default)
    let s = &rec.steps.last().unwrap().1;
    let gap = G * 0.2f64.powi(3) / 3.0;
    eprintln!("gap(0.7) = {} (closed form {gap})", contact.coordinate(s));
    assert!((contact.coordinate(s) - gap).abs() <= 1e-3 * gap);
}

/// Two spheres on free nodes (rigid bodies, no gravity): A (radius 0.2,
/// mass m_a) at the origin moving at v_a along x, B (radius 0.3, mass m_b)
/// at x = 1 moving at v_b, extra tables `extra`.
fn spheres(end_time: f64, m: [f64; 2], v: [f64; 2], e: f64, extra: &str) -> String {
    format!(
        r#"
[analysis]
type = "dynamic"
end_time = {end_time}
time_step = 0.01

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [1.0, 0.0, 0.0]

[[rigid_bodies]]
id = 1
node = 1
mass = {}
inertia = [0.01, 0.01, 0.01]

[[rigid_bodies]]
id = 2
node = 2
mass = {}
inertia = [0.02, 0.02, 0.02]

[[contacts]]
id = 40
type = "spheres"
nodes = [1, 2]
radii = [0.2, 0.3]
restitution = {e}

[[initial_motion]]
nodes = [1]
velocity = [{}, 0.0, 0.0]

[[initial_motion]]
nodes = [2]
velocity = [{}, 0.0, 0.0]
{extra}
"#,
        m[0], m[1], v[0], v[1]
    )
}

/// Head-on collision: the gap 0.5 closes at 1.5 m/s, so the spheres meet
/// at t = 1/3; the impact reverses the relative rate times e, conserves
/// momentum, v_a⁺ = v_a − (1 + e) m_b/(m_a + m_b) (v_a − v_b) (and
/// symmetrically for B), and dissipates (1 − e²) ½ μ (v_a − v_b)²,
/// μ = m_a m_b/(m_a + m_b), with the impulse μ (1 + e)(v_a − v_b).
#[test]
fn two_spheres_collide_head_on() {
    let (m, v, e) = ([1.0, 3.0], [1.0, -0.5], 0.8);
    let (model, _, rec) = run(&spheres(0.8, m, v, e, ""));
    assert_eq!(rec.contacts.len(), 1, "{:?}", rec.contacts);
    let c = &rec.contacts[0];
    eprintln!("{c:?}");
    assert_eq!(c.kind, ContactKind::Impact);
    assert_eq!((c.stop, c.joint), (40, None));
    let closing = v[0] - v[1];
    // time: within the event tolerance over the speed (1e-8 m / 1.5 m/s)
    assert!((c.time - 0.5 / closing).abs() <= 1e-8, "{}", c.time);
    assert!(c.coordinate.abs() <= GAP_TOLERANCE);
    // the relative rate, exact in free flight (1e-10), reversed times e
    // (1e-10: the impact is linear algebra)
    assert!((c.rate_before + closing).abs() <= 1e-10 * closing);
    assert!((c.rate_after + e * c.rate_before).abs() <= 1e-10 * closing);
    let mu = m[0] * m[1] / (m[0] + m[1]);
    let loss = (1.0 - e * e) * 0.5 * mu * closing * closing;
    assert!(
        (c.energy_lost - loss).abs() <= 1e-10 * loss,
        "{}",
        c.energy_lost
    );
    let impulse = mu * (1.0 + e) * closing;
    assert!((c.impulse - impulse).abs() <= 1e-10 * impulse);
    // momentum at every accepted state: 1e-10 of Σ m|v|
    let p0 = m[0] * v[0] + m[1] * v[1];
    let scale = m[0] * v[0].abs() + m[1] * v[1].abs();
    for (i, s) in &rec.steps {
        let p = m[0] * s.velocity[0][0] + m[1] * s.velocity[1][0];
        assert!((p - p0).abs() <= 1e-10 * scale, "t = {}: {p}", i.time);
        for node in 0..2 {
            for k in 1..6 {
                assert!(s.velocity[node][k].abs() <= 1e-12, "t = {}", i.time);
            }
        }
    }
    // the velocities after (1e-10 relative)
    let s = &rec.steps.last().unwrap().1;
    let va = v[0] - (1.0 + e) * m[1] / (m[0] + m[1]) * closing;
    let vb = v[1] + (1.0 + e) * m[0] / (m[0] + m[1]) * closing;
    eprintln!(
        "v_a⁺ = {} ({va}), v_b⁺ = {} ({vb})",
        s.velocity[0][0], s.velocity[1][0]
    );
    assert!((s.velocity[0][0] - va).abs() <= 1e-10 * closing);
    assert!((s.velocity[1][0] - vb).abs() <= 1e-10 * closing);
    // they part: the gap grows at e × 1.5 m/s after the impact
    let gap = contact(&model).coordinate(s);
    let expected = (0.8 - c.time) * e * closing;
    assert!((gap - expected).abs() <= 1e-8, "{gap} {expected}");
}

/// A plastic collision (e = 0) with A pushed towards B by a force F: the
/// contact closes and stays closed, both move together with the common
/// velocity v_c of the impact (momentum) and the acceleration
/// F/(m_a + m_b), and the contact carries N = m_b F/(m_a + m_b)
/// (persistent contact between two nodes).
#[test]
fn two_spheres_stay_in_contact_when_pushed_together() {
    let (m, v, f) = ([1.0, 3.0], [1.0, -0.5], 2.0);
    let (model, _, rec) = run(&spheres(
        0.8,
        m,
        v,
        0.0,
        &format!("\n[[loads]]\nnode = 1\nforce = [{f}, 0.0, 0.0]\ncurve = \"constant\"\n"),
    ));
    assert_eq!(rec.contacts.len(), 1, "{:?}", rec.contacts);
    let c = &rec.contacts[0];
    assert_eq!(c.kind, ContactKind::Close);
    // the relative rate stopped (round-off of the impact solve)
    assert!(c.rate_after.abs() <= 1e-10 * c.rate_before.abs(), "{c:?}");
    let contact = contact(&model);
    let (i_c, s_c) = rec
        .steps
        .iter()
        .find(|(i, _)| i.time == c.time)
        .expect("the impact's step");
    // the common velocity after the plastic impact: momentum (1e-10)
    let v_c = (m[0] * s_c.velocity[0][0] + m[1] * s_c.velocity[1][0]) / (m[0] + m[1]);
    assert!((s_c.velocity[0][0] - v_c).abs() <= 1e-10);
    assert!((s_c.velocity[1][0] - v_c).abs() <= 1e-10);
    let a = f / (m[0] + m[1]);
    let expected = m[1] * f / (m[0] + m[1]);
    let mut worst = 0.0f64;
    let after: Vec<_> = rec.steps.iter().filter(|(i, _)| i.time > c.time).collect();
    assert!(after.len() > 5);
    for (i, s) in after {
        // closed, the gap held within the event tolerance
        assert!(contact.coordinate(s).abs() <= GAP_TOLERANCE);
        // both move as one: x(t) = x(t_c) + v_c τ + a τ²/2 (1e-9 m: the
        // relative velocity of index-3 integration, below 6e-6 m/s,
        // alternates and does not accumulate)
        let tau = i.time - i_c.time;
        for node in 0..2 {
            let x = s_c.x[node].x + v_c * tau + 0.5 * a * tau * tau;
            assert!(
                (s.x[node].x - x).abs() <= 1e-9 + 1e-6 * a * tau * tau,
                "t = {}",
                i.time
            );
        }
        // N = m_b F/(m_a + m_b): 1e-8 relative, the constraint's
        // convergence (measured: 1.1e-9; 7.4e-3 alternating from step to
        // step when the steps resumed from the landing step of 5e-7 s,
        // whose round-off of the positions, 1e-16 m, the index-3 scheme
        // divides by βh²: the steps now resume with the size they had
        // before the landing, docs/theory.md §16.4)
        let n = force(&model, s);
        worst = worst.max((n - expected).abs() / expected);
        assert!(
            (n - expected).abs() <= 1e-8 * expected,
            "t = {}: {n}",
            i.time
        );
    }
    eprintln!("contact force within {worst:.2e} of m_b F/(m_a + m_b)");
}

/// Input errors name the file, the contact and what is wrong; `unfold
/// check` refuses them with exit code 2.
#[test]
fn contact_input_errors_name_the_contact() {
    let plane = |keys: &str, z: f64| ball(1.0, [0.0, 0.0, z], keys, "");
    let cases = [
        (
            plane("type = \"plane\"\nnode = 7\nnormal = [0.0, 0.0, 1.0]", 1.0),
            "node 7 does not exist",
        ),
        (
            plane("type = \"plane\"\nnode = 1\nnormal = [0.0, 0.0, 0.0]", 1.0),
            "normal must be a non-zero finite vector",
        ),
        (
            plane("type = \"plane\"\nnode = 1", 1.0),
            "a contact with a plane needs `normal`",
        ),
        (
            plane(
                "type = \"plane\"\nnode = 1\nnormal = [0.0, 0.0, 1.0]\nradius = -0.1",
                1.0,
            ),
            "radius must be zero or positive and finite, got -0.1",
        ),
        (
            plane(
                "type = \"plane\"\nnode = 1\nnormal = [0.0, 0.0, 1.0]\nrestitution = 1.5",
                1.0,
            ),
            "restitution must be in [0, 1], got 1.5",
        ),
        (
            plane(
                "type = \"plane\"\nnode = 1\nnormal = [0.0, 0.0, 1.0]\nrestitution = -0.2",
                1.0,
            ),
            "restitution must be in [0, 1], got -0.2",
        ),
        (
            plane(
                "type = \"plane\"\nnode = 1\nnormal = [0.0, 0.0, 1.0]\nradius = 0.1",
                0.05,
            ),
            "the sphere on node 1 penetrates the plane in the reference configuration: its gap n·(x − p) − r is -5.000e-2 m",
        ),
        (
            plane(
                "type = \"plane\"\nnode = 1\nnormal = [0.0, 0.0, 1.0]\nradii = [0.1, 0.1]",
                1.0,
            ),
            "`radii` belong to type = \"spheres\"",
        ),
        (
            spheres(1.0, [1.0, 1.0], [0.0, 0.0], 0.5, "")
                .replace("radii = [0.2, 0.3]", "radii = [0.6, 0.5]"),
            "the spheres on nodes 1 and 2 penetrate each other in the reference configuration: their gap |x_b − x_a| − r_a − r_b is -1.000e-1 m",
        ),
        (
            spheres(1.0, [1.0, 1.0], [0.0, 0.0], 0.5, "")
                .replace("nodes = [1, 2]\nradii", "nodes = [1, 1]\nradii"),
            "the two spheres are on the same node 1",
        ),
        (
            spheres(1.0, [1.0, 1.0], [0.0, 0.0], 0.5, "")
                .replace("nodes = [1, 2]\nradii", "nodes = [1, 9]\nradii"),
            "node 9 does not exist",
        ),
        (
            spheres(1.0, [1.0, 1.0], [0.0, 0.0], 0.5, "")
                .replace("radii = [0.2, 0.3]", "radii = [0.2, -0.3]"),
            "radii[2] must be zero or positive and finite, got -0.3",
        ),
        (
            spheres(1.0, [1.0, 1.0], [0.0, 0.0], 0.5, "")
                .replace("radii = [0.2, 0.3]", "radii = [0.0, 0.0]"),
            "radii are both zero",
        ),
        (
            spheres(1.0, [1.0, 1.0], [0.0, 0.0], 0.5, "")
                .replace("nodes = [1, 2]\nradii", "nodes = [1, 2, 3]\nradii"),
            "nodes must be two node ids, got 3 of them",
        ),
    ];
    let dir = std::env::temp_dir().join(format!("unfold-contacts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (k, (text, expected)) in cases.iter().enumerate() {
        let message = error_of(text);
        assert!(message.contains("contact "), "{message}");
        assert!(message.contains(expected), "{message}");
        let file = dir.join(format!("case{k}.toml"));
        std::fs::write(&file, text).unwrap();
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_unfold"))
            .arg("check")
            .arg(&file)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{stderr}");
        // the file, the entity and the problem
        assert!(stderr.contains(&format!("case{k}.toml")), "{stderr}");
        assert!(
            stderr.contains("contact 30") || stderr.contains("contact 40"),
            "{stderr}"
        );
        assert!(stderr.contains(expected), "{stderr}");
    }
    // an unknown type is refused by the reader (exit code 2)
    let file = dir.join("type.toml");
    std::fs::write(
        &file,
        plane("type = \"cone\"\nnode = 1\nnormal = [0.0, 0.0, 1.0]", 1.0),
    )
    .unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_unfold"))
        .arg("check")
        .arg(&file)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("cone") && stderr.contains("plane"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A run of the ball writes its contact's results to `contacts.csv` and
/// its events to `events.csv`, the contact as the element and the joint
/// column empty.
#[test]
fn a_run_writes_contacts_and_events() {
    let dir = std::env::temp_dir().join(format!("unfold-contacts-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("ball.toml");
    std::fs::write(
        &file,
        ball(
            0.6,
            [0.0, 0.0, 1.0 + RADIUS],
            &format!(
                "type = \"plane\"\nnode = 1\nnormal = [0.0, 0.0, 1.0]\nradius = {RADIUS}\nrestitution = 0.5"
            ),
            "",
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args(["run", "--quiet"])
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let contacts = std::fs::read_to_string(out.join("contacts.csv")).unwrap();
    let mut lines = contacts.lines();
    assert_eq!(lines.next(), Some("step,time,contact,gap,closed,force"));
    assert!(lines.all(|l| l.split(',').nth(2) == Some("30")));
    let events = std::fs::read_to_string(out.join("events.csv")).unwrap();
    let rows: Vec<Vec<&str>> = events
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    eprintln!("{events}");
    // one impact at t = √(2/g) = 0.4515 (the next at 0.903 is past the end)
    assert_eq!(rows.len(), 1, "{events}");
    assert_eq!((rows[0][3], rows[0][4], rows[0][5]), ("30", "impact", ""));
    let t: f64 = rows[0][2].parse().unwrap();
    assert!((t - (2.0 / G).sqrt()).abs() <= 1e-6, "{t}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The builder writes `[[contacts]]`; the contact's results in the
/// reference configuration: open, the gap.
#[test]
fn the_builder_writes_the_contact_entries() {
    use unfold::elements::ElementKind;
    use unfold::model::builder::*;
    let mut m = ModelBuilder::new("two balls above a plane");
    m.analysis(Analysis::dynamic());
    let a = m.node([0.0, 0.0, 1.0]);
    let b = m.node([0.0, 0.0, 2.0]);
    m.add(RigidBody::at(a, 1.0).inertia([0.01, 0.01, 0.01]));
    m.add(RigidBody::at(b, 1.0).inertia([0.01, 0.01, 0.01]));
    let floor = m.add(
        Contact::plane(a, [0.0, 0.0, 0.0], [0.0, 0.0, 2.0])
            .radius(0.25)
            .restitution(0.7),
    );
    let pair = m.add(Contact::spheres(a, b).radii(0.25, 0.5).restitution(0.2));
    let model = m.build().unwrap();
    assert_eq!(model.element(floor).kind(), ElementKind::Contact);
    let r = model.results(floor, &model.initial_state());
    assert_eq!(r.get("closed"), Some(0.0));
    assert_eq!(r.get("force"), Some(0.0));
    // the normal is made unit: g = 1 − 0.25 (round-off)
    assert!((r.get("gap").unwrap() - 0.75).abs() < 1e-15);
    let r = model.results(pair, &model.initial_state());
    assert!((r.get("gap").unwrap() - 0.25).abs() < 1e-15);
    let text = m.to_toml().unwrap();
    assert!(
        text.contains("[[contacts]]")
            && text.contains("type = \"spheres\"")
            && text.contains("restitution = 0.7"),
        "{text}"
    );
    let input: ModelInput = toml::from_str(&text).unwrap();
    assert_eq!(input.contacts.len(), 2);
    assert!(Model::from_input(&input).is_ok());
}

// ---------- a rigid bar falling on one end ----------

/// Length, mass and tilt of the bar, and the height of its lower end.
const BAR_LENGTH: f64 = 1.0;
const BAR_MASS: f64 = 1.0;
const BAR_TILT_DEG: f64 = 30.0;
const BAR_DROP: f64 = 0.5;

/// A uniform rigid bar of length L = 1 m and mass m = 1 kg (a rigid body
/// on its centre node 1, J_G = m L²/12 across it, 1e-4 kg·m² about its
/// axis: a thin tube), its ends nodes 2 (upper, x < 0) and 3 (lower,
/// x > 0) glued to it (massless: the glue carries them), released at rest
/// tilted by 30° about y with its lower end 0.5 m above the plane z = 0,
/// under gravity −z; contacts 12 and 13 of the two ends with the plane
/// (points: radius 0), restitution `e`, frictionless.
fn bar(end_time: f64, e: f64) -> String {
    let (c, s) = (
        BAR_TILT_DEG.to_radians().cos(),
        BAR_TILT_DEG.to_radians().sin(),
    );
    let half = 0.5 * BAR_LENGTH;
    let zg = BAR_DROP + half * s;
    let j = BAR_MASS * BAR_LENGTH * BAR_LENGTH / 12.0;
    format!(
        r#"
[analysis]
type = "dynamic"
end_time = {end_time}
time_step = 0.01

[[nodes]]
id = 1
x = [0.0, 0.0, {zg}]
rotation = [0.0, {BAR_TILT_DEG}, 0.0]
unit = "deg"

[[nodes]]
id = 2
x = [{}, 0.0, {}]

[[nodes]]
id = 3
x = [{}, 0.0, {BAR_DROP}]

[[rigid_bodies]]
id = 1
node = 1
mass = {BAR_MASS}
inertia = [1e-4, {j}, {j}]

[[joints]]
id = 2
type = "glue"
nodes = [1, 2]

[[joints]]
id = 3
type = "glue"
nodes = [1, 3]

[[contacts]]
id = 12
type = "plane"
node = 2
normal = [0.0, 0.0, 1.0]
restitution = {e}

[[contacts]]
id = 13
type = "plane"
node = 3
normal = [0.0, 0.0, 1.0]
restitution = {e}

[gravity]
acceleration = [0.0, 0.0, -{G}]
curve = "constant"
"#,
        -half * c,
        zg + half * s,
        half * c,
    )
}

/// The contact `id` of the model.
fn contact_of(model: &Model, id: u64) -> &unfold::joints::Stop {
    model
        .elements
        .iter()
        .find(|e| e.id() == id)
        .and_then(|e| e.as_stop())
        .expect("the contact")
}

/// The planar rigid motion of the bar at `s`: the velocity of its centre
/// (global), its angular velocity about y (global: ω = R Ω), the position
/// of its centre, the positions of its ends (nodes 2, 3).
struct BarMotion {
    v: Vec3,
    w: f64,
    x: Vec3,
    ends: [Vec3; 2],
}

fn bar_motion(s: &State) -> BarMotion {
    let omega = s.q[0] * Vec3::new(s.velocity[0][3], s.velocity[0][4], s.velocity[0][5]);
    BarMotion {
        v: translation(s, 0),
        w: omega.y,
        x: s.x[0],
        ends: [s.x[1], s.x[2]],
    }
}

impl BarMotion {
    /// The kinetic energy ½ m v² + ½ J ω² (planar: the motion stays in
    /// the plane xz).
    fn kinetic(&self) -> f64 {
        let j = BAR_MASS * BAR_LENGTH * BAR_LENGTH / 12.0;
        0.5 * BAR_MASS * self.v.norm_squared() + 0.5 * j * self.w * self.w
    }
    /// The normal (z) velocity of end `k`: v_z + (ω × r)_z = v_z − ω r_x.
    fn normal_rate(&self, k: usize) -> f64 {
        self.v.z - self.w * (self.ends[k].x - self.x.x)
    }
}

/// A uniform rigid bar released tilted at rest falls on its lower end
/// (reference paper §4, eq. 16; the acceptance case "a bar falling on one
/// end, hitting a stop with restitution e: rebound velocities equal e
/// times the approach velocity to 1e-6; the bar comes to rest without
/// chattering, with penetration below the stated tolerance").
///
/// The impact law of a rigid body struck at a point `P` at `r = P − G`
/// from its centre, frictionless along the normal `n = e_z`, by the
/// impulse `Π = P n` (Pfeiffer & Glocker 1996, ch. 5; docs/theory.md
/// §16.4, LK1–LK2e for the glued ends):
///
///   Δv_G = P n/m,   Δω = J_G⁻¹ (r × P n),  in the plane xz
///   Δω_y = −r_x P/J,  the normal rate of P: v_n = v_Gz − ω_y r_x,
///   Δv_n = P (1/m + r_x²/J) = P/m*,   m* = (1/m + r_x²/J)⁻¹,
///
/// and Newton's law v_n⁺ = −e v_n⁻ gives P = −(1 + e) m* v_n⁻, the loss
/// T⁻ − T⁺ = (1 − e²) ½ m* v_n⁻² (LK3e), the tangential (x) velocity of G
/// unchanged. With the other end resting on the plane (closed: it holds
/// v_z = 0 through the impact), the two impulses P_k solve
/// Σ_j (1/m + r_kx r_jx/J) P_j = Δv_k (Δv = −(1 + e) v_n⁻ at the end
/// struck, 0 at the end resting), and the loss is T⁻ − T⁺ of the two
/// states. Between impacts the bar flies (no moment about G: ω constant,
/// v_G of the free fall), so the state before each impact in flight is
/// known exactly from the state after the one before.
#[test]
fn a_bar_falls_on_one_end_and_comes_to_rest_on_both() {
    let e = 0.5;
    let (model, out, rec) = run(&bar(1.5, e));
    let j = BAR_MASS * BAR_LENGTH * BAR_LENGTH / 12.0;
    let ids = [12u64, 13];
    let contacts = [contact_of(&model, 12), contact_of(&model, 13)];
    let gravity = Vec3::new(0.0, 0.0, -G);
    // the velocity scale: the fall of the lower end, √(2 g h)
    let v0 = (2.0 * G * BAR_DROP).sqrt();
    let state_at = |t: f64| -> usize {
        rec.steps
            .iter()
            .position(|(i, _)| i.time == t)
            .expect("the event's step")
    };
    let mut previous_event = 0usize;
    // the largest relative errors: rebound, approach from the flight,
    // loss
    let mut worst = [0.0f64; 3];
    eprintln!(
        "event, contact, t, rate before → after (ratio), impulse, loss, steps since the last event"
    );
    for (k, c) in rec.contacts.iter().enumerate() {
        assert!(
            matches!(c.kind, ContactKind::Impact | ContactKind::Close),
            "{c:?}"
        );
        let end = ids.iter().position(|&id| id == c.stop).unwrap();
        let other = 1 - end;
        let after_index = state_at(c.time);
        let (_, after) = &rec.steps[after_index];
        let (i_before, before) = &rec.steps[after_index - 1];
        let plus = bar_motion(after);
        let e_applied = if c.kind == ContactKind::Impact {
            e
        } else {
            0.0
        };
        eprintln!(
            "{k:2} {} t = {:.9}: {:+.6e} → {:+.6e} ({:+.3e}), P = {:.6e}, loss {:.6e}, {} steps",
            c.stop,
            c.time,
            c.rate_before,
            c.rate_after,
            c.rate_after / c.rate_before,
            c.impulse,
            c.energy_lost,
            after_index - previous_event
        );
        previous_event = after_index;
        // Newton's law on the end struck, from the state after the impact
        // (the bar's rigid motion, not the event's own report): v_n⁺ =
        // −e v_n⁻ to 1e-6 of v_n⁻ (the acceptance tolerance)
        let vn_plus = plus.normal_rate(end);
        worst[0] = worst[0].max((vn_plus + e_applied * c.rate_before).abs() / c.rate_before.abs());
        assert!(
            (vn_plus + e_applied * c.rate_before).abs() <= 1e-6 * c.rate_before.abs(),
            "{c:?}: v_n⁺ = {vn_plus}"
        );
        assert!((c.rate_after - vn_plus).abs() <= 1e-9 * c.rate_before.abs());
        // the impulses: the end struck, and the other if it rests on the
        // plane (closed before the impact)
        let resting = contacts[other].contact(before) != unfold::joints::stop::Contact::Open;
        let r = [plus.ends[0].x - plus.x.x, plus.ends[1].x - plus.x.x];
        let w = |a: usize, b: usize| 1.0 / BAR_MASS + r[a] * r[b] / j;
        let target = -(1.0 + e_applied) * c.rate_before;
        let (p, q) = if resting {
            // [w_ee w_eo; w_oe w_oo] (P, Q) = (target, 0)
            let det = w(end, end) * w(other, other) - w(end, other) * w(other, end);
            (
                target * w(other, other) / det,
                -target * w(other, end) / det,
            )
        } else {
            (target / w(end, end), 0.0)
        };
        // the impulse reported: P (1e-6 relative)
        assert!((c.impulse - p).abs() <= 1e-6 * p.abs(), "{c:?}: P = {p}");
        // the state before, from the formula: v_G⁻ = v_G⁺ − (P + Q)/m e_z,
        // ω⁻ = ω⁺ + (r_e P + r_o Q)/J
        let minus = BarMotion {
            v: plus.v - Vec3::new(0.0, 0.0, (p + q) / BAR_MASS),
            w: plus.w + (r[end] * p + r[other] * q) / j,
            ..bar_motion(after)
        };
        if !resting && contacts[end].contact(before) == unfold::joints::stop::Contact::Open {
            // in flight before: the state before the impact is the free
            // flight from the step before (ω constant, v_G + g τ, exact
            // for the scheme: 1e-9 of the velocity scale), so the jumps
            // Δv_G = P/m and Δω = −r_x P/J of the formula are checked
            // against the integrated motion
            let flight = bar_motion(before);
            let tau = c.time - i_before.time;
            let v_flight = flight.v + gravity * tau;
            worst[1] = worst[1]
                .max((minus.v - v_flight).norm() / v0)
                .max((minus.w - flight.w).abs() * BAR_LENGTH / v0);
            assert!(
                (minus.v - v_flight).norm() <= 1e-9 * v0,
                "{c:?}: v_G⁻ {:?} against {v_flight:?}",
                minus.v
            );
            assert!(
                (minus.w - flight.w).abs() <= 1e-9 * v0 / BAR_LENGTH,
                "{c:?}: ω⁻ {} against {}",
                minus.w,
                flight.w
            );
        }
        // the approach rate of the end struck, from the state before
        // (1e-6 relative)
        assert!(
            (minus.normal_rate(end) - c.rate_before).abs() <= 1e-6 * c.rate_before.abs(),
            "{c:?}"
        );
        // no friction: the tangential velocity of G is unchanged (it is
        // zero throughout, below)
        assert!((plus.v.x - minus.v.x).abs() <= 1e-12 * v0);
        // the energy lost: T⁻ − T⁺ of the two rigid states, which for an
        // impact in flight is (1 − e²) ½ m* v_n⁻² (LK3e), against the
        // loss reported and the drop of the kinetic energy (1e-6 of T⁻)
        let loss = minus.kinetic() - plus.kinetic();
        worst[2] = worst[2].max((c.energy_lost - loss).abs() / minus.kinetic());
        if !resting {
            let m_star = 1.0 / w(end, end);
            let formula = (1.0 - e_applied * e_applied) * 0.5 * m_star * c.rate_before.powi(2);
            assert!((loss - formula).abs() <= 1e-6 * minus.kinetic(), "{c:?}");
        }
        assert!(
            (c.energy_lost - loss).abs() <= 1e-6 * minus.kinetic(),
            "{c:?}: loss {loss}"
        );
        assert!((c.kinetic_energy_drop - loss).abs() <= 1e-6 * minus.kinetic());
    }
    eprintln!(
        "largest errors: rebound {:.1e} of v_n⁻, state before from the flight {:.1e} of √(2gh), loss {:.1e} of T⁻",
        worst[0], worst[1], worst[2]
    );
    eprintln!(
        "{} events, {} steps, {} rejected, {} retried to land on events",
        rec.contacts.len(),
        out.steps,
        out.rejected_steps,
        out.event_retries
    );

    // rest without chattering: both contacts closed once each, and nothing
    // after. The bound: each end's last sequence of rebounds (the other
    // end resting or in flight) is geometric, its approach rates falling
    // by e at each impact from the first v₁, and a rebound slower than
    // v_min = √(2 g_tol |c̈|) closes the contact (docs/theory.md §16.4):
    // at most ⌈log(v₁/v_min)/log(1/e)⌉ + 1 events of that end after it
    // last struck at v₁; before them the two ends exchange a few impacts
    // while the bar flies. Measured: 30 events in all.
    let closes: Vec<&ContactInfo> = rec
        .contacts
        .iter()
        .filter(|c| c.kind == ContactKind::Close)
        .collect();
    assert_eq!(closes.len(), 2, "{:?}", rec.contacts);
    assert!(rec.contacts.len() <= 40, "{}", rec.contacts.len());
    for &id in &ids {
        // the last run of events of this contact that ends in its close
        let close = rec.contacts.iter().rposition(|c| c.stop == id).unwrap();
        assert_eq!(rec.contacts[close].kind, ContactKind::Close);
        let mut first = close;
        while first > 0
            && rec.contacts[first - 1].stop == id
            && rec.contacts[first - 1].rate_before.abs() > rec.contacts[first].rate_before.abs()
        {
            first -= 1;
        }
        let v1 = rec.contacts[first].rate_before.abs();
        // v_min with |c̈| = g: an end of the bar lying almost flat falls
        // at g in flight and at 1.5 g about the other end resting; a
        // larger |c̈| closes sooner
        let v_min = (2.0 * GAP_TOLERANCE * G).sqrt();
        let bound = ((v1 / v_min).ln() / (1.0 / e).ln()).ceil() as usize + 1;
        eprintln!(
            "contact {id}: {} events from {v1:.3e} m/s to its close (bound {bound})",
            close - first + 1
        );
        assert!(close - first < bound, "{}", close - first + 1);
    }
    let last = rec.contacts.last().unwrap();
    let rest: Vec<_> = rec
        .steps
        .iter()
        .filter(|(i, _)| i.time > last.time)
        .collect();
    assert!(rest.len() > 10, "{}", rest.len());
    for (i, s) in &rest {
        let ctx = model.context(s.time, unfold::elements::Need::RESIDUAL);
        let n = [contacts[0].load(&ctx, s), contacts[1].load(&ctx, s)];
        // at rest on both ends: the contact forces sum to the weight and
        // each carries half of it (uniform bar, symmetric supports), to
        // 1e-6 relative
        assert!(
            (n[0] + n[1] - BAR_MASS * G).abs() <= 1e-6 * BAR_MASS * G,
            "t = {}: {n:?}",
            i.time
        );
        for f in n {
            assert!(
                (f - 0.5 * BAR_MASS * G).abs() <= 1e-6 * BAR_MASS * G,
                "t = {}: {n:?}",
                i.time
            );
        }
        // at rest: no velocity (1e-8 m/s)
        let m = bar_motion(s);
        assert!(
            m.v.norm() <= 1e-8 && m.w.abs() * BAR_LENGTH <= 1e-8,
            "t = {}",
            i.time
        );
    }
    // penetration: no end below the plane by more than the event
    // tolerance g_tol = 1e-8 m (docs/theory.md §16.5) at any accepted step
    let worst = rec.steps.iter().fold(0.0f64, |w, (_, s)| {
        w.max(-contacts[0].coordinate(s))
            .max(-contacts[1].coordinate(s))
    });
    eprintln!("largest penetration {worst:.3e} m");
    assert!(worst <= GAP_TOLERANCE);
    // frictionless: no horizontal force, the momentum m v_Gx stays zero
    // (1e-9 of m √(2 g h)) and G stays above its start
    for (i, s) in &rec.steps {
        let m = bar_motion(s);
        assert!(
            (BAR_MASS * m.v.x).abs() <= 1e-9 * BAR_MASS * v0,
            "t = {}: {}",
            i.time,
            m.v.x
        );
        assert!(
            m.x.x.abs() <= 1e-9 * BAR_LENGTH,
            "t = {}: {}",
            i.time,
            m.x.x
        );
    }
    // the energy balance through the impacts (1e-6 of m g h)
    eprintln!("energy balance error {:.3e} J", out.energies.balance_error);
    assert!(out.energies.balance_error.abs() <= 1e-6 * BAR_MASS * G * BAR_DROP);
}
