//! Elements: everything that contributes to the residual and its
//! matrices.
//!
//! Beams, shells, rigid bodies, point masses, springs, nodal loads and
//! joints are all elements behind one small trait, [`Element`]; the assembler does not
//! know which is which. The same trait carries what analyses need:
//! - generalised coordinates ([`Element::n_coordinates`]: a slider's curve
//!   parameter, modal amplitudes) and Lagrange multipliers
//!   ([`Element::n_multipliers`]) owned by an element. They follow the node
//!   unknowns in the element's local vector, coordinates first;
//! - internal variables ([`Element::n_internal`]): unwrapped angles,
//!   hysteresis, latch states, read from the last converged state and
//!   updated at convergence;
//! - inertia and damping: in one evaluation an element writes its residual,
//!   its stiffness `∂r/∂q` and its inertia matrix
//!   `w_d ∂r/∂v + w_m ∂r/∂v̇`, each only when asked ([`Need`]); inertia
//!   and damping forces enter the residual when [`EvalContext::dynamics`]
//!   says so (docs/theory.md §12).
//!
//! ## Local unknowns and sign convention
//! A node contributes 6 local unknowns: the translation increment `Δx`
//! (global frame) and the incremental *material* rotation `ΔΘ`, with the
//! update `R ← R exp(ΔΘ~)` ([`crate::state::State::displace_node`],
//! docs/theory.md §2). Its velocity and acceleration are `(ẋ, Ω)` and
//! `(ẍ, Ω̇)`, `Ω` material. An element writes its contribution to the
//! residual `r = f_int − f_ext + f_inertia` (so a load enters with a minus
//! sign) and to its matrices, column-major, derivatives in `q` taken along
//! the update above at fixed velocities and accelerations.

pub mod beam;
pub mod inertia;
mod kind;
pub mod laminate;
pub mod load;
pub mod mass;
pub mod shape;
pub mod shell;
pub mod spring;
pub mod superelement;

use crate::curves::Curve;
use crate::model::Id;
use crate::so3::Vec3;
use crate::state::State;

pub use kind::{CellField, CellShape, ElementKind};

/// Weights of the inertia matrix an element writes:
/// `damping·∂r/∂v + mass·∂r/∂v̇`. The generalised-α integrator asks for
/// `(γ′, β′)` (docs/theory.md §12), a modal analysis for `(0, 1)` (the mass
/// matrix alone).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InertiaWeights {
    /// Weight of the damping matrix `∂r/∂v`.
    pub damping: f64,
    /// Weight of the mass matrix `∂r/∂v̇`.
    pub mass: f64,
}

/// Which local matrices an evaluation asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Need {
    /// The stiffness `∂r/∂q`.
    pub stiffness: bool,
    /// The inertia matrix with these weights.
    pub inertia: Option<InertiaWeights>,
}

impl Need {
    /// The residual alone.
    pub const RESIDUAL: Need = Need {
        stiffness: false,
        inertia: None,
    };
    /// The residual and the stiffness (statics).
    pub const STIFFNESS: Need = Need {
        stiffness: true,
        inertia: None,
    };

    /// The residual, the stiffness and the inertia matrix with weights
    /// `damping` and `mass`.
    pub fn with_inertia(damping: f64, mass: f64) -> Need {
        Need {
            stiffness: true,
            inertia: Some(InertiaWeights { damping, mass }),
        }
    }

    /// The residual, with the stiffness if `stiffness`.
    pub fn stiffness(stiffness: bool) -> Need {
        Need {
            stiffness,
            inertia: None,
        }
    }

    /// Whether any matrix is wanted.
    pub fn any_matrix(&self) -> bool {
        self.stiffness || self.inertia.is_some()
    }
}

/// What every element may read besides the state.
#[derive(Clone, Copy, Debug)]
pub struct EvalContext<'a> {
    /// Load parameter (pseudo-time in statics, time in dynamics).
    pub time: f64,
    /// All load curves of the model.
    pub curves: &'a [Curve],
    /// Gravity acceleration at `time` (already scaled by its curve).
    pub gravity: Vec3,
    /// Which matrices are wanted; the buffers of [`ElementOutput`] are
    /// given exactly for these.
    pub need: Need,
    /// Whether inertia and damping forces enter the residual (and their
    /// derivatives in `q` the stiffness): true in dynamics, false in
    /// statics, where velocities and accelerations are zero. The inertia
    /// matrix, when asked, is written either way.
    pub dynamics: bool,
    /// Scaling and penalty of constraint equations (eq. 17).
    pub scaling: ConstraintScaling,
}

