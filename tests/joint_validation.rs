//! Validation of the joint library (kinematic pairs, joint springs,
//! drivers) on mechanisms with known answers. Each test states its source
//! (an analytic derivation given in its comment) and the reason for each
//! tolerance.
//!
//! Sign conventions (docs/joints.md §3.7, §4, §6.1, §7): a joint to the
//! ground has the ground as body A and its node as body B, and coordinates
//! measure B relative to A: a node turning by `+θ` about the joint axis
//! has the joint angle `c = +θ`, a node moving by `+u` along it the stroke
//! `c = +u`. A driver's `load` `Q` is the generalised force it applies to
//! body B along `c` (a moment `+Q` about the axis for an angle); a joint
//! spring with force `f_s` applies `−f_s` along `c` to body B. A joint's
//! reported load (`F1..M3`) is the load it applies to its first node (the
//! node, for a joint to the ground), moments about the joint point, in
//! body A's current joint axes (the ground's fixed triad for a joint to
//! the ground).
//!
//! Newton tolerances: most checks below are at the 1e-9 level, far below
//! the default convergence tolerances (residual 1e-8 of the force flux,
//! constraints and corrections 1e-6 of the model size). The models set
//! [`tight`] tolerances, which Newton's quadratic convergence reaches in
//! one or two more iterations; what is left is round-off.

mod common;

use std::f64::consts::{PI, TAU};

use unfold::analysis::{ConvergenceNorms, IncrementInfo, IterationInfo, Observer};
use unfold::elements::ElementKind;
use unfold::joints::JointType;
use unfold::model::input::{
    BeamLineInput, CurveInput, DriverInput, Id, JointInput, JointSpringInput, ModelInput,
    RigidBodyInput,
};
use unfold::model::Model;
use unfold::so3::{self, Mat3, Vec3};
use unfold::state::State;

// ---------------------------------------------------------------- helpers

/// Everything an analysis reports: per increment the converged state, the
/// residual at every dof, and the norms of every Newton iteration of the
/// attempt that converged.
#[derive(Default)]
struct Path {
    infos: Vec<IncrementInfo>,
    states: Vec<State>,
    residuals: Vec<Vec<f64>>,
    /// (increment, norms of each iteration) of the attempt under way.
    attempt: Option<(usize, Vec<ConvergenceNorms>)>,
    /// Norms of the converged attempt of each increment.
    norms: Vec<Vec<ConvergenceNorms>>,
    cutbacks: usize,
    /// Remarks of the analysis (redundant constraints removed).
    notes: Vec<String>,
}

impl Observer for Path {
    fn iteration(&mut self, info: &IterationInfo) {
        if info.iteration == 0 {
            self.attempt = Some((info.increment, Vec::new()));
        }
        if let Some((_, v)) = self.attempt.as_mut() {
            v.push(info.norms);
        }
    }
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _: &Model,
        state: &State,
        residual: &[f64],
    ) -> std::io::Result<()> {
        self.infos.push(info.clone());
        self.states.push(state.clone());
        self.residuals.push(residual.to_vec());
        let (inc, norms) = self.attempt.take().expect("iterations before convergence");
        assert_eq!(inc, info.increment);
        self.norms.push(norms);
        Ok(())
    }
    fn cutback(&mut self, _: &unfold::analysis::CutbackInfo) {
        self.cutbacks += 1;
    }
    fn note(&mut self, text: &str) {
        self.notes.push(text.to_string());
    }
}

/// Builds and runs `input`, asserting that it reaches its end time.
fn solve(input: &ModelInput) -> (std::sync::Arc<Model>, Path) {
    let model = Model::from_input(input).unwrap_or_else(|e| panic!("invalid model: {e}"));
    let model = std::sync::Arc::new(model);
    let mut path = Path::default();
    let outcome = common::analysis(&model, input).run(model.initial_state(), &mut path);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    (model, path)
}

/// Convergence tolerances at round-off level (see the module comment):
/// residual 1e-10 of the force flux, constraints and corrections 1e-12 of
/// the model size (1e-12 rad).
fn tight(m: &mut ModelInput) {
    m.analysis.residual_tolerance = Some(1e-10);
    m.analysis.displacement_tolerance = Some(1e-12);
    m.analysis.rotation_tolerance = Some(1e-12);
}

/// The results of an element, by name (`r["F3"]`; a joint's coordinates
/// `r["angle"]`, `r["slide"]`...).
struct Named {
    names: &'static [&'static str],
    values: Vec<f64>,
}

impl std::ops::Index<&str> for Named {
    type Output = f64;
    fn index(&self, name: &str) -> &f64 {
        match self.names.iter().position(|n| *n == name) {
            Some(k) => &self.values[k],
            None => panic!("no result {name} among {:?}", self.names),
        }
    }
}

/// The results of element `id` of kind `kind` at `state`.
fn results(model: &Model, state: &State, kind: ElementKind, id: Id) -> Named {
    let e = model
        .elements
        .iter()
        .find(|e| e.kind() == kind && e.id() == id)
        .unwrap_or_else(|| panic!("no {} {id}", kind.name()));
    let names = e.result_names();
    let mut values = vec![0.0; names.len()];
    e.results(
        &model.context(state.time, unfold::elements::Need::RESIDUAL),
        state,
        &mut values,
    );
    Named { names, values }
}

/// Load joint `id` applies to its first node, global components: force
/// and moment about the joint point. `axes` are the joint axes the results
/// are written in (columns, global): the triad `e` of the input for a
/// joint to the ground; `R_A e` for a joint between nodes whose first node
/// A has the identity as reference orientation.
fn joint_reaction(model: &Model, state: &State, id: Id, axes: &Mat3) -> (Vec3, Vec3) {
    let r = results(model, state, ElementKind::Joint, id);
    (
        axes * Vec3::new(r["F1"], r["F2"], r["F3"]),
        axes * Vec3::new(r["M1"], r["M2"], r["M3"]),
    )
}

/// The triad the model builder makes from `axis` and `reference`:
/// `e₃ = axis`, `e₁` = the part of `reference` normal to it, `e₂ = e₃ × e₁`.
fn triad(axis: [f64; 3], reference: [f64; 3]) -> Mat3 {
    let e3 = Vec3::from(axis).normalize();
    let r = Vec3::from(reference);
    let e1 = (r - e3 * e3.dot(&r)).normalize();
    Mat3::from_columns(&[e1, e3.cross(&e1), e3])
}

/// A straight beam line between existing nodes with explicit ids.
fn beam_line(m: &mut ModelInput, ends: [Id; 2], n: usize, section: &str, first: (Id, Id)) {
    m.beam_lines.push(BeamLineInput {
        nodes: ends,
        elements: n,
        section: section.into(),
        orientation: Some([0.0, 0.0, 1.0]),
        first_node: Some(first.0),
        first_element: Some(first.1),
        arc_center: None,
        initial_strain: None,
        initial_strain_curve: None,
    });
}

/// A joint with an axis and a reference direction.
fn joint(id: Id, kind: JointType, nodes: &[Id], axis: [f64; 3], reference: [f64; 3]) -> JointInput {
    JointInput {
        id,
        kind,
        nodes: nodes.to_vec(),
        axis: Some(axis),
        reference_direction: Some(reference),
        ..Default::default()
    }
}

/// A driver of coordinate `coordinate` of joint `joint` to `value·t`.
fn joint_driver(id: Id, joint: Id, coordinate: &str, value: f64) -> DriverInput {
    DriverInput {
        id,
        joint: Some(joint),
        coordinate: Some(coordinate.into()),
        value,
        ..Default::default()
    }
}

/// A linear spring on a joint coordinate, unloaded in the reference
/// configuration.
fn linear_spring(id: Id, joint: Id, coordinate: &str, stiffness: f64) -> JointSpringInput {
    JointSpringInput {
        id,
        joint,
        coordinate: Some(coordinate.into()),
        stiffness: Some(stiffness),
        ..Default::default()
    }
}

/// The constant curve `f(t) = 1`.
fn constant_curve(m: &mut ModelInput) {
    m.curves.push(CurveInput {
        name: "constant".into(),
        points: vec![[0.0, 1.0], [1.0, 1.0]],
        ..Default::default()
    });
}

