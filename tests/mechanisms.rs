//! Kinematic analysis of closed-loop mechanisms against closed-form
//! solutions: a planar four-bar (Freudenstein's equation), an offset
//! slider-crank, and the threefold-symmetric Bricard linkage (an
//! over-constrained spatial 6R loop); then the diagnosis of indeterminate,
//! inconsistent and malformed mechanisms.
//!
//! Every body is rigid: one node, no element, its joints attached at the
//! offsets given by their `position`. Every node starts with the identity
//! orientation, so a body's rotation from the reference is its node's
//! orientation `R`, and a point `P` of the reference configuration carried
//! by a body whose node is at `X` is at `x + R (P − X)`.
//!
//! The loops are closed by 3-D revolute (and prismatic) joints, so the
//! planar loops are over-constrained too: a planar loop of four one-dof
//! joints has three redundant equations in 3-D, the Bricard loop one.
//!
//! Accuracy: every analysis holds its constraints to `TOL = 1e-12` (of the
//! model size `L` for distances, in radians for angles). A converged state
//! then satisfies each constraint equation to `TOL` (the convergence test
//! of `analysis::newton`), so positions are exact to a
//! few `TOL·L` and angles, i.e. distances over link lengths of at least
//! `L/5`, to a few `1e-11` rad. The acceptance limits below, `1e-8` rad and
//! `1e-8·L`, leave three orders of magnitude for round-off accumulated
//! over the path and are still far below any modelling error.

use std::f64::consts::{FRAC_PI_4, PI, TAU};

use unfold::analysis::newton::NewtonSolver;
use unfold::analysis::observers::History;
use unfold::analysis::statics::StaticError;
use unfold::analysis::{StaticAnalysis, StaticOutcome};
use unfold::elements::ElementKind;
use unfold::joints::JointType;
use unfold::model::input::{AnalysisInput, DriverInput, Id, JointInput, ModelInput};
use unfold::model::Model;
use unfold::so3::{self, Mat3, Vec3};
use unfold::state::State;

/// Tolerance of the constraints (relative to the model size for
/// distances, radians for angles) in every analysis of this file.
const TOL: f64 = 1e-12;

/// Acceptance limit on angles (rad) and, times the model size, on
/// positions: see the module documentation.
const LIMIT: f64 = 1e-8;

// ---------------------------------------------------------------------
// helpers
// ---------------------------------------------------------------------

/// Builds and runs a model, keeping every converged state.
fn simulate(input: &ModelInput) -> (std::sync::Arc<Model>, StaticOutcome, History) {
    let model = std::sync::Arc::new(Model::from_input(input).expect("valid model"));
    let mut path = History::with_states();
    let settings = input.analyses().unwrap()[0].as_static().unwrap().clone();
    let outcome =
        StaticAnalysis::new(model.clone(), settings).run(model.initial_state(), &mut path);
    (model, outcome, path)
}

/// A kinematic analysis of `t ∈ [0, 1]` in `n` equal increments, the
/// constraints held to [`TOL`].
fn kinematic(n: usize) -> AnalysisInput {
    let dt = 1.0 / n as f64;
    AnalysisInput {
        kind: "kinematic".into(),
        end_time: 1.0,
        initial_increment: Some(dt),
        max_increment: Some(dt),
        displacement_tolerance: Some(TOL),
        rotation_tolerance: Some(TOL),
        ..AnalysisInput::default()
    }
}

/// A joint of type `kind` between `nodes` (one node: to the ground) at
/// `position`, axis `axis`.
fn joint(id: Id, kind: JointType, nodes: &[Id], position: Vec3, axis: Vec3) -> JointInput {
    JointInput {
        id,
        kind,
        nodes: nodes.to_vec(),
        axis: Some(axis.into()),
        position: Some(position.into()),
        ..JointInput::default()
    }
}

/// A driver of the first coordinate of joint `joint` to `value·t`.
fn driver(id: Id, joint: Id, value: f64) -> DriverInput {
    DriverInput {
        id,
        joint: Some(joint),
        value,
        ..DriverInput::default()
    }
}

/// Index of node `id`.
fn node(model: &Model, id: Id) -> usize {
    model.node_index(id).expect("node exists")
}

/// Rotation angle about global z of a node's orientation (planar motion).
fn yaw(state: &State, n: usize) -> f64 {
    let r = so3::matrix(&state.q[n]);
    r[(1, 0)].atan2(r[(0, 0)])
}

/// `angle` shifted by whole turns to the branch nearest `reference`.
fn near(angle: f64, reference: f64) -> f64 {
    angle + TAU * ((reference - angle) / TAU).round()
}

/// Where the reference point `p` carried by node `n` is at `state`.
fn carried(model: &Model, state: &State, n: usize, p: &Vec3) -> Vec3 {
    state.x[n] + so3::matrix(&state.q[n]) * (p - model.reference_x[n])
}