impl EvalContext<'_> {
    /// The same context asking for `need`.
    pub fn with_need(&self, need: Need) -> Self {
        Self { need, ..*self }
    }
}

/// What a constraint equation measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConstraintKind {
    /// A distance (its multiplier times `k` is a force).
    Distance,
    /// An angle (its multiplier times `k` is a moment).
    Angle,
}

/// Scaling factor `k` and penalty `p` of the augmented Lagrangian
/// `F* = F − k λ·Φ + ½ p |Φ|²` (paper eq. 17), for constraints on
/// distances (`force`) and on angles (`moment`). Defaults are set by the
/// analysis from the stiffness of the model (docs/joints.md §1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstraintScaling {
    /// `(k, p)` of distance constraints.
    pub force: (f64, f64),
    /// `(k, p)` of angle constraints.
    pub moment: (f64, f64),
    /// `τ`: velocity constraints `A(q) v = 0` (rolling, paper eq. 15)
    /// enter the residual as the lengths `τ A v`, scaled as distance
    /// constraints. 1 by default; `1/γ′` in the iterations of the
    /// generalised-α method, so that their rows of the iteration matrix
    /// are `A + τ ∂(Av)/∂q`, of the order of a holonomic constraint's `B`
    /// (docs/joints.md §3.8, docs/theory.md D8).
    pub rate_time: f64,
}

impl ConstraintScaling {
    /// `(k, p)` of constraints of `kind`.
    pub fn of(&self, kind: ConstraintKind) -> (f64, f64) {
        match kind {
            ConstraintKind::Distance => self.force,
            ConstraintKind::Angle => self.moment,
        }
    }
}

impl Default for ConstraintScaling {
    fn default() -> Self {
        Self {
            force: (1.0, 1.0),
            moment: (1.0, 1.0),
            rate_time: 1.0,
        }
    }
}

/// Where an element's coordinates, multipliers and internal variables
/// start in [`State::coordinates`], [`State::multipliers`] and
/// [`State::internal`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Offsets {
    /// First coordinate.
    pub coordinates: usize,
    /// First multiplier.
    pub multipliers: usize,
    /// First internal variable.
    pub internal: usize,
}

/// A point an element attaches to one of its nodes or to the ground (see
/// [`Element::attachments`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attachment {
    /// The node carrying it; `None` for the ground.
    pub node: Option<usize>,
    /// Where it is, global frame.
    pub point: Vec3,
    /// The axes it carries (columns), global frame.
    pub axes: crate::so3::Mat3,
}

/// Where an element writes its contributions: the residual always, and
/// each local matrix (`n × n`, column-major) when the context asks for it
/// ([`EvalContext::need`]). Buffers are zeroed by the caller; an element
/// adds to them.
pub struct ElementOutput<'a> {
    /// Local residual `f_int − f_ext + f_inertia`, length
    /// `n = 6·nodes + coordinates + multipliers`.
    pub residual: &'a mut [f64],
    /// `∂r/∂q`, when asked.
    pub stiffness: Option<&'a mut [f64]>,
    /// `w_d ∂r/∂v + w_m ∂r/∂v̇` with the weights of
    /// [`EvalContext::need`], when asked.
    pub inertia: Option<&'a mut [f64]>,
}

impl<'a> ElementOutput<'a> {
    /// The residual alone.
    pub fn residual(residual: &'a mut [f64]) -> Self {
        Self {
            residual,
            stiffness: None,
            inertia: None,
        }
    }

    /// The residual and the stiffness.
    pub fn with_stiffness(residual: &'a mut [f64], stiffness: &'a mut [f64]) -> Self {
        Self {
            residual,
            stiffness: Some(stiffness),
            inertia: None,
        }
    }
}

/// A finite element of the mechanism.
pub trait Element: Send + Sync {
    /// The element's kind.
    fn kind(&self) -> ElementKind;

    /// The element's id in the model file.
    fn id(&self) -> Id;

    /// Indices of the nodes it connects (into the model's node list).
    fn nodes(&self) -> &[usize];

    /// Number of generalised coordinates it owns (a slider's parameter,
    /// modal amplitudes).
    fn n_coordinates(&self) -> usize {
        0
    }