/// Rotation angle of `q` about the unit axis `axis`, unwrapped to the branch
/// nearest `previous` (valid for rotations about that axis only).
fn angle_about(q: &so3::Rotation, axis: &Vec3, previous: f64) -> f64 {
    let psi = so3::log(q);
    let a = psi.dot(axis);
    a + TAU * ((previous - a) / TAU).round()
}

/// `max(‖r_F‖/F, ‖r_M‖/M)`: the residual relative to the applied loads.
fn relative(n: &ConvergenceNorms, force: f64, moment: f64) -> f64 {
    (n.residual_force / force).max(n.residual_moment / moment)
}

/// Checks that every increment ends quadratically (as in
/// tests/beam_validation.rs): with `e` the residual relative to the loads,
/// - from the first iterate with `e < 1e-2` the smallest residual of the
///   increment is reached within 3 iterations (digits 2 → 4 → 8 → 16; a
///   linear rate of 0.1 would need 9);
/// - from the first iterate with `e < 1` (the residual smaller than the
///   loads) on, every iterate satisfies `e_{k+1} ≤ max(e_k², floor)`, with
///   `floor` the round-off level of the residual: Newton's constant
///   `|K⁻¹| |∂K/∂q|/2` in load-relative units is far below 1 for this
///   mechanism (the largest ratio `e_{k+1}/e_k²` is printed: 1.7e-6, from
///   `e ≈ 5e-2` one iteration reaches round-off), while a linear rate of
///   0.1 would already fail from `e_k = 5e-2`.
///
/// Returns the iterations of every increment.
fn assert_quadratic(path: &Path, force: f64, moment: f64, floor: f64) -> Vec<usize> {
    let mut iterations = Vec::new();
    let mut worst_ratio = 0.0f64;
    for (k, inc) in path.norms.iter().enumerate().skip(1) {
        let e: Vec<f64> = inc.iter().map(|n| relative(n, force, moment)).collect();
        println!(
            "increment {k}: {}",
            e.iter()
                .map(|v| format!("{v:.1e}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
        let best = e.iter().copied().fold(f64::INFINITY, f64::min);
        let reached = e.iter().position(|&v| v == best).unwrap();
        let first_small = e
            .iter()
            .position(|&v| v < 1e-2)
            .unwrap_or_else(|| panic!("increment {k}: residual never below 1e-2"));
        assert!(
            reached - first_small <= 3,
            "increment {k}: {} iterations from e < 1e-2 to {best:.1e}",
            reached - first_small
        );
        let below_load = e.iter().position(|&v| v < 1.0).unwrap();
        for w in e[below_load..].windows(2) {
            worst_ratio = worst_ratio.max(w[1] / (w[0] * w[0]));
            assert!(
                w[1] <= (w[0] * w[0]).max(floor),
                "increment {k}: {:.2e} after {:.2e} is not quadratic",
                w[1],
                w[0]
            );
        }
        iterations.push(path.infos[k].iterations);
    }
    println!("largest e_k+1/e_k² once e < 1: {worst_ratio:.1e}");
    iterations
}

// ----------------------------------------------------- 1. slider-crank

/// Slider-crank: crank radius, rod length, resisting force.
const CRANK: f64 = 0.1;
const ROD: f64 = 0.3;
const RESISTANCE: f64 = 100.0;

/// A flexible slider-crank in the xy plane, driven through half a turn.
///
/// Nodes: 1 crank pivot (origin), 2 crank pin on the crank, 3 crank pin on
/// the rod, 4 wrist pin on the rod, 5 slider. The crank (4 beams, 1→2)
/// turns about z on a revolute joint to the ground (101), driven by 201 on
/// the joint angle from 0 to π (the crank turns by π about z). The rod
/// (6 beams, 3→4) is pinned to the crank (102) and to the slider (103); the
/// slider moves along x on a prismatic joint to the ground (104) and
/// carries the constant force `(P, 0, 0)`, which resists its motion
/// towards −x. `stiffness` scales every stiffness of the sections.
fn slider_crank(stiffness: f64) -> ModelInput {
    let (r, l) = (CRANK, ROD);
    let mut m = ModelInput::new("flexible slider-crank");
    m.analysis.kind = "kinetostatic".into();
    m.analysis.initial_increment = Some(0.05);
    m.analysis.max_increment = Some(0.05);
    tight(&mut m);
    let s = stiffness;
    // EA, GA2, GA3, GJ, EI2, EI3
    m.add_section(
        "link",
        [1e8 * s, 4e7 * s, 4e7 * s, 1e4 * s, 1e4 * s, 1e4 * s],
    );
    m.add_node(1, [0.0; 3]);
    m.add_node(2, [r, 0.0, 0.0]);
    m.add_node(3, [r, 0.0, 0.0]);
    m.add_node(4, [r + l, 0.0, 0.0]);
    m.add_node(5, [r + l, 0.0, 0.0]);
    beam_line(&mut m, [1, 2], 4, "link", (10, 1));
    beam_line(&mut m, [3, 4], 6, "link", (20, 10));
    let (z, x, y) = ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    m.joints.push(joint(101, JointType::Revolute, &[1], z, x));
    m.joints
        .push(joint(102, JointType::Revolute, &[2, 3], z, x));
    m.joints
        .push(joint(103, JointType::Revolute, &[4, 5], z, x));
    m.joints.push(joint(104, JointType::Prismatic, &[5], x, y));
    m.drivers.push(joint_driver(201, 101, "angle", PI));
    constant_curve(&mut m);
    m.loads.push(unfold::model::input::LoadInput {
        node: 5,
        force: Some([RESISTANCE, 0.0, 0.0]),
        moment: None,
        follower: false,
        curve: Some("constant".into()),
    });
    m
}

/// Rigid slider-crank: slider position `x(θ) = r cos θ + √(l² − r² sin² θ)`
/// and, by virtual work (`τ δθ + F δx = 0` with `F = P` along x), the
/// crank torque `τ(θ) = −P x'(θ) = P r sin θ (1 + r cos θ/√(l² − r² sin² θ))`.
fn rigid_crank(theta: f64) -> (f64, f64) {
    let (r, l, p) = (CRANK, ROD, RESISTANCE);
    let w = (l * l - (r * theta.sin()).powi(2)).sqrt();
    let x = r * theta.cos() + w;
    let torque = p * r * theta.sin() * (1.0 + r * theta.cos() / w);
    (x, torque)
}

/// Largest deviation of the driver torque from the rigid closed form over
/// the path, relative to `P r`. Also checks that the slider stays on the
/// rigid path within 1e-3 r (the links' compliance moves it by ~ε r).
fn crank_torque_error(model: &Model, path: &Path) -> f64 {
    let slider = model.node_index(5).unwrap();
    let mut worst = 0.0f64;
    for state in &path.states {
        let d = results(model, state, ElementKind::Driver, 201);
        // the crank angle θ, the torque on the crank
        let (theta, torque) = (d["coordinate"], d["load"]);
        let (x, rigid) = rigid_crank(theta);
        let dx = (state.x[slider].x - x) / CRANK;
        let err = (torque - rigid).abs() / (RESISTANCE * CRANK);
        worst = worst.max(err);
        assert!(dx.abs() < 1e-3, "slider off the rigid path by {dx:e} r");
    }
    worst
}

/// Flexible slider-crank under kinetostatic driving (half a turn of the
/// crank in 20 increments against a constant resisting force on the
/// slider; the mechanism passes from one dead centre to the other).
///
/// (a) Quadratic convergence in every increment ([`assert_quadratic`],
/// norms relative to `P` and `P r`). Round-off floor: the axial force of a
/// beam element is computed with an error of about `ε_mach EA` (2.2e-8 N
/// here, 2.2e-10 P), so the residual norm over the ~70 free dofs cannot go
/// below a few 1e-9 P: an iterate may stop at `1e-8 P` instead of `e_k²`.
/// Measured: every increment goes `~1e4 → ~1e4 → ~5 → ~5e-2 → ~1e-9`
/// (4 iterations; the first residuals are the driver's penalty forces
/// `p Φ` for the new crank angle).
///
/// (b) Global equilibrium: the loads the ground applies through the
/// revolute (101) and prismatic (104) joints, the driver's torque and the
/// applied force balance, in force and in moment about the origin. Source:
/// equilibrium of the whole mechanism (beams and pins between bodies are
/// self-equilibrated). Tolerances: forces 1e-9 P (the force imbalance is
/// the sum of the residuals at free dofs, whose round-off parts cancel
/// pairwise between elements); moments `10 ε_mach EA (r + l)`, i.e. 8.9e-9
/// P r (the residual forces at free dofs, ~`ε_mach EA` each, sum to zero
/// but not their moments: their arms are up to `r + l`). The revolute
/// carries no moment about its axis (the driver does): `|M3| ≤ 1e-9 P r`,
/// and the prismatic joint no force along its axis: `|F3| ≤ 1e-9 P`
/// (docs/joints.md §3.4; both are round-off of the multiplier terms).
///
/// (c) The driver torque equals the rigid-body virtual-work torque
/// `τ = −P dx/dθ` ([`rigid_crank`]) within `ε P r`, with `ε = P r²/EI`
/// (1e-4) the compliance of the links: the crank tip lags the driven pivot
/// by the chord rotation `F r²/3EI` under a transverse pin force `F`
/// (at most ~1.1 P), which changes the torque by `|dτ/dθ| F r²/3EI ≤ 0.5 ε
/// P r` (`|dτ/dθ| ≤ 1.4 P r`); the axial compliances add `P l/EA` relative
/// (3e-7). That the deviation is the links' compliance and not an error is
/// shown by making the links 10 times stiffer: it drops by a factor 10
/// (9 to 11 allowed: second-order terms in ε are 1e-4 of the first).
#[test]
fn flexible_slider_crank() {
    let (model, path) = solve(&slider_crank(1.0));
    assert_eq!(path.cutbacks, 0);
    // flexible links: no joint equation repeats another, even at the dead
    // centre where the analysis starts
    assert!(path.notes.is_empty(), "{:?}", path.notes);
    let (p, r, l, ea) = (RESISTANCE, CRANK, ROD, 1e8);

    // (a) quadratic convergence
    let iterations = assert_quadratic(&path, p, p * r, 1e-8);
    println!(
        "{} increments, iterations per increment {iterations:?}",
        iterations.len()
    );
    assert_eq!(iterations.len(), 20);
    let last = path.states.last().unwrap();
    let crank_angle = results(&model, last, ElementKind::Driver, 201)["coordinate"];
    assert!((crank_angle - PI).abs() < 1e-10, "crank at {crank_angle}");

    // (b) global equilibrium at every increment
    let (pivot, slider) = (model.node_index(1).unwrap(), model.node_index(5).unwrap());
    let e_rev = triad([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let e_pri = triad([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let load = Vec3::new(p, 0.0, 0.0);
    let (mut worst_f, mut worst_m) = (0.0f64, 0.0f64);
    let (mut worst_m3, mut worst_f3) = (0.0f64, 0.0f64);
    for state in &path.states {
        let (f1, m1) = joint_reaction(&model, state, 101, &e_rev);
        let (f4, m4) = joint_reaction(&model, state, 104, &e_pri);
        let q = results(&model, state, ElementKind::Driver, 201)["load"];
        let driver_moment = Vec3::new(0.0, 0.0, q);
        let (x1, x5) = (state.x[pivot], state.x[slider]);
        let sum_f = f1 + f4 + load;
        let sum_m = m1 + x1.cross(&f1) + driver_moment + m4 + x5.cross(&f4) + x5.cross(&load);
        worst_f = worst_f.max(sum_f.norm() / p);
        worst_m = worst_m.max(sum_m.norm() / (p * r));
        let rev = results(&model, state, ElementKind::Joint, 101);
        worst_m3 = worst_m3.max(rev["M3"].abs() / (p * r));
        // the prismatic carries no force along its axis: the rod does
        let pri = results(&model, state, ElementKind::Joint, 104);
        worst_f3 = worst_f3.max(pri["F3"].abs() / p);
    }
    let moment_floor = 10.0 * f64::EPSILON * ea * (r + l) / (p * r);
    println!(
        "equilibrium: |ΣF| ≤ {worst_f:.2e} P, |ΣM| ≤ {worst_m:.2e} P r (floor {moment_floor:.1e}); revolute |M3| ≤ {worst_m3:.1e} P r, prismatic |F3| ≤ {worst_f3:.1e} P"
    );
    assert!(worst_f < 1e-9, "force imbalance {worst_f:e} P");
    assert!(worst_m < moment_floor, "moment imbalance {worst_m:e} P r");
    assert!(
        worst_m3 < 1e-9,
        "revolute moment about its axis {worst_m3:e} P r"
    );
    assert!(
        worst_f3 < 1e-9,
        "prismatic force along its axis {worst_f3:e} P"
    );

    // (c) driver torque against the rigid virtual-work torque
    let err = crank_torque_error(&model, &path);
    let (stiff_model, stiff_path) = solve(&slider_crank(10.0));
    let err_stiff = crank_torque_error(&stiff_model, &stiff_path);
    let eps = p * r * r / 1e4;
    println!(
        "driver torque − rigid torque: {err:.3e} P r (ε = {eps:.1e}), {err_stiff:.3e} P r with 10× stiffer links, ratio {:.2}",
        err / err_stiff
    );
    assert!(err < eps, "torque error {err:e} P r");
    assert!((9.0..11.0).contains(&(err / err_stiff)));
}

// ------------------------------------------------------------ 2. helical

/// A node on a helical joint to the ground (axis z, pitch `PITCH`).
const PITCH: f64 = 0.05;

fn screw() -> ModelInput {
    let mut m = ModelInput::new("screw");
    tight(&mut m);
    m.add_node(1, [0.2, -0.1, 0.3]);
    m.joints.push(JointInput {
        pitch: Some(PITCH),
        ..joint(
            101,
            JointType::Helical,
            &[1],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
        )
    });
    m
}

/// Unwrapped rotation of node `n` about z along the path, and its
/// translation along z, at every increment.
fn screw_motion(model: &Model, path: &Path, n: Id) -> Vec<(f64, f64)> {
    let n = model.node_index(n).unwrap();
    let mut previous = 0.0;
    path.states
        .iter()
        .map(|s| {
            previous = angle_about(&s.q[n], &Vec3::z(), previous);
            // the rotation stays about z: no tilt
            let tilt = (so3::matrix(&s.q[n]) * Vec3::z() - Vec3::z()).norm();
            assert!(tilt < 1e-12, "screw axis tilted by {tilt:e}");
            (previous, s.x[n].z - model.reference_x[n].z)
        })
        .collect()
}

/// The screw's load on the node (ground axes = global here): it balances
/// the axial force `F` (`F3 = −F`) with the torque `M3 = −(p/2π) F3`
/// (docs/joints.md §3.4), and nothing else; within 1e-9 of `scale`, the
/// full axial force.
fn check_screw_load(model: &Model, s: &State, force: f64, scale: f64, lead: f64) {
    let r = results(model, s, ElementKind::Joint, 101);
    assert!((r["F3"] + force).abs() <= 1e-9 * scale, "F3 = {}", r["F3"]);
    assert!(
        (r["M3"] + lead * r["F3"]).abs() <= 1e-9 * scale * lead,
        "M3 = {}",
        r["M3"]
    );
    let others = [r["F1"], r["F2"], r["M1"], r["M2"]];
    assert!(others.iter().all(|v| v.abs() <= 1e-9 * scale), "{others:?}");
}

/// Screw joint: the axial advance is `pitch × rotation/2π`, within 1e-10
/// relative, over two and a half turns (angles unwrapped across turns),
/// whether the rotation is driven or produced by a moment against a
/// spring.
///
/// Source: definition of the helical pair. (i) Driven: a driver turns the
/// node by `θ = 5π` while an axial force `F` acts on it; by virtual work
/// (`τ δθ + F δu = 0` with `δu = (p/2π) δθ`) the driver torque is
/// `τ = −F p/2π`. (ii) Loaded: a moment `M` about the axis against a
/// rotational spring `k` on the joint angle, with the same axial force:
/// `(M + F p/2π − kθ) δθ = 0` gives `θ = (M + F p/2π)/k`, here 8.0 rad
/// (1.27 turns). Tolerances: the constraint and the equilibrium hold to the
/// tight Newton tolerances (1e-12 m and rad), i.e. ~1e-11 of the 0.06–0.125
/// advance, checked at 1e-10; the torque 1e-9 relative (multipliers are
/// accurate to the residual, 1e-10 of the flux). The joint's own load is
/// checked by [`check_screw_load`].
#[test]
fn helical_joint_advances_by_pitch_per_turn() {
    let lead = PITCH / TAU;
    let force = -20.0;
    // (i) driven through 2.5 turns in 20 increments of 0.785 rad
    let mut m = screw();
    m.analysis.initial_increment = Some(0.05);
    m.analysis.max_increment = Some(0.05);
    m.drivers.push(joint_driver(201, 101, "angle", 5.0 * PI));
    m.loads.push(unfold::model::input::LoadInput {
        node: 1,
        force: Some([0.0, 0.0, force]),
        moment: None,
        follower: false,
        curve: None,
    });
    let (model, path) = solve(&m);
    let motion = screw_motion(&model, &path, 1);
    let mut worst = 0.0f64;
    for ((theta, u), s) in motion.iter().zip(&path.states) {
        let time = s.time;
        worst = worst.max((u - lead * theta).abs() / (lead * 5.0 * PI));
        // joint coordinates: (angle, slide) = (θ, u)
        let c = results(&model, s, ElementKind::Joint, 101);
        assert!((c["angle"] - theta).abs() < 1e-12 && (c["slide"] - u).abs() < 1e-12);
        // driver torque by virtual work, at the load F·t
        let q = results(&model, s, ElementKind::Driver, 201)["load"];
        let tau = -force * time * lead;
        assert!(
            (q - tau).abs() <= 1e-9 * (force * lead).abs(),
            "torque {q} vs {tau}"
        );
        check_screw_load(&model, s, force * time, force.abs(), lead);
    }
    let (theta, u) = *motion.last().unwrap();
    println!(
        "driven: θ = {theta:.12} ({:.3} turns), u = {u:.12}, |u − pθ/2π| ≤ {worst:.2e} of the advance",
        theta / TAU
    );
    assert!((theta - 5.0 * PI).abs() < 1e-10);
    assert!(worst < 1e-10);

    // (ii) a moment against a spring on the joint angle
    let (k, moment) = (1.0, 8.0 - force * lead);
    let mut m = screw();
    m.analysis.initial_increment = Some(0.05);
    m.analysis.max_increment = Some(0.05);
    m.joint_springs.push(linear_spring(301, 101, "angle", k));
    m.add_load(1, [0.0, 0.0, force], [0.0, 0.0, moment]);
    let (model, path) = solve(&m);
    let motion = screw_motion(&model, &path, 1);
    let mut worst = 0.0f64;
    for ((theta, u), s) in motion.iter().zip(&path.states) {
        worst = worst.max((u - lead * theta).abs() / (lead * 8.0));
        let expected = (moment + force * lead) * s.time / k;
        assert!((theta - expected).abs() < 1e-10, "θ = {theta}, {expected}");
        check_screw_load(&model, s, force * s.time, force.abs(), lead);
    }
    let (theta, u) = *motion.last().unwrap();
    println!(
        "moment and spring: θ = {theta:.12} (expected 8), u = {u:.12}, |u − pθ/2π| ≤ {worst:.2e} of the advance"
    );
    assert!(worst < 1e-10);
}

// ---------------------------------------------------------- 3. spherical

/// Spherical joint between two beams: it passes the load as a force alone.
///
/// Cantilever C (8 beams, clamped at node 1, tip node 2 at x = 1) and beam
/// D (6 beams, node 3 at x = 1.2 to node 4 at x = 2) meet at a spherical
/// joint at x = 1.1, away from both nodes (rigid offsets of 0.1 on each
/// side). Node 4's rotations are fixed (translations free) and it carries
/// the force `F`. D's equilibrium (no force from node 4's support) makes
/// the joint pass `F` to C. Large deflection (0.22 of the length).
///
/// Checks, at every increment:
/// - the joint's moment about the joint point (M1..M3) is zero to
///   round-off: `|M| ≤ 1e-12 |F| L` (it is the node moment minus
///   `arm × f`, both ~|F|·0.1, so round-off is ~1e-16 of that);
/// - the joint's force on C equals `F` within 1e-9 |F| (equilibrium of D,
///   residual at its free dofs ~1e-10 of the flux);
/// - the clamp of C reacts `−F` and exactly the moment of `F` applied at
///   the joint point (no transmitted moment), and node 4's support reacts
///   the moment of `F` about the joint point: both within 1e-9 |F| L.
#[test]
fn spherical_joint_transmits_no_moment() {
    let mut m = ModelInput::new("spherical joint between two beams");
    tight(&mut m);
    m.add_section("s", [1e6, 4e5, 4e5, 80.0, 100.0, 100.0]);
    m.add_node(1, [0.0; 3]).add_node(2, [1.0, 0.0, 0.0]);
    m.add_node(3, [1.2, 0.0, 0.0]).add_node(4, [2.0, 0.0, 0.0]);
    beam_line(&mut m, [1, 2], 8, "s", (10, 1));
    beam_line(&mut m, [3, 4], 6, "s", (30, 20));
    m.joints.push(JointInput {
        id: 101,
        kind: JointType::Spherical,
        nodes: vec![2, 3],
        position: Some([1.1, 0.0, 0.0]),
        ..Default::default()
    });
    m.fix(1, &["all"]).fix(4, &["rotations"]);
    let f = Vec3::new(3.0, -8.0, 5.0) * 8.0;
    m.add_load(4, f.into(), [0.0; 3]);
    m.analysis.initial_increment = Some(0.25);
    let (model, path) = solve(&m);
    let (n1, n2, n4) = (
        model.node_index(1).unwrap(),
        model.node_index(2).unwrap(),
        model.node_index(4).unwrap(),
    );
    let fl = f.norm() * 2.0;
    let (mut worst_m, mut worst_f, mut worst_r) = (0.0f64, 0.0f64, 0.0f64);
    for (s, res) in path.states.iter().zip(&path.residuals) {
        let load = f * s.time;
        let axes = so3::matrix(&s.q[n2]);
        let (force, moment) = joint_reaction(&model, s, 101, &axes);
        worst_m = worst_m.max(moment.norm() / fl);
        worst_f = worst_f.max((force - load).norm() / f.norm());
        // joint point on C: node 2 plus its rotated offset
        let p = s.x[n2] + so3::matrix(&s.q[n2]) * Vec3::new(0.1, 0.0, 0.0);
        // reactions (residual at fixed dofs; nodes 1 and 4 keep R = I)
        let r1 = Vec3::new(res[6 * n1], res[6 * n1 + 1], res[6 * n1 + 2]);
        let m1 = Vec3::new(res[6 * n1 + 3], res[6 * n1 + 4], res[6 * n1 + 5]);
        let m4 = Vec3::new(res[6 * n4 + 3], res[6 * n4 + 4], res[6 * n4 + 5]);
        let clamp_f = (r1 + load).norm();
        let clamp_m = (m1 + (p - s.x[n1]).cross(&load)).norm();
        let wrist_m = (m4 + (s.x[n4] - p).cross(&load)).norm();
        worst_r = worst_r
            .max(clamp_f / f.norm())
            .max(clamp_m / fl)
            .max(wrist_m / fl);
    }
    let tip = path.states.last().unwrap().x[n4] - model.reference_x[n4];
    println!(
        "tip displacement {:.3} L; joint |M| ≤ {worst_m:.1e} |F|L, |F_joint − F| ≤ {worst_f:.1e} |F|, support reactions within {worst_r:.1e}",
        tip.norm() / 2.0
    );
    assert!(tip.norm() > 0.2, "not a large deflection");
    assert!(worst_m < 1e-12);
    assert!(worst_f < 1e-9);
    assert!(worst_r < 1e-9);
}

// ------------------------------------------------- 4. revolute + spring

/// A flexible beam (4 elements, EI = 10, node 1 at the origin to node 2 at
/// x = 1) on a revolute joint to the ground at node 1 (axis z), with a
/// spring `spring` on the joint angle and the moment `M` about z at its
/// free end, in 20 increments.
fn hinged_beam(spring: JointSpringInput, moment: f64) -> ModelInput {
    let mut m = ModelInput::new("hinged beam with a joint spring");
    tight(&mut m);
    m.add_section("s", [1e5, 4e4, 4e4, 10.0, 10.0, 10.0]);
    m.add_node(1, [0.0; 3]).add_node(2, [1.0, 0.0, 0.0]);
    beam_line(&mut m, [1, 2], 4, "s", (10, 1));
    m.joints.push(joint(
        101,
        JointType::Revolute,
        &[1],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
    ));
    m.joint_springs.push(spring);
    m.add_load(2, [0.0; 3], [0.0, 0.0, moment]);
    m.analysis.initial_increment = Some(0.05);
    m.analysis.max_increment = Some(0.05);
    m
}

/// The inverse of a piecewise-linear increasing table: the `x` where it
/// equals `f` (inside the table).
fn table_inverse(table: &[[f64; 2]], f: f64) -> f64 {
    let w = table
        .windows(2)
        .find(|w| (w[0][1]..=w[1][1]).contains(&f))
        .expect("value inside the table");
    w[0][0] + (f - w[0][1]) * (w[1][0] - w[0][0]) / (w[1][1] - w[0][1])
}

/// Revolute joint with a rotational spring: the spring alone carries the
/// moment about the axis.
///
/// Source: equilibrium of the beam about the hinge axis. The end moment `M`
/// reaches the hinge node unchanged (a pure couple passes through the
/// beam, however bent), so the joint angle `θ` (the hinge node's rotation)
/// satisfies `f_s(θ) = M`: `θ = M/k` for a linear spring (1 rad here; the
/// beam end turns further, by `θ + ML/EI`), and the piecewise-linear
/// inverse `θ = table⁻¹(M)` for a table (0.72 rad, on the soft branch
/// beyond the kink at 0.3 rad). The spring applies `−f_s = −M` about the
/// axis; the revolute's constraint moment about its axis (`M3`) is zero,
/// so the moment the ground side (joint + spring) applies about the axis
/// is `M3 − f_s = −M`; the joint's force and other moments vanish (a pure
/// couple). Tolerances: angle 1e-10 rad, moments 1e-9 M (tight Newton
/// tolerances on a flexible beam: residual round-off ~1e-13 M). The load
/// is applied in 20 increments: in 10, the increment that ends on the soft
/// branch took 18 iterations (large trial rotations of the axially stiff
/// beam) and stopped 1.6e-9 rad short of the solution, because the
/// solver's estimate of the next correction (last correction × residual
/// ratio) does not see a soft mode (0.7 N·m/rad) among stiff ones
/// (4e5 N/m); the default tolerance (1e-6 rad) was met all the same.
#[test]
fn revolute_joint_spring_carries_the_axial_moment() {
    let (k, moment) = (5.0, 5.0);
    let linear = linear_spring(301, 101, "angle", k);
    // stiff (slope 5) up to 0.3 rad, then soft (slope 5/7)
    let table = vec![
        [-1.0, -2.0],
        [-0.3, -1.5],
        [0.0, 0.0],
        [0.3, 1.5],
        [1.0, 2.0],
    ];
    let nonlinear = JointSpringInput {
        id: 301,
        joint: 101,
        table: table.clone(),
        ..Default::default()
    };
    let e = triad([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    for (name, spring, moment, expected) in [
        ("linear", linear, moment, moment / k),
        ("table", nonlinear, 1.8, table_inverse(&table, 1.8)),
    ] {
        let (model, path) = solve(&hinged_beam(spring, moment));
        let s = path.states.last().unwrap();
        let hinge = model.node_index(1).unwrap();
        let theta = angle_about(&s.q[hinge], &Vec3::z(), 0.0);
        let joint = results(&model, s, ElementKind::Joint, 101);
        let spring = results(&model, s, ElementKind::JointSpring, 301);
        let (fj, mj) = joint_reaction(&model, s, 101, &e);
        let iterations: Vec<usize> = path.infos[1..].iter().map(|i| i.iterations).collect();
        println!(
            "{name}: θ = {:.15} (expected {expected:.15}), hinge node {theta:.15}, spring {:.12}, joint M3 {:.1e}, |F| {:.1e}, |M| {:.1e}; iterations {iterations:?}",
            joint["angle"],
            spring["spring"],
            joint["M3"],
            fj.norm(),
            mj.norm()
        );
        assert!((joint["angle"] - expected).abs() < 1e-10);
        assert!((theta - expected).abs() < 1e-10);
        assert!((spring["coordinate"] - joint["angle"]).abs() < 1e-14);
        assert!((spring["spring"] - moment).abs() < 1e-9 * moment);
        assert!(joint["M3"].abs() < 1e-9 * moment);
        assert!((joint["M3"] - spring["spring"] + moment).abs() < 1e-9 * moment);
        assert!(fj.norm() < 1e-9 * moment && mj.norm() < 1e-9 * moment);
    }
}

// ---------------------------------------------------------- 5. universal

/// Cardan joint between two shafts at an angle `β` = 30°.
///
/// Input shaft: node 1 at (−1, 0, 0) on a revolute joint to the ground
/// about x, driven through a full turn `φ₁: 0 → 2π` in 20 increments.
/// Output shaft: node 2 at (cos β, sin β, 0) on a revolute to the ground
/// about `u = (cos β, sin β, 0)`. The universal joint sits at the origin,
/// where the axes cross (its point equations repeat the revolutes' and are
/// removed as redundant by the rank analysis).
///
/// Derivation: with the input's cross arm `a₀` and the output's `b₀`
/// (perpendicular), the arms after the rotations are `a = R_x(φ₁) a₀` and
/// `b = R_u(φ₂) b₀`, and the joint keeps `a·b = 0`.
/// - Input arm in the plane of the shafts, `a₀ = y`, `b₀ = z`:
///   `a = (0, cos φ₁, sin φ₁)`, `b = cos φ₂ z + sin φ₂ (u × z) =
///   (sin β sin φ₂, −cos β sin φ₂, cos φ₂)`, and `a·b = 0` gives
///   `−cos φ₁ cos β sin φ₂ + sin φ₁ cos φ₂ = 0`: `tan φ₂ = tan φ₁ / cos β`.
/// - Input arm normal to that plane, `a₀ = z`, `b₀ = (−sin β, cos β, 0)`:
///   `a = (0, −sin φ₁, cos φ₁)`, `b = (−sin β cos φ₂, cos β cos φ₂, sin φ₂)`,
///   `a·b = 0` gives `tan φ₂ = cos β tan φ₁`.
///
/// The output angle is read from the output revolute's coordinate and from
/// the node's orientation, and compared with the branch of the formula
/// continuous with `φ₁`. Tolerance 1e-8 rad: the constraints hold to
/// 1e-12 (tight tolerances), so what is left is round-off.
#[test]
fn universal_joint_follows_the_cardan_law() {
    let beta: f64 = 30f64.to_radians();
    let (cb, sb) = (beta.cos(), beta.sin());
    let u = [cb, sb, 0.0];
    type Law = fn(f64, f64) -> f64;
    let in_plane: Law = |p1, cb| p1.sin().atan2(p1.cos() * cb);
    let normal: Law = |p1, cb| (p1.sin() * cb).atan2(p1.cos());
    let cases = [
        (
            "arm in the plane",
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            in_plane,
        ),
        (
            "arm normal to the plane",
            [0.0, 0.0, 1.0],
            [-sb, cb, 0.0],
            normal,
        ),
    ];
    for (name, arm_a, arm_b, law) in cases {
        let mut m = ModelInput::new("Cardan joint");
        tight(&mut m);
        m.analysis.initial_increment = Some(0.05);
        m.analysis.max_increment = Some(0.05);
        m.add_node(1, [-1.0, 0.0, 0.0]).add_node(2, [cb, sb, 0.0]);
        m.joints.push(joint(
            101,
            JointType::Revolute,
            &[1],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
        ));
        m.joints
            .push(joint(102, JointType::Revolute, &[2], u, [0.0, 0.0, 1.0]));
        m.joints.push(JointInput {
            id: 103,
            kind: JointType::Universal,
            nodes: vec![1, 2],
            axis: Some(arm_a),
            axis_b: Some(arm_b),
            position: Some([0.0; 3]),
            ..Default::default()
        });
        m.drivers.push(joint_driver(201, 101, "angle", TAU));
        let (model, path) = solve(&m);
        // the universal joint's point equations repeat the revolutes'
        assert_eq!(path.notes.len(), 1);
        assert!(path.notes[0].starts_with("3 redundant"), "{:?}", path.notes);
        let out = model.node_index(2).unwrap();
        let (mut worst, mut previous) = (0.0f64, 0.0);
        for s in &path.states {
            let phi1 = results(&model, s, ElementKind::Joint, 101)["angle"];
            let phi2 = results(&model, s, ElementKind::Joint, 102)["angle"];
            previous = angle_about(&s.q[out], &Vec3::from(u), previous);
            let formula = law(phi1, cb);
            let expected = phi1 + (formula - phi1 + PI).rem_euclid(TAU) - PI;
            worst = worst
                .max((phi2 - expected).abs())
                .max((previous - expected).abs());
        }
        let iterations: Vec<usize> = path.infos[1..].iter().map(|i| i.iterations).collect();
        println!("{name}: |φ₂ − law| ≤ {worst:.2e} rad over a turn; iterations {iterations:?}");
        let last = path.states.last().unwrap();
        let phi1 = results(&model, last, ElementKind::Joint, 101)["angle"];
        assert!((phi1 - TAU).abs() < 1e-10, "input at {phi1}");
        assert!(worst < 1e-8);
    }
}

// -------------------------------------- 6. prismatic, cylindrical, planar

/// Prismatic, cylindrical and planar joints to the ground: loads along the
/// free directions are taken by joint springs on the joint coordinates,
/// loads along the constrained directions by the joint.
///
/// One node at (0.3, −0.2, 0.5) on a joint to the ground with axis
/// `e₃ = (1, 2, 2)/3` (reference direction z), a dead force `F` and moment
/// `M` (global, generic directions) applied in one increment, and linear
/// springs on every coordinate: `k₁ = 100`, `k₂ = 250` on strokes,
/// `k_θ = 10` on the angle. Source: statics of one node; with the ground as
/// body A the coordinates are the node's displacement `u` along the fixed
/// axes `eᵢ` and its rotation `θ` about `e₃`, so each spring takes the load
/// component along its coordinate:
/// - prismatic (stroke): `u = (F·e₃/k₁) e₃`, no rotation; the joint takes
///   `−(F − (F·e₃)e₃)` and `−M`;
/// - cylindrical (angle, stroke): also `θ = M·e₃/k_θ` (0.57 rad); the joint
///   takes `−(F − (F·e₃)e₃)` and `−(M − (M·e₃)e₃)`;
/// - planar (stroke 1, stroke 2, angle): `u = (F·e₁/k₁) e₁ + (F·e₂/k₂) e₂`,
///   `θ = M·e₃/k_θ`; the joint takes `−(F·e₃)e₃` and `−(M − (M·e₃)e₃)`.
///
/// The joint's load is read in the ground's axes `e` (docs/joints.md §7).
/// Tolerances: 1e-9 relative (displacements to `|F|/k`, angles to
/// `|M|/k_θ`, loads to `|F|` and `|M|`): exact solutions, met to the tight
/// Newton tolerances.
#[test]
fn prismatic_cylindrical_planar_carry_constrained_loads() {
    let x0 = Vec3::new(0.3, -0.2, 0.5);
    let axis = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0];
    let reference = [0.0, 0.0, 1.0];
    let e = triad(axis, reference);
    let (e1, e2, e3) = (
        e.column(0).into_owned(),
        e.column(1).into_owned(),
        e.column(2).into_owned(),
    );
    let f = Vec3::new(4.0, -7.0, 3.0);
    let mm = Vec3::new(5.0, -3.0, 9.0);
    let (k1, k2, kt) = (100.0, 250.0, 10.0);
    let along = |v: &Vec3, a: &Vec3| a * v.dot(a);
    type Case = (JointType, Vec<(&'static str, f64)>, Vec3, f64, Vec3, Vec3);
    let cases: [Case; 3] = [
        (
            JointType::Prismatic,
            vec![("slide", k1)],
            e3 * (f.dot(&e3) / k1),
            0.0,
            -(f - along(&f, &e3)),
            -mm,
        ),
        (
            JointType::Cylindrical,
            vec![("slide", k1), ("angle", kt)],
            e3 * (f.dot(&e3) / k1),
            mm.dot(&e3) / kt,
            -(f - along(&f, &e3)),
            -(mm - along(&mm, &e3)),
        ),
        (
            JointType::Planar,
            vec![("slide1", k1), ("slide2", k2), ("angle", kt)],
            e1 * (f.dot(&e1) / k1) + e2 * (f.dot(&e2) / k2),
            mm.dot(&e3) / kt,
            -along(&f, &e3),
            -(mm - along(&mm, &e3)),
        ),
    ];
    for (kind, springs, u, theta, force, moment) in cases {
        let mut m = ModelInput::new("joint to the ground with springs");
        tight(&mut m);
        m.analysis.initial_increment = Some(1.0);
        m.add_node(1, x0.into());
        m.joints.push(joint(101, kind, &[1], axis, reference));
        for (k, (coordinate, stiffness)) in springs.iter().enumerate() {
            m.joint_springs
                .push(linear_spring(301 + k as u64, 101, coordinate, *stiffness));
        }
        m.add_load(1, f.into(), mm.into());
        let (model, path) = solve(&m);
        let s = path.states.last().unwrap();
        let n = model.node_index(1).unwrap();
        let du = (s.x[n] - x0 - u).norm() / (f.norm() / k1);
        let rotation = so3::log(&(so3::exp(&(e3 * theta)).inverse() * s.q[n])).norm();
        let (fj, mj) = joint_reaction(&model, s, 101, &e);
        let df = (fj - force).norm() / f.norm();
        let dm = (mj - moment).norm() / mm.norm();
        // each spring carries the load along its coordinate
        let mut ds = 0.0f64;
        for (k, (coordinate, _)) in springs.iter().enumerate() {
            let fs = results(&model, s, ElementKind::JointSpring, 301 + k as u64)["spring"];
            let expected = match *coordinate {
                "slide" => f.dot(&e3),
                "slide1" => f.dot(&e1),
                "slide2" => f.dot(&e2),
                _ => mm.dot(&e3),
            };
            ds = ds.max((fs - expected).abs() / f.norm().max(mm.norm()));
        }
        println!(
            "{}: θ = {theta:.4}, |Δu| {du:.1e}·F/k, rotation error {rotation:.1e} rad, joint force {df:.1e}·|F|, moment {dm:.1e}·|M|, springs {ds:.1e}; {} iterations",
            kind.name(),
            path.infos[1].iterations
        );
        assert!(du < 1e-9 && rotation < 1e-9 * mm.norm() / kt);
        assert!(df < 1e-9 && dm < 1e-9 && ds < 1e-9);
    }
}

// ------------------------------------------------------------- 7. slider

/// Radius, angular spacing of the curve nodes and their angles.
const ARC_RADIUS: f64 = 1.0;
const ARC_STEP: f64 = 15.0 * PI / 180.0;

/// The slider curve through `c` at parameter `s` and its derivative
/// `dC/ds`, written from docs/joints.md §3.5 (interior segments only):
/// the cubic Hermite segment between `c_k` and `c_{k+1}` with chord-length
/// Catmull–Rom tangents `dC/ds(c_i) = (c_{i+1} − c_{i−1})/(ℓ_{i−1} + ℓ_i)`,
/// `s` the distance along the polygon.
fn catmull_rom(c: &[Vec3], s: f64) -> (Vec3, Vec3) {
    let len: Vec<f64> = c.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let mut k = 0;
    let mut start = 0.0;
    while start + len[k] <= s {
        start += len[k];
        k += 1;
    }
    assert!(k >= 1 && k + 2 < c.len(), "interior segments only");
    let l = len[k];
    let t = (s - start) / l;
    let tangent = |i: usize| (c[i + 1] - c[i - 1]) / (len[i - 1] + len[i]) * l;
    let (m0, m1) = (tangent(k), tangent(k + 1));
    let (t2, t3) = (t * t, t * t * t);
    let p = c[k] * (2.0 * t3 - 3.0 * t2 + 1.0)
        + m0 * (t3 - 2.0 * t2 + t)
        + c[k + 1] * (3.0 * t2 - 2.0 * t3)
        + m1 * (t3 - t2);
    let dp = c[k] * (6.0 * t2 - 6.0 * t)
        + m0 * (3.0 * t2 - 4.0 * t + 1.0)
        + c[k + 1] * (6.0 * t - 6.0 * t2)
        + m1 * (3.0 * t2 - 2.0 * t);
    (p, dp / l)
}

/// Curvilinear slider along a circular arc given by its nodes.
///
/// Eleven fixed nodes every 15° on a circle of radius 1 (from −30° to
/// 120°) define a spline; node 1 starts on the curve node at 0° (rotations
/// fixed) and a node driver moves it along `d = (−1, 1, 0)/√2` by `√2`,
/// which brings it along the arc to 90° in 20 increments (`d` is never
/// normal to the arc in between, so the driver determines the motion).
/// A dead force `F` acts on the node as well.
///
/// Checks:
/// - the node is on the spline, at its parameter `s`: `|x − C(s)| ≤ 1e-9`
///   (the constraint, met to the tight tolerance 1e-12; `C` evaluated by
///   the independent [`catmull_rom`]);
/// - the node is on the circle within the spline's interpolation error.
///   For uniform spacing `α` on a circle the chord-length Catmull–Rom
///   tangents have length `R sin α` (in the segment parameter) instead of
///   the circle's `R α`, and the Hermite midpoint lies inside the circle
///   by `R (1 − cos(α/2) − sin α sin(α/2)/4) ≈ (3/128) R α⁴` (1.10e-4 R for
///   15°). The largest deviation of the spline, found by sampling the
///   interior segments, must agree with that expansion (to its relative
///   O(α²) remainder, 10 %), and the node must be within it (+1e-9);
/// - `s` increases monotonically from 2 chords (the node at 0°) to 8
///   (the curve node at 90°), where the driven displacement brings it;
/// - the slider transmits no force along the curve: its reaction is normal
///   to `C'(s)` (1e-9 |F|), and by virtual work the driver's load is
///   `Q = −F·C'/(d·C')` (1e-9 |F|).
#[test]
fn slider_follows_a_circular_spline() {
    let r = ARC_RADIUS;
    let nodes: Vec<Vec3> = (0..11)
        .map(|i| {
            let phi = (i as f64 - 2.0) * ARC_STEP;
            Vec3::new(r * phi.cos(), r * phi.sin(), 0.0)
        })
        .collect();
    let mut m = ModelInput::new("slider on an arc");
    tight(&mut m);
    m.analysis.initial_increment = Some(0.05);
    m.analysis.max_increment = Some(0.05);
    m.add_node(1, [r, 0.0, 0.0]);
    for (i, x) in nodes.iter().enumerate() {
        m.add_node(11 + i as u64, (*x).into());
        m.fix(11 + i as u64, &["all"]);
    }
    m.fix(1, &["rotations"]);
    m.joints.push(JointInput {
        id: 101,
        kind: JointType::Slider,
        nodes: vec![1],
        curve: (11..22).collect(),
        ..Default::default()
    });
    let d = Vec3::new(-1.0, 1.0, 0.0) / 2f64.sqrt();
    m.drivers.push(DriverInput {
        id: 201,
        node: Some(1),
        direction: Some(d.into()),
        value: 2f64.sqrt() * r,
        ..Default::default()
    });
    let f = Vec3::new(1.0, -3.0, 2.0);
    m.loads.push(unfold::model::input::LoadInput {
        node: 1,
        force: Some(f.into()),
        moment: None,
        follower: false,
        curve: Some("constant".into()),
    });
    constant_curve(&mut m);
    let (model, path) = solve(&m);

    // the spline's own deviation from the circle, interior segments
    let len = (nodes[1] - nodes[0]).norm();
    let mut spline_dev = 0.0f64;
    for j in 0..=6000 {
        let s = len * (1.0 + 7.0 * j as f64 / 6000.0);
        let (p, _) = catmull_rom(&nodes, s.min(8.0 * len - 1e-12));
        spline_dev = spline_dev.max((p.norm() - r).abs());
    }
    let a = ARC_STEP;
    let midpoint = r * (1.0 - (a / 2.0).cos() - a.sin() * (a / 2.0).sin() / 4.0);
    let expansion = 3.0 / 128.0 * r * a.powi(4);
    println!(
        "spline vs circle: max deviation {spline_dev:.4e} R, midpoint {midpoint:.4e} R, (3/128)α⁴ = {expansion:.4e} R"
    );
    assert!((spline_dev - expansion).abs() < 0.1 * expansion);

    let n = model.node_index(1).unwrap();
    let (mut on_spline, mut on_circle, mut along, mut driver) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    // the node starts on the curve node at 0°, two chords along the curve
    let s0 = results(&model, &path.states[0], ElementKind::Joint, 101)["s"];
    assert!((s0 - 2.0 * len).abs() < 1e-12, "s0 = {s0}");
    let mut last_s = f64::NEG_INFINITY;
    for st in &path.states {
        let x = st.x[n];
        let joint = results(&model, st, ElementKind::Joint, 101);
        let s = joint["s"];
        assert!(s > last_s, "s does not increase: {s} after {last_s}");
        last_s = s;
        let (c, dc) = catmull_rom(&nodes, s);
        on_spline = on_spline.max((x - c).norm() / r);
        on_circle = on_circle.max((x.norm() - r).abs() / r);
        // the slider's load on the node, in its (fixed) material axes
        let reaction = Vec3::new(joint["F1"], joint["F2"], joint["F3"]);
        along = along.max(reaction.dot(&dc).abs() / (dc.norm() * f.norm()));
        let q = results(&model, st, ElementKind::Driver, 201)["load"];
        driver = driver.max((q + f.dot(&dc) / d.dot(&dc)).abs() / f.norm());
    }
    let end = path.states.last().unwrap().x[n];
    println!(
        "node: |x − C(s)| ≤ {on_spline:.1e} R, ||x| − R| ≤ {on_circle:.3e} R, force along the curve {along:.1e} |F|, driver load error {driver:.1e} |F|; end at {:?}, s = {last_s:.6} (8 chords = {:.6}); iterations {:?}",
        end,
        8.0 * len,
        path.infos[1..].iter().map(|i| i.iterations).collect::<Vec<_>>()
    );
    assert!(on_spline < 1e-9);
    assert!(on_circle <= spline_dev + 1e-9);
    assert!((end - Vec3::new(0.0, r, 0.0)).norm() < 1e-9);
    assert!((last_s - 8.0 * len).abs() < 1e-9);
    assert!(along < 1e-9 && driver < 1e-9);
}

// ---------------------------------------------------------- 8. glue, rigid

/// A clamped cantilever of two beam lines (5 elements each, EI = 10,
/// 1 → 2 → 3 along x), loaded at node 3 by a dead force and moment growing
/// to a large 3-D deflection. `join` = `None`: the lines share node 2;
/// otherwise the second line starts at a node 4 coincident with node 2,
/// joined to it by a joint of that type.
fn two_part_cantilever(join: Option<JointType>) -> ModelInput {
    let mut m = ModelInput::new("cantilever in two parts");
    tight(&mut m);
    m.add_section("s", [1e5, 4e4, 4e4, 8.0, 10.0, 10.0]);
    m.add_node(1, [0.0; 3]).add_node(2, [1.0, 0.0, 0.0]);
    m.add_node(3, [2.0, 0.0, 0.0]);
    beam_line(&mut m, [1, 2], 5, "s", (10, 1));
    match join {
        None => beam_line(&mut m, [2, 3], 5, "s", (20, 10)),
        Some(kind) => {
            m.add_node(4, [1.0, 0.0, 0.0]);
            beam_line(&mut m, [4, 3], 5, "s", (20, 10));
            m.joints.push(JointInput {
                id: 101,
                kind,
                nodes: vec![2, 4],
                ..Default::default()
            });
        }
    }
    m.fix(1, &["all"]);
    m.add_load(3, [0.0, 1.0, 2.0], [1.0, -0.5, 2.0]);
    m
}

/// A clamped cantilever (5 elements, 1 → 2) whose tip carries, at the
/// offset `h` (in the tip's frame), a rigid body on node 5: glued to the
/// tip (`Glue`) or linked to it by a rigid joint (`Rigid`), or `None`: no
/// body, the loads at the tip itself.
fn cantilever_with_body(link: Option<JointType>, force: [f64; 3], moment: [f64; 3]) -> ModelInput {
    let mut m = ModelInput::new("cantilever with a rigid body at an offset");
    tight(&mut m);
    m.add_section("s", [1e5, 4e4, 4e4, 8.0, 10.0, 10.0]);
    m.add_node(1, [0.0; 3]).add_node(2, [1.0, 0.0, 0.0]);
    beam_line(&mut m, [1, 2], 5, "s", (10, 1));
    m.fix(1, &["all"]);
    match link {
        None => {
            m.add_load(2, force, moment);
        }
        Some(kind) => {
            m.add_node(5, [1.0, 0.3, -0.2]);
            m.rigid_bodies.push(RigidBodyInput {
                id: 50,
                node: 5,
                mass: 2.0,
                inertia: None,
                center_of_mass: None,
                shape: None,
            });
            m.joints.push(JointInput {
                id: 101,
                kind,
                nodes: vec![2, 5],
                ..Default::default()
            });
            m.add_load(5, force, moment);
        }
    }
    m
}

/// Largest distance between the positions of common nodes (relative to
/// `scale`) and between their orientations (rad) in two final states.
fn state_difference(a: (&Model, &Path), b: (&Model, &Path), ids: &[Id], scale: f64) -> (f64, f64) {
    let (sa, sb) = (a.1.states.last().unwrap(), b.1.states.last().unwrap());
    let (mut dx, mut dq) = (0.0f64, 0.0f64);
    for &id in ids {
        let (na, nb) = (a.0.node_index(id).unwrap(), b.0.node_index(id).unwrap());
        dx = dx.max((sa.x[na] - sb.x[nb]).norm() / scale);
        dq = dq.max(so3::log(&(sa.q[na].inverse() * sb.q[nb])).norm());
    }
    (dx, dq)
}

/// Glue and rigid joints make rigid connections.
///
/// (i) A cantilever in two beam lines joined at coincident nodes by a glue
/// joint (rotations locked) or a rigid joint deflects like the continuous
/// cantilever built with a shared node, under a 3-D tip force and moment
/// (large deflection, ~0.5 of its length): every node within 1e-9 of the
/// tip displacement, rotations within 1e-9 rad. Source: a rigid
/// connection of two nodes is the shared node. Tolerance: the constraints
/// hold to 1e-12 and both models converge to the tight tolerances; the
/// difference is round-off amplified by the condition of the bent
/// structure.
///
/// (ii) A rigid body at an offset `h` from a cantilever's tip, glued to it
/// (or rigidly joined), loaded by a moment `M`: a couple passes through a
/// rigid link unchanged, so the cantilever is the shared-node cantilever
/// with `M` at its tip (a roll-up into an arc of 90°), and the body sits
/// at `x_tip + R_tip h` with the tip's orientation; within 1e-9 (relative
/// to the tip displacement) and 1e-9 rad.
///
/// (iii) The same body under a force at the offset: glue and rigid joints
/// (different constraint equations: glue holds node B at A's material
/// offset, rigid holds both to the joint point on A) give the same
/// deflection within 1e-9.
#[test]
fn glue_and_rigid_joints_are_rigid_connections() {
    // (i)
    let (m0, p0) = solve(&two_part_cantilever(None));
    let ids: Vec<Id> = [1, 2, 3].into_iter().chain(10..14).chain(20..24).collect();
    let tip = {
        let s = p0.states.last().unwrap();
        let n = m0.node_index(3).unwrap();
        (s.x[n] - m0.reference_x[n]).norm()
    };
    for kind in [JointType::Glue, JointType::Rigid] {
        let (m1, p1) = solve(&two_part_cantilever(Some(kind)));
        let (dx, dq) = state_difference((&m0, &p0), (&m1, &p1), &ids, tip);
        let (s1, n2, n4) = (
            p1.states.last().unwrap(),
            m1.node_index(2).unwrap(),
            m1.node_index(4).unwrap(),
        );
        let gap = (s1.x[n2] - s1.x[n4]).norm();
        println!(
            "{} at coincident nodes: tip displacement {:.3} L, positions within {dx:.1e}, rotations {dq:.1e} rad, gap {gap:.1e}; iterations {:?} vs {:?}",
            kind.name(),
            tip / 2.0,
            p1.infos[1..].iter().map(|i| i.iterations).collect::<Vec<_>>(),
            p0.infos[1..].iter().map(|i| i.iterations).collect::<Vec<_>>()
        );
        assert!(tip / 2.0 > 0.3, "not a large deflection");
        assert!(dx < 1e-9 && dq < 1e-9);
    }

    // (ii) a moment through an offset body: roll-up by M L/EI = π/2
    let moment = [0.0, 0.0, PI / 2.0 * 10.0];
    let (m0, p0) = solve(&cantilever_with_body(None, [0.0; 3], moment));
    let s0 = p0.states.last().unwrap();
    let t0 = m0.node_index(2).unwrap();
    let tip = (s0.x[t0] - m0.reference_x[t0]).norm();
    let ids: Vec<Id> = [1, 2].into_iter().chain(10..14).collect();
    let h = Vec3::new(0.0, 0.3, -0.2);
    for kind in [JointType::Glue, JointType::Rigid] {
        let (m1, p1) = solve(&cantilever_with_body(Some(kind), [0.0; 3], moment));
        let (dx, dq) = state_difference((&m0, &p0), (&m1, &p1), &ids, tip);
        let s1 = p1.states.last().unwrap();
        let (t1, b1) = (m1.node_index(2).unwrap(), m1.node_index(5).unwrap());
        let body = (s1.x[b1] - s1.x[t1] - so3::matrix(&s1.q[t1]) * h).norm() / tip;
        let body_q = so3::log(&(s1.q[t1].inverse() * s1.q[b1])).norm();
        println!(
            "{} body at an offset, end moment: tip rotation {:.6} rad, cantilever within {dx:.1e}/{dq:.1e} rad, body off its point by {body:.1e}, turned by {body_q:.1e} rad",
            kind.name(),
            so3::log(&s1.q[t1]).norm()
        );
        assert!(dx < 1e-9 && dq < 1e-9 && body < 1e-9 && body_q < 1e-9);
    }

    // (iii) a force at the offset: glue and rigid agree
    let force = [1.0, -4.0, 6.0];
    let (mg, pg) = solve(&cantilever_with_body(
        Some(JointType::Glue),
        force,
        [0.0; 3],
    ));
    let (mr, pr) = solve(&cantilever_with_body(
        Some(JointType::Rigid),
        force,
        [0.0; 3],
    ));
    let s = pg.states.last().unwrap();
    let n5 = mg.node_index(5).unwrap();
    let disp = (s.x[n5] - mg.reference_x[n5]).norm();
    let ids: Vec<Id> = [1, 2, 5].into_iter().chain(10..14).collect();
    let (dx, dq) = state_difference((&mg, &pg), (&mr, &pr), &ids, disp);
    println!("force at the offset: body displacement {disp:.3}, glue vs rigid within {dx:.1e}, {dq:.1e} rad");
    assert!(disp > 0.2, "not a large deflection");
    assert!(dx < 1e-9 && dq < 1e-9);
}