/// Result `name` (`angle`, `slide`, `F1`, ...; `coordinate` of a driver)
/// of the joint or driver `id` at `state`.
fn result(model: &Model, state: &State, kind: ElementKind, id: Id, name: &str) -> f64 {
    let e = model
        .elements
        .iter()
        .find(|e| e.kind() == kind && e.id() == id)
        .expect("element exists");
    let mut out = vec![f64::NAN; e.result_names().len()];
    e.results(
        &model.context(state.time, unfold::elements::Need::RESIDUAL),
        state,
        &mut out,
    );
    let k = e.result_names().iter().position(|n| *n == name);
    out[k.unwrap_or_else(|| panic!("{} {id} has no result {name}", kind.name()))]
}

/// Number of constraint equations found redundant in the reference
/// configuration (what the analysis does first).
fn redundant_count(model: &Model) -> usize {
    let mut state = model.initial_state();
    model.apply_prescribed(&mut state, 0.0);
    NewtonSolver::new(model)
        .constraint_rank(model, &state, 0.0)
        .redundant
        .len()
}

/// The largest position difference and the largest rotation between the
/// nodes of two states, and whether they are within `dx` and `dth`.
fn same_poses(a: &State, b: &State, dx: f64, dth: f64) -> (f64, f64, bool) {
    let ex =
        a.x.iter()
            .zip(&b.x)
            .map(|(p, q)| (p - q).norm())
            .fold(0.0, f64::max);
    let er =
        a.q.iter()
            .zip(&b.q)
            .map(|(p, q)| so3::log(&(p.inverse() * q)).norm())
            .fold(0.0, f64::max);
    (ex, er, ex <= dx && er <= dth)
}

// ---------------------------------------------------------------------
// 1. planar four-bar
// ---------------------------------------------------------------------

/// Crank-rocker: crank `a`, coupler `b`, rocker `c`, ground `d` (m).
/// Grashof: s + l = a + d = 0.50 ≤ p + q = b + c = 0.65, and the shortest
/// link is the crank, next to the ground: the crank turns fully and the
/// rocker oscillates.
const FB: [f64; 4] = [0.10, 0.35, 0.30, 0.40];

/// Crank angle of the reference configuration.
const FB_THETA2: f64 = FRAC_PI_4;

/// Rocker angle `θ₄` of the open four-bar for the crank angle `θ₂`, both
/// measured from the ground line `O₂O₄` counter-clockwise, and the ratio
/// `S/√(P²+Q²)` that must stay inside (−1, 1) for the mechanism to
/// assemble.
///
/// Loop closure `a e^{iθ₂} + b e^{iθ₃} = d + c e^{iθ₄}`: isolating
/// `b e^{iθ₃}` and taking the squared modulus,
/// `b² = a² + c² + d² + 2cd cos θ₄ − 2ad cos θ₂ − 2ac cos(θ₂ − θ₄)`,
/// i.e. Freudenstein's equation
/// `K₁ cos θ₄ − K₂ cos θ₂ + K₃ = cos(θ₂ − θ₄)` with `K₁ = d/a`,
/// `K₂ = d/c`, `K₃ = (a² − b² + c² + d²)/(2ac)`. Expanding
/// `cos(θ₂ − θ₄)`: `P cos θ₄ + Q sin θ₄ = S` with `P = cos θ₂ − K₁`,
/// `Q = sin θ₂`, `S = K₃ − K₂ cos θ₂`, so
/// `θ₄ = atan2(Q, P) ± acos(S/√(P²+Q²))`. The minus sign is the open
/// configuration (coupler and rocker above the ground line), the one
/// assembled in the reference configuration; the two roots meet only
/// where `|S| = √(P²+Q²)` (coupler and rocker aligned), which a
/// crank-rocker never reaches, so the branch holds for the whole turn.
fn freudenstein(theta2: f64) -> (f64, f64) {
    let [a, b, c, d] = FB;
    let (k1, k2, k3) = (
        d / a,
        d / c,
        (a * a - b * b + c * c + d * d) / (2.0 * a * c),
    );
    let (p, q, s) = (theta2.cos() - k1, theta2.sin(), k3 - k2 * theta2.cos());
    let ratio = s / p.hypot(q);
    (q.atan2(p) - ratio.acos(), ratio)
}