    /// Number of Lagrange multipliers it owns (one per constraint
    /// equation).
    fn n_multipliers(&self) -> usize {
        0
    }

    /// Number of internal variables it keeps between converged states.
    fn n_internal(&self) -> usize {
        0
    }

    /// Tells the element where its coordinates, multipliers and internal
    /// variables start in the state (called once when the element joins a
    /// model).
    fn set_offsets(&mut self, _offsets: Offsets) {}

    /// Values of the coordinates in the reference state (zero by default;
    /// a slider's curve parameter starts where the node is).
    fn initial_coordinates(&self, _out: &mut [f64]) {}

    /// The displacement a unit change of coordinate `k` makes (1 for a
    /// coordinate that is a length, such as a slider's parameter; a modal
    /// amplitude declares the largest displacement of its mode): the scale
    /// of its correction and of its generalised force in the convergence
    /// test (docs/theory.md §7.1).
    fn coordinate_length(&self, _k: usize) -> f64 {
        1.0
    }

    /// What constraint equation `k` measures, for its scaling and its
    /// tolerance.
    fn multiplier_kind(&self, _k: usize) -> ConstraintKind {
        ConstraintKind::Distance
    }

    /// Whether constraint equation `k` is a velocity constraint
    /// `A(q) v = 0` (rolling, paper eq. 15) rather than a holonomic one:
    /// its row of the iteration matrix comes from `∂r/∂v`, and the
    /// initial conditions of a dynamic analysis treat it at velocity
    /// level (docs/theory.md D9–D10).
    fn velocity_constraint(&self, _k: usize) -> bool {
        false
    }

    /// Whether the element's constraints act at `time` in `state` (a
    /// driver outside its window, an open contact do not). When this
    /// changes, the analysis runs the rank analysis of the constraints
    /// again (docs/joints.md §5).
    fn constraints_active(&self, _time: f64, _state: &State) -> bool {
        true
    }

    /// The element as a joint of the joint library, for its type and
    /// coordinates in the outputs (`joints.csv`, docs/results.md).
    fn as_joint(&self) -> Option<&crate::joints::Joint> {
        None
    }

    /// The element as a latch, for the analyses that lock latches
    /// (docs/joints.md §6.2).
    fn as_latch(&self) -> Option<&crate::joints::Latch> {
        None
    }

    /// The element as a unilateral stop, for the analyses that watch
    /// contacts (docs/joints.md §6.3).
    fn as_stop(&self) -> Option<&crate::joints::Stop> {
        None
    }

    /// The element as a superelement, for the recovery of its original
    /// mesh in the outputs (docs/theory.md §18.7).
    fn as_superelement(&self) -> Option<&superelement::Superelement> {
        None
    }

    /// The element as a shell, for its stress recovery
    /// ([`shell::Shell::layer_stresses`]).
    fn as_shell(&self) -> Option<&shell::Shell> {
        None
    }

    /// New values of the internal variables after the state has converged
    /// (unwrapped joint angles, hysteresis); `internal` holds the old ones.
    fn update_internal(&self, _ctx: &EvalContext, _state: &State, _internal: &mut [f64]) {}

    /// Checks that the element's law holds along a converged step from
    /// `before` to `after` (consecutive converged states): `Some(why)` if
    /// the step took the element where its law does not hold (a relative
    /// rotation measured by the principal logarithm passing half a turn,
    /// where it jumps by a full turn: docs/theory.md §3.1, §5). The
    /// analysis then stops.
    fn law_violated(&self, _before: &State, _after: &State) -> Option<String> {
        None
    }

    /// An angle the element imposes as `amplitude·f(t)` (a driver on an
    /// angle): its amplitude and curve `f`. The step controller keeps the
    /// change of such angles within an increment below half a turn
    /// ([`crate::model::Model::rotation_step_limit`]).
    fn imposed_angle(&self) -> Option<(f64, crate::curves::CurveIndex)> {
        None
    }

    /// Size of the local vector: 6 per node, then the coordinates and the
    /// multipliers.
    fn n_local(&self) -> usize {
        6 * self.nodes().len() + self.n_coordinates() + self.n_multipliers()
    }