/// The four-bar in its reference configuration: ground node 1 (fixed) at
/// `O₂`, crank node 2, coupler node 3, rocker node 4 at their link
/// midpoints; revolute joints 1 (ground–crank at `O₂`), 2 (crank–coupler
/// at `A`), 3 (coupler–rocker at `B`), 4 (ground–rocker at `O₄`), all
/// about z, listed with the ground (or the body nearer to it) as body A, so
/// that every joint angle is the counter-clockwise rotation of the body
/// farther from the ground. With `drive`, driver 10 turns the crank
/// through a full turn.
fn four_bar(drive: bool) -> ModelInput {
    let [a, _, c, d] = FB;
    let theta4 = freudenstein(FB_THETA2).0;
    let o2 = Vec3::zeros();
    let o4 = Vec3::new(d, 0.0, 0.0);
    let pa = Vec3::new(a * FB_THETA2.cos(), a * FB_THETA2.sin(), 0.0);
    let pb = o4 + Vec3::new(c * theta4.cos(), c * theta4.sin(), 0.0);
    let mut m = ModelInput::new("planar four-bar, crank-rocker");
    m.analysis = kinematic(72).into();
    m.add_node(1, o2.into());
    m.add_node(2, ((o2 + pa) / 2.0).into());
    m.add_node(3, ((pa + pb) / 2.0).into());
    m.add_node(4, ((o4 + pb) / 2.0).into());
    m.fix(1, &["all"]);
    let z = Vec3::z();
    m.joints = vec![
        joint(1, JointType::Revolute, &[1, 2], o2, z),
        joint(2, JointType::Revolute, &[2, 3], pa, z),
        joint(3, JointType::Revolute, &[3, 4], pb, z),
        joint(4, JointType::Revolute, &[1, 4], o4, z),
    ];
    if drive {
        m.drivers.push(driver(10, 1, TAU));
    }
    m
}

/// A crank-rocker four-bar driven at the crank through a full turn in 72
/// increments (5°).
///
/// Source: Freudenstein's equation (closed form derived in
/// [`freudenstein`]), evaluated at the crank angle the driver prescribes,
/// `θ₂ = π/4 + 2πt`. Tolerance 1e-8 rad on the rocker angle at every
/// converged increment, on the crank angle, and on the return of the
/// whole mechanism to its reference configuration after the turn (module
/// documentation: the constraints hold to 1e-12).
#[test]
fn four_bar_rocker_follows_freudenstein() {
    let [_, b, _, _] = FB;
    let (theta4_0, _) = freudenstein(FB_THETA2);
    let input = four_bar(true);
    // the reference configuration is assembled: |AB| = b
    let p = |k: usize| Vec3::from(input.joints[k].position.unwrap());
    assert!(((p(2) - p(1)).norm() - b).abs() < 1e-15);
    let (model, outcome, path) = simulate(&input);
    assert!(outcome.error.is_none(), "{}", outcome.error.unwrap());
    assert_eq!(outcome.time, 1.0);
    assert_eq!(outcome.increments, 72);
    assert_eq!(outcome.cutbacks, 0);

    // four 3-D revolute joints closing a planar loop: 4×5 + 1 equations on
    // 3×6 unknowns, of rank 18: three redundant equations, reported
    assert_eq!(redundant_count(&model), 3);
    assert!(
        path.notes.iter().any(|n| n.contains("3 redundant")),
        "{:?}",
        path.notes
    );

    let (crank, rocker) = (node(&model, 2), node(&model, 4));
    let l = model.length_scale;
    let (mut max_rocker, mut max_crank, mut max_coord, mut max_z) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut min_margin = f64::INFINITY;
    let mut theta4_prev = theta4_0;
    for s in &path.states {
        let t = s.time;
        let theta2 = FB_THETA2 + TAU * t;
        // crank: the driver's law
        let crank_angle = near(FB_THETA2 + yaw(s, crank), theta2);
        max_crank = max_crank.max((crank_angle - theta2).abs());
        // rocker against the closed form
        let (reference, ratio) = freudenstein(theta2);
        min_margin = min_margin.min(1.0 - ratio.abs());
        let theta4 = near(theta4_0 + yaw(s, rocker), theta4_prev);
        theta4_prev = theta4;
        max_rocker = max_rocker.max((theta4 - near(reference, theta4)).abs());
        // the joint coordinate of the rocker joint is the rocker's rotation
        let c = result(&model, s, ElementKind::Joint, 4, "angle");
        max_coord = max_coord.max((c - (theta4 - theta4_0)).abs());
        // the motion stays in its plane
        for n in 0..model.n_nodes() {
            let r = so3::matrix(&s.q[n]);
            // position off the plane, and tilt of the node's z axis
            max_z = max_z
                .max(s.x[n].z.abs() / l)
                .max(r[(0, 2)].hypot(r[(1, 2)]));
        }
    }
    let iterations = path.iterations();
    println!(
        "four-bar: {} increments, {iterations} iterations; max |θ4 − θ4_ref| = {max_rocker:.2e} rad, \
         max |θ2 − θ2_driver| = {max_crank:.2e} rad, joint coordinate vs rotation {max_coord:.2e}, \
         out of plane {max_z:.1e}; transmission margin {min_margin:.3}",
        outcome.increments
    );
    // the crank-rocker never reaches a toggle position: the branch is kept
    assert!(min_margin > 0.2, "margin {min_margin}");
    assert!(max_rocker <= LIMIT, "rocker angle error {max_rocker:.3e}");
    assert!(max_crank <= LIMIT, "crank angle error {max_crank:.3e}");
    assert!(
        max_coord <= LIMIT,
        "rocker joint coordinate {max_coord:.3e}"
    );
    assert!(max_z <= LIMIT, "out-of-plane motion {max_z:.3e}");

    // after the turn: crank coordinate 2π (unwrapped), everything back home
    let last = path.states.last().unwrap();
    let crank_coordinate = result(&model, last, ElementKind::Joint, 1, "angle");
    assert!(
        (crank_coordinate - TAU).abs() <= LIMIT,
        "crank coordinate {crank_coordinate}"
    );
    let driven = result(&model, last, ElementKind::Driver, 10, "coordinate");
    assert!((driven - TAU).abs() <= LIMIT, "driver coordinate {driven}");
    assert!(
        (theta4_prev - theta4_0).abs() <= LIMIT,
        "rocker back at {theta4_prev} instead of {theta4_0}"
    );
    let (ex, er, ok) = same_poses(&path.states[0], last, LIMIT * l, LIMIT);
    assert!(ok, "not back home: position {ex:.2e}, rotation {er:.2e}");
}