    /// Adds the residual and the matrices the context asks for at the
    /// current state (see [`ElementOutput`]).
    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput);

    /// Names of the result quantities reported by [`Element::results`].
    fn result_names(&self) -> &'static [&'static str] {
        &[]
    }

    /// Result quantities (section forces, spring forces...) for the current
    /// state, in the order of [`Element::result_names`].
    fn results(&self, _ctx: &EvalContext, _state: &State, _out: &mut [f64]) {}

    /// Elastic energy stored in the element (beams, springs).
    fn strain_energy(&self, _ctx: &EvalContext, _state: &State) -> f64 {
        0.0
    }

    /// Kinetic energy of the element's inertia (docs/theory.md I1, I7).
    fn kinetic_energy(&self, _state: &State) -> f64 {
        0.0
    }

    /// Linear momentum and angular momentum about the global origin of the
    /// element's inertia (docs/theory.md I6), global frame; zero without
    /// inertia.
    fn momenta(&self, _state: &State) -> inertia::Momenta {
        inertia::Momenta::default()
    }

    /// Potential of the weight, `−m g·x_c` with `x_c` the centre of mass
    /// and `g` the gravity of `ctx`.
    fn weight_potential(&self, _ctx: &EvalContext, _state: &State) -> f64 {
        0.0
    }

    /// Power dissipated by the element's dampers (non-negative), in
    /// dynamics.
    fn dissipated_power(&self, _ctx: &EvalContext, _state: &State) -> f64 {
        0.0
    }

    /// The element's forces that have no potential and are not inertia
    /// forces, in dynamics: the dampers' forces (`Element::dissipated_power`
    /// is their power) and the moment of a hinge law. Added to `out`
    /// (length [`Element::n_local`]) as the residual carries them, so that
    /// their work over a step of increments `δ` is `½ (f_n + f_{n+1})·δ`
    /// (docs/theory.md D12a). None by default.
    fn nonconservative_forces(&self, _ctx: &EvalContext, _state: &State, _out: &mut [f64]) {}

    /// Points of the element carried by its nodes (joint points), for
    /// drawing: each is drawn joined to its node, so that a rigid link is
    /// seen from its node to its joints. Appended to `out`.
    fn attachments(&self, _state: &State, _out: &mut Vec<Attachment>) {}

    /// How the element is drawn in VTK files.
    fn cell_shape(&self) -> CellShape {
        CellShape::None
    }

    /// The solid drawn for the element, carried by its first node (a
    /// rigid body's box, plate or cylinder), in place of its
    /// [`Element::cell_shape`]; none by default.
    fn body_shape(&self) -> Option<&shape::BodyShape> {
        None
    }

    /// Mass carried by the element (for model summaries and checks).
    fn mass(&self) -> f64 {
        0.0
    }
}

/// Adds a 3×3 block into a column-major `n × n` buffer at (row, col).
#[inline]
pub(crate) fn add_block(buf: &mut [f64], n: usize, row: usize, col: usize, m: &crate::so3::Mat3) {
    for j in 0..3 {
        let base = (col + j) * n + row;
        for i in 0..3 {
            buf[base + i] += m[(i, j)];
        }
    }
}

/// Adds `w·m` (an `N × N` matrix) into a column-major `n × n` buffer at
/// (row, row).
#[inline]
pub(crate) fn add_scaled<const N: usize>(
    buf: &mut [f64],
    n: usize,
    row: usize,
    w: f64,
    m: &nalgebra::SMatrix<f64, N, N>,
) {
    // column by column on slices: no bounds check per entry, vectorised
    for (j, column) in m.as_slice().chunks_exact(N).enumerate() {
        let base = (row + j) * n + row;
        for (b, &v) in buf[base..base + N].iter_mut().zip(column) {
            *b += w * v;
        }
    }
}

/// Adds to `out` the share of `element`'s residual that only dynamic
/// evaluations carry: for an element without inertia whose dampers act in
/// dynamics only (springs, joint springs, latches), the dampers' forces.
pub(crate) fn damper_share(
    element: &dyn Element,
    ctx: &EvalContext,
    state: &State,
    out: &mut [f64],
) {
    let n = element.n_local();
    let mut r = vec![0.0; 2 * n];
    let (dynamic, quasi_static) = r.split_at_mut(n);
    let ctx = EvalContext {
        dynamics: true,
        ..ctx.with_need(Need::RESIDUAL)
    };
    element.evaluate(&ctx, state, &mut ElementOutput::residual(dynamic));
    let ctx = EvalContext {
        dynamics: false,
        ..ctx
    };
    element.evaluate(&ctx, state, &mut ElementOutput::residual(quasi_static));
    for ((o, d), s) in out.iter_mut().zip(dynamic.iter()).zip(quasi_static.iter()) {
        *o += d - s;
    }
}

/// Adds a 3-vector into a buffer at `row`.
#[inline]
pub(crate) fn add_vec(buf: &mut [f64], row: usize, v: &Vec3) {
    buf[row] += v.x;
    buf[row + 1] += v.y;
    buf[row + 2] += v.z;
}

/// The motion of node `node` in `state`, for the inertia kernels.
pub(crate) fn node_motion(state: &State, node: usize) -> inertia::NodeMotion {
    let (v, a) = (&state.velocity[node], &state.acceleration[node]);
    inertia::NodeMotion {
        position: state.x[node],
        rotation: state.q[node],
        velocity: Vec3::new(v[0], v[1], v[2]),
        angular_velocity: Vec3::new(v[3], v[4], v[5]),
        acceleration: Vec3::new(a[0], a[1], a[2]),
        angular_acceleration: Vec3::new(a[3], a[4], a[5]),
    }
}

#[cfg(test)]
pub(crate) mod testing {
    //! Finite-difference checks of the element matrices, shared by the
    //! element tests: the stiffness against central differences of the
    //! residual in `q` (along the update rule of
    //! [`State::displace_local`]), the damping and mass matrices against
    //! differences in the velocities and the accelerations. The element's
    //! coordinates and multipliers are at offset 0 of the state in these
    //! tests.
    use super::*;

    /// A random node motion `[ẋ, Ω, ẍ, Ω̇]`: velocities up to 10 m/s,
    /// spins of 20 to 50 rad/s about a random axis, accelerations up to
    /// ~170 m/s² and angular accelerations up to ~900 rad/s².
    pub fn motion() -> impl proptest::strategy::Strategy<Value = [Vec3; 4]> {
        use proptest::prelude::*;
        let v = |m: f64| (-m..m, -m..m, -m..m).prop_map(|(a, b, c)| Vec3::new(a, b, c));
        let spin = (v(1.0), 20.0..50.0f64).prop_filter_map("zero axis", |(a, w)| {
            (a.norm() > 1e-3).then(|| a * (w / a.norm()))
        });
        (v(10.0), spin, v(100.0), v(500.0)).prop_map(|(x, w, a, w_dot)| [x, w, a, w_dot])
    }

    /// Sets the velocity and acceleration of `node` to `m = [ẋ, Ω, ẍ, Ω̇]`.
    pub fn set_motion(state: &mut State, node: usize, m: &[Vec3; 4]) {
        for c in 0..3 {
            state.velocity[node][c] = m[0][c];
            state.velocity[node][c + 3] = m[1][c];
            state.acceleration[node][c] = m[2][c];
            state.acceleration[node][c + 3] = m[3][c];
        }
    }

    /// Residual, stiffness and inertia matrix of `e` (the inertia matrix
    /// with the weights of `ctx`, empty when it asks for none).
    pub fn eval_all(e: &dyn Element, ctx: &EvalContext, state: &State) -> [Vec<f64>; 3] {
        let n = e.n_local();
        let mut r = vec![0.0; n];
        let mut k = vec![0.0; if ctx.need.stiffness { n * n } else { 0 }];
        let mut d = vec![0.0; if ctx.need.inertia.is_some() { n * n } else { 0 }];
        e.evaluate(
            ctx,
            state,
            &mut ElementOutput {
                residual: &mut r,
                stiffness: ctx.need.stiffness.then_some(&mut k[..]),
                inertia: ctx.need.inertia.is_some().then_some(&mut d[..]),
            },
        );
        [r, k, d]
    }

    /// Residual and stiffness of `e`.
    pub fn eval(e: &dyn Element, ctx: &EvalContext, state: &State) -> (Vec<f64>, Vec<f64>) {
        let [r, k, _] = eval_all(e, &ctx.with_need(Need::STIFFNESS), state);
        (r, k)
    }

    /// The state with local unknown `k` of `e` moved by `h`.
    pub fn moved(state: &State, e: &dyn Element, k: usize, h: f64) -> State {
        let mut s = state.clone();
        s.displace_local(e.nodes(), e.n_coordinates(), &Offsets::default(), k, h);
        s
    }