// ---------------------------------------------------------------------
// 2. slider-crank
// ---------------------------------------------------------------------

/// Crank `r`, connecting rod `l`, offset `e` of the slider line `y = −e`
/// (m); crank angle of the reference configuration.
const SC: [f64; 3] = [0.10, 0.35, 0.02];
const SC_THETA: f64 = 0.5;

/// Slider position for the crank angle `θ`: the crank pin is at
/// `r(cos θ, sin θ)`, the slider at `(x, −e)` on its line, and the rod
/// length gives `l² = (x − r cos θ)² + (r sin θ + e)²`; the slider on the
/// side of positive x (the reference configuration) is
/// `x = r cos θ + √(l² − (r sin θ + e)²)`.
fn slider_x(theta: f64) -> f64 {
    let [r, l, e] = SC;
    r * theta.cos() + (l * l - (r * theta.sin() + e).powi(2)).sqrt()
}

/// The offset slider-crank: crank node 1 at the crank axis (revolute
/// joint 1 to the ground, about z), rod node 2 at the rod's midpoint
/// (revolute joint 2 to the crank at the pin, joint 3 to the slider),
/// slider node 3 on a prismatic joint 4 to the ground along x; driver 10
/// turns joint 1 through a full turn. Joints 1 and 4 are joints to the
/// ground (one node).
fn slider_crank() -> ModelInput {
    let [r, _, e] = SC;
    let pin = Vec3::new(r * SC_THETA.cos(), r * SC_THETA.sin(), 0.0);
    let slider = Vec3::new(slider_x(SC_THETA), -e, 0.0);
    let mut m = ModelInput::new("offset slider-crank");
    m.analysis = kinematic(72).into();
    m.add_node(1, [0.0; 3]);
    m.add_node(2, ((pin + slider) / 2.0).into());
    m.add_node(3, slider.into());
    let z = Vec3::z();
    m.joints = vec![
        joint(1, JointType::Revolute, &[1], Vec3::zeros(), z),
        joint(2, JointType::Revolute, &[1, 2], pin, z),
        joint(3, JointType::Revolute, &[2, 3], slider, z),
        joint(4, JointType::Prismatic, &[3], slider, Vec3::x()),
    ];
    m.drivers.push(driver(10, 1, TAU));
    m
}

/// An offset slider-crank driven at the crank through a full turn in 72
/// increments.
///
/// Source: the closed form [`slider_x`] evaluated at the crank angle of
/// the computed configuration (the rotation of the crank node). Tolerance
/// 1e-8·L on the slider position at every converged increment and on the
/// slider staying on its line, 1e-8 rad on the crank's turn and on the
/// return to the reference configuration (module documentation).
///
/// The crank's joint and the slider's are joints to the ground (one node).
/// Whether their coordinates measure the node relative to the ground or
/// the reverse is a convention of the joint library (docs/joints.md §3.7);
/// this test takes the sign `σ = ±1` of the crank's turn from the
/// computation and checks that it is the same for angles and slides: the
/// crank turns by `σ·2πt` and the prismatic joint's slide is `σ` times the
/// slider's displacement along x (same tolerances).
#[test]
fn slider_crank_follows_closed_form() {
    let [_, l_rod, e] = SC;
    let input = slider_crank();
    // the reference configuration is assembled: |pin − slider| = l
    let p = |k: usize| Vec3::from(input.joints[k].position.unwrap());
    assert!(((p(1) - p(2)).norm() - l_rod).abs() < 1e-15);
    let (model, outcome, path) = simulate(&input);
    assert!(outcome.error.is_none(), "{}", outcome.error.unwrap());
    assert_eq!(outcome.time, 1.0);
    assert_eq!(outcome.increments, 72);
    // the planar loop of three revolute joints and a prismatic joint:
    // 4×5 + 1 equations on 3×6 unknowns, three redundant
    assert_eq!(redundant_count(&model), 3);

    let (crank, slider) = (node(&model, 1), node(&model, 3));
    let x0 = model.reference_x[slider].x;
    let l = model.length_scale;
    let (mut max_x, mut max_y, mut max_turn, mut max_slide) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut turn = 0.0;
    let mut slides = Vec::new();
    for s in &path.states {
        turn = near(yaw(s, crank), turn);
        let theta = SC_THETA + turn;
        max_turn = max_turn.max((turn.abs() - TAU * s.time).abs());
        max_x = max_x.max((s.x[slider].x - slider_x(theta)).abs() / l);
        max_y = max_y.max((s.x[slider].y + e).abs() / l);
        slides.push((
            result(&model, s, ElementKind::Joint, 4, "slide"),
            s.x[slider].x - x0,
        ));
    }
    // the convention of joints to the ground, from the crank's turn
    let sigma = turn.signum();
    for (slide, u) in slides {
        max_slide = max_slide.max((slide - sigma * u).abs() / l);
    }
    println!(
        "slider-crank: {} increments, {} iterations; max |x − x_ref| = {max_x:.2e} L (L = {l:.3} m), \
         off the line {max_y:.2e} L, crank turn error {max_turn:.2e} rad, slide {max_slide:.2e} L",
        outcome.increments,
        path.iterations()
    );
    assert!(max_x <= LIMIT, "slider position error {max_x:.3e} L");
    assert!(max_y <= LIMIT, "slider off its line by {max_y:.3e} L");
    assert!(max_turn <= LIMIT, "crank turn error {max_turn:.3e}");
    assert!(
        max_slide <= LIMIT,
        "prismatic coordinate off by {max_slide:.3e} L"
    );
    // a full turn, and everything back home
    assert!((turn.abs() - TAU).abs() <= LIMIT, "crank turned by {turn}");
    let last = path.states.last().unwrap();
    assert!((last.x[slider].x - x0).abs() <= LIMIT * l);
    let (ex, er, ok) = same_poses(&path.states[0], last, LIMIT * l, LIMIT);
    assert!(ok, "not back home: position {ex:.2e}, rotation {er:.2e}");
}

// ---------------------------------------------------------------------
// 3. Bricard linkage
// ---------------------------------------------------------------------

/// Link length (m) and twist of the threefold-symmetric Bricard linkage.
const BRICARD_A: f64 = 0.5;
const BRICARD_ALPHA: f64 = FRAC_PI_4;
/// Angle of joint 1 in the reference configuration.
const BRICARD_THETA1: f64 = 0.4;

/// Rotation by `angle` about the unit vector `axis`.
fn rot(axis: Vec3, angle: f64) -> Mat3 {
    so3::exp_matrix(&(axis * angle))
}

/// Denavit–Hartenberg frames of a 6R loop: `F₁ = I` and
/// `Fᵢ₊₁ = Fᵢ Rz(θᵢ) Tx(a) Rx(αᵢ)`, as (orientation, origin); joint `i`
/// is the z axis of `Fᵢ` through its origin. Returns `F₁ … F₇`; the loop
/// closes when `F₇ = F₁`.
fn dh_frames(theta: &[f64; 6], alpha: &[f64; 6], a: f64) -> Vec<(Mat3, Vec3)> {
    let mut f = vec![(Mat3::identity(), Vec3::zeros())];
    for i in 0..6 {
        let (r, p) = *f.last().unwrap();
        let r = r * rot(Vec3::z(), theta[i]);
        let p = p + r * Vec3::new(a, 0.0, 0.0);
        f.push((r * rot(Vec3::x(), alpha[i]), p));
    }
    f
}