    /// Largest difference between `analytic` (column-major `n × n`) and the
    /// central differences `(r(+h) − r(−h))/2h` of the residual, column `j`
    /// from `moved(j, ±h)`, relative to the largest entry of either (a
    /// zero analytic matrix passes only if the differences vanish too).
    fn fd_error(
        e: &dyn Element,
        ctx: &EvalContext,
        analytic: &[f64],
        h: f64,
        moved: impl Fn(usize, f64) -> State,
    ) -> f64 {
        let n = e.n_local();
        let ctx = ctx.with_need(Need::RESIDUAL);
        let mut fd = vec![0.0; n * n];
        for j in 0..n {
            let [rp, ..] = eval_all(e, &ctx, &moved(j, h));
            let [rm, ..] = eval_all(e, &ctx, &moved(j, -h));
            for i in 0..n {
                fd[j * n + i] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        let amax = |m: &[f64]| m.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let scale = amax(analytic).max(amax(&fd));
        if scale == 0.0 {
            return 0.0;
        }
        fd.iter()
            .zip(analytic)
            .fold(0.0f64, |w, (f, a)| w.max((f - a).abs() / scale))
    }

    /// Largest error between the stiffness and central finite differences
    /// of the residual in `q`, entry `(i, j)` relative to `√(sᵢ tⱼ)`, `sᵢ`
    /// the largest entry of row `i` and `tⱼ` of column `j` (of either
    /// matrix): the soft terms of a slender beam (bending, `EI/L` ~ 1e-5 of
    /// the axial `EA/L`) are held to the same relative accuracy as the
    /// stiff ones, which an error relative to the largest entry would let
    /// pass. Rows or columns that are zero in both matrices are skipped.
    pub fn scaled_tangent_error(e: &dyn Element, ctx: &EvalContext, state: &State, h: f64) -> f64 {
        let (_, k) = eval(e, ctx, state);
        let n = e.n_local();
        let ctx = ctx.with_need(Need::RESIDUAL);
        let mut fd = vec![0.0; n * n];
        for j in 0..n {
            let [rp, ..] = eval_all(e, &ctx, &moved(state, e, j, h));
            let [rm, ..] = eval_all(e, &ctx, &moved(state, e, j, -h));
            for i in 0..n {
                fd[j * n + i] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        let entry = |i: usize, j: usize| k[j * n + i].abs().max(fd[j * n + i].abs());
        let rows: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| entry(i, j)).fold(0.0, f64::max))
            .collect();
        let cols: Vec<f64> = (0..n)
            .map(|j| (0..n).map(|i| entry(i, j)).fold(0.0, f64::max))
            .collect();
        let mut worst = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                let scale = (rows[i] * cols[j]).sqrt();
                if scale > 0.0 {
                    worst = worst.max((fd[j * n + i] - k[j * n + i]).abs() / scale);
                }
            }
        }
        worst
    }

    /// Largest error between the stiffness and central finite differences
    /// of the residual in `q`, relative to the largest entry.
    pub fn tangent_error(e: &dyn Element, ctx: &EvalContext, state: &State, h: f64) -> f64 {
        let (_, k) = eval(e, ctx, state);
        fd_error(e, ctx, &k, h, |j, h| moved(state, e, j, h))
    }

    /// Errors of `∂r/∂v` and `∂r/∂v̇` (the inertia matrix with weights
    /// (1, 0) and (0, 1)) against central finite differences of the
    /// residual in the velocities (step `h_v`) and accelerations (`h_a`),
    /// relative to the largest entry of each.
    pub fn rate_errors(
        e: &dyn Element,
        ctx: &EvalContext,
        state: &State,
        h_v: f64,
        h_a: f64,
    ) -> (f64, f64) {
        let (nodes, nc, o) = (e.nodes(), e.n_coordinates(), Offsets::default());
        let [_, _, c] = eval_all(e, &ctx.with_need(Need::with_inertia(1.0, 0.0)), state);
        let [_, _, m] = eval_all(e, &ctx.with_need(Need::with_inertia(0.0, 1.0)), state);
        let ev = fd_error(e, ctx, &c, h_v, |j, h| {
            let mut s = state.clone();
            s.change_local_rate(nodes, nc, &o, j, h);
            s
        });
        let ea = fd_error(e, ctx, &m, h_a, |j, h| {
            let mut s = state.clone();
            s.change_local_acceleration(nodes, nc, &o, j, h);
            s
        });
        (ev, ea)
    }
}