/// The angle `θ₂` of the threefold-symmetric Bricard linkage for the
/// angle `θ₁`, on the branch nearest `previous`.
///
/// The linkage (Chen, You & Chen, "Threefold-symmetric Bricard linkages
/// for deployable structures", Int. J. Solids Struct. 42, 2005): six links
/// of equal length `a`, twists alternately `α` and `2π − α` (i.e. `−α`),
/// no offsets. Its motion keeps `θ₁ = θ₃ = θ₅` and `θ₂ = θ₄ = θ₆`, so the
/// loop is `M³ = I` with `M = Rz(θ₁)Tx(a)Rx(α)·Rz(θ₂)Tx(a)Rx(−α)`. The
/// rotation of `M` is `Rz(θ₁)` times the rotation by `θ₂` about
/// `Rx(α)e_z`, whose quaternion has the scalar part
/// `w = cos(θ₁/2)cos(θ₂/2) − cos α sin(θ₁/2) sin(θ₂/2)`; its cube is the
/// identity when its angle is `±2π/3`, `w = ±1/2` (the translation of `M³`
/// then vanishes too, as the closure check of the test confirms). With
/// `A = cos(θ₁/2)`, `B = −cos α sin(θ₁/2)`, `ρ = √(A² + B²)`,
/// `φ = atan2(B, A)`: `θ₂ = 2φ ± 2 acos(1/(2ρ))` (mod 2π; `w = −1/2` gives
/// the same angles). For `|cos α| > 1/2`, `ρ > 1/2` for every `θ₁`: `θ₁`
/// turns fully, and the two roots stay apart by `4 acos(1/(2ρ)) ≥ π` for
/// `α = π/4`, so following the nearest root from step to step keeps the
/// branch.
fn bricard_theta2(theta1: f64, previous: f64) -> f64 {
    let (a, b) = (
        (theta1 / 2.0).cos(),
        -BRICARD_ALPHA.cos() * (theta1 / 2.0).sin(),
    );
    let (rho, phi) = (a.hypot(b), b.atan2(a));
    let half = (0.5 / rho).acos();
    let roots = [2.0 * (phi + half), 2.0 * (phi - half)].map(|r| near(r, previous));
    let (best, other) = if (roots[0] - previous).abs() <= (roots[1] - previous).abs() {
        (roots[0], roots[1])
    } else {
        (roots[1], roots[0])
    };
    // the branch is unambiguous
    assert!(
        (other - previous).abs() > 1.0,
        "roots too close at θ₁ = {theta1}"
    );
    best
}

/// The threefold-symmetric Bricard linkage assembled at `θ₁ = 0.4`: body
/// `i` (node `i`, at its link's midpoint) carries joints `i` and `i + 1`;
/// revolute joint `i` joins body `i − 1` (body 6 for joint 1) to body `i`
/// on the z axis of the Denavit–Hartenberg frame `Fᵢ`. Body 6 is fixed;
/// driver 10 turns joint 1 (the rotation of body 1 relative to body 6)
/// through a full turn. Returns the model, the joints' reference points
/// and axes, and the reference angles `θ₁, θ₂`.
fn bricard() -> (ModelInput, Vec<(Vec3, Vec3)>, f64, f64) {
    let theta1 = BRICARD_THETA1;
    let theta2 = bricard_theta2(theta1, 2.0 * PI / 3.0);
    let (a, al) = (BRICARD_A, BRICARD_ALPHA);
    let f = dh_frames(
        &[theta1, theta2, theta1, theta2, theta1, theta2],
        &[al, -al, al, -al, al, -al],
        a,
    );
    let mut m = ModelInput::new("threefold-symmetric Bricard linkage");
    m.analysis = kinematic(72).into();
    let axes: Vec<(Vec3, Vec3)> = f[..6]
        .iter()
        .map(|(r, p)| (*p, r.column(2).into_owned()))
        .collect();
    for i in 0..6 {
        m.add_node(i as Id + 1, ((f[i].1 + f[i + 1].1) / 2.0).into());
    }
    m.fix(6, &["all"]);
    for (i, (p, z)) in axes.iter().enumerate() {
        let body = i as Id + 1;
        let previous = if body == 1 { 6 } else { body - 1 };
        m.joints
            .push(joint(body, JointType::Revolute, &[previous, body], *p, *z));
    }
    m.drivers.push(driver(10, 1, TAU));
    (m, axes, theta1, theta2)
}

/// Relative rotation angle of node `b` to node `a` about `axis` (a unit
/// vector of the reference configuration), and the misalignment of the
/// two bodies' copies of the axis.
fn hinge_angle(s: &State, a: usize, b: usize, axis: &Vec3) -> (f64, f64) {
    let q = so3::matrix(&s.q[a]).transpose() * so3::matrix(&s.q[b]);
    let e1 = axis
        .cross(&Vec3::x())
        .try_normalize(1e-3)
        .unwrap_or_else(|| axis.cross(&Vec3::y()).normalize());
    let qe1 = q * e1;
    let angle = axis.dot(&e1.cross(&qe1)).atan2(e1.dot(&qe1));
    (angle, (q * axis).cross(axis).norm())
}

/// The threefold-symmetric Bricard linkage (a mobile over-constrained 6R
/// loop) driven at joint 1 through a full turn in 72 increments.
///
/// Sources and tolerances:
/// - the reference configuration closes (Denavit–Hartenberg product, to
///   1e-15·a: round-off);
/// - the rank analysis finds one redundant equation: 6 revolute joints
///   give 30 equations on 5 free bodies (30 unknowns) and leave one
///   motion, i.e. rank 29, plus the driver;
/// - along the path every joint holds: joint points of both bodies within
///   2·TOL·L and axes within 2·TOL rad (the convergence test holds each
///   equation to TOL, the one left out as redundant included);
/// - the threefold symmetry `θ₁ = θ₃ = θ₅`, `θ₂ = θ₄ = θ₆` and the
///   closed-form input-output relation [`bricard_theta2`] hold within
///   1e-8 rad, the angles measured from the bodies' orientations; each
///   joint's own coordinate agrees with them;
/// - after the full turn of joint 1, joint 2 has turned by −2π (closed
///   form) and every body is back in its initial pose within 1e-8 (L and
///   rad).
#[test]
fn bricard_linkage_turns_through_its_cycle() {
    let (input, axes, theta1_0, theta2_0) = bricard();
    let a = BRICARD_A;
    // the loop closes in the reference configuration
    {
        let al = BRICARD_ALPHA;
        let f = dh_frames(
            &[theta1_0, theta2_0, theta1_0, theta2_0, theta1_0, theta2_0],
            &[al, -al, al, -al, al, -al],
            a,
        );
        let (r, p) = f[6];
        let closure = (r - Mat3::identity()).abs().max().max(p.norm() / a);
        assert!(closure < 1e-14, "loop does not close: {closure:.2e}"); // round-off of six products
    }
    let (model, outcome, path) = simulate(&input);
    assert!(outcome.error.is_none(), "{}", outcome.error.unwrap());
    assert_eq!(outcome.time, 1.0);
    assert_eq!(outcome.increments, 72);
    assert_eq!(redundant_count(&model), 1);
    assert!(
        path.notes.iter().any(|n| n.contains("1 redundant")),
        "{:?}",
        path.notes
    );

    let l = model.length_scale;
    let bodies: Vec<usize> = (1..=6).map(|i| node(&model, i)).collect();
    let (mut max_gap, mut max_axis) = (0.0f64, 0.0f64);
    let (mut max_sym, mut max_rel, mut max_coord) = (0.0f64, 0.0f64, 0.0f64);
    let mut turns = [0.0f64; 6];
    let mut theta2_ref = theta2_0;
    for s in &path.states {
        let theta1 = theta1_0 + TAU * s.time;
        theta2_ref = bricard_theta2(theta1, theta2_ref);
        for (i, (p, z)) in axes.iter().enumerate() {
            let (ba, bb) = (bodies[(i + 5) % 6], bodies[i]);
            // loop closure: joint i holds
            let gap = (carried(&model, s, ba, p) - carried(&model, s, bb, p)).norm();
            let (angle, misalignment) = hinge_angle(s, ba, bb, z);
            max_gap = max_gap.max(gap / l);
            max_axis = max_axis.max(misalignment);
            // joint angle relative to the reference, unwrapped
            turns[i] = near(angle, turns[i]);
            let c = result(&model, s, ElementKind::Joint, i as Id + 1, "angle");
            max_coord = max_coord.max((c - turns[i]).abs());
        }
        // threefold symmetry and the input-output relation
        for i in 2..6 {
            max_sym = max_sym.max((turns[i] - turns[i % 2]).abs());
        }
        max_rel = max_rel
            .max((turns[0] - (theta1 - theta1_0)).abs())
            .max((turns[1] - (theta2_ref - theta2_0)).abs());
    }
    println!(
        "Bricard: {} increments, {} iterations, {} redundant; max joint gap {max_gap:.2e} L, axis \
         misalignment {max_axis:.2e} rad; symmetry {max_sym:.2e} rad, closed form {max_rel:.2e} rad, \
         joint coordinates {max_coord:.2e} rad; final turns {:?}",
        outcome.increments,
        path.iterations(),
        redundant_count(&model),
        turns.map(|t| (t / TAU * 1e6).round() / 1e6)
    );
    assert!(max_gap <= 2.0 * TOL, "joint gap {max_gap:.3e} L");
    assert!(max_axis <= 2.0 * TOL, "axis misalignment {max_axis:.3e}");
    assert!(max_sym <= LIMIT, "threefold symmetry lost by {max_sym:.3e}");
    assert!(max_rel <= LIMIT, "closed form missed by {max_rel:.3e}");
    assert!(
        max_coord <= LIMIT,
        "joint coordinates off by {max_coord:.3e}"
    );
    // one cycle: joints 1, 3, 5 turned by +2π, joints 2, 4, 6 by −2π
    assert!((theta2_ref - theta2_0 + TAU).abs() < 1e-12);
    for (i, t) in turns.iter().enumerate() {
        let expected = if i % 2 == 0 { TAU } else { -TAU };
        assert!(
            (t - expected).abs() <= LIMIT,
            "joint {}: turned by {t}",
            i + 1
        );
    }
    let (ex, er, ok) = same_poses(
        &path.states[0],
        path.states.last().unwrap(),
        LIMIT * l,
        LIMIT,
    );
    assert!(ok, "not back home: position {ex:.2e}, rotation {er:.2e}");
}

// ---------------------------------------------------------------------
// 4. indeterminate and inconsistent mechanisms
// ---------------------------------------------------------------------

/// The four-bar without its driver has one free motion: the kinematic
/// analysis stops before any increment with `Indeterminate`, counting
/// one free motion.
#[test]
fn undriven_four_bar_is_indeterminate() {
    let (_, outcome, path) = simulate(&four_bar(false));
    let error = outcome
        .error
        .expect("an undriven mechanism must be rejected");
    let message = error.to_string();
    match error {
        StaticError::Indeterminate { free, ref dofs } => {
            assert_eq!(free, 1, "{message}");
            assert!(dofs.contains("node "), "{message}");
        }
        other => panic!("expected Indeterminate, got {other}"),
    }
    assert!(message.contains("1 motion(s) are left free"), "{message}");
    assert!(path.states.is_empty());
    assert_eq!(outcome.increments, 0);
}

/// The four-bar driven at the crank and, incompatibly, at the rocker
/// (joint 4 to 0.3 rad while the crank's turn moves it otherwise): the
/// rocker's driver is a combination of the other constraints in the
/// reference configuration, so it is left out as redundant, then found
/// violated after the first increment: `Inconsistent`, naming the
/// driver. The state kept is the last consistent one (the reference).
#[test]
fn conflicting_drivers_are_inconsistent() {
    let mut input = four_bar(true);
    input.drivers.push(driver(11, 4, 0.3));
    let (model, outcome, path) = simulate(&input);
    // 22 equations on 18 unknowns: the three of the loop and the second
    // driver are redundant in the reference configuration
    assert_eq!(redundant_count(&model), 4);
    let error = outcome.error.expect("conflicting drivers must be rejected");
    let message = error.to_string();
    match error {
        StaticError::Inconsistent {
            time,
            ref constraint,
            violation,
        } => {
            assert_eq!(constraint, "driver 11 equation 1", "{message}");
            assert!(time > 0.0 && time <= 1.0 / 72.0 + 1e-12, "{message}");
            assert!(violation > 1.0, "{message}");
        }
        other => panic!("expected Inconsistent, got {other}"),
    }
    assert!(message.contains("driver 11"), "{message}");
    assert_eq!(outcome.increments, 0);
    assert_eq!(path.states.len(), 1, "only the initial state is reported");
}

// ---------------------------------------------------------------------
// 5. malformed joints
// ---------------------------------------------------------------------

/// The errors of `Model::from_input` for `input`, as (entity, message).
fn errors(input: &ModelInput) -> Vec<(String, String)> {
    match Model::from_input(input) {
        Ok(_) => panic!("the model should be rejected"),
        Err(e) => e.0.into_iter().map(|e| (e.entity, e.message)).collect(),
    }
}

/// A joint between a node and itself, a joint naming a node that does not
/// exist, and a revolute joint whose `axis_b` is not parallel to `axis`
/// (5.7° off, and reversed) are each rejected with an error naming the
/// joint.
#[test]
fn malformed_joints_are_rejected() {
    // node joined to itself
    let mut m = four_bar(true);
    m.joints[1].nodes = vec![2, 2];
    let e = errors(&m);
    assert!(!e.is_empty());
    assert!(e.iter().all(|(entity, _)| entity == "joint 2"), "{e:?}");
    assert!(e[0].1.contains("itself"), "{e:?}");

    // unknown node
    let mut m = four_bar(true);
    m.joints[2].nodes = vec![3, 99];
    let e = errors(&m);
    assert!(!e.is_empty());
    assert!(e.iter().all(|(entity, _)| entity == "joint 3"), "{e:?}");
    assert!(e[0].1.contains("node 99"), "{e:?}");

    // axis_b not parallel to axis
    for axis_b in [[0.0, 0.1, 1.0], [0.0, 0.0, -1.0]] {
        let mut m = four_bar(true);
        m.joints[3].axis_b = Some(axis_b);
        let e = errors(&m);
        assert!(!e.is_empty());
        assert!(e.iter().all(|(entity, _)| entity == "joint 4"), "{e:?}");
        assert!(e[0].1.contains("axis_b"), "{e:?}");
    }

    // while a parallel `axis_b` is accepted
    let mut m = four_bar(true);
    m.joints[3].axis_b = Some([0.0, 0.0, 2.0]);
    assert!(Model::from_input(&m).is_ok());
}
