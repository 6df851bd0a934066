//! The joint element: a kinematic pair's constraints enforced by the
//! augmented Lagrangian of paper eqs. 17–18, with the second-derivative
//! term that eq. 18 leaves out (docs/joints.md §1):
//!
//! ```text
//! r_q = Bᵀ(pΦ − kλ)                      r_λ = −kΦ
//! K_qq = p BᵀB + Σᵢ (pΦᵢ − kλᵢ) ∂Bᵢ/∂q    K_qλ = −k Bᵀ,  K_λq = −k B,  K_λλ = 0
//! ```
//!
//! with `B = ∂Φ/∂q` (one row per equation) taken along the update of the
//! unknowns. `k` and `p` are per equation: distance constraints use the
//! translational pair of [`ConstraintScaling`], angle constraints the
//! rotational one.

use super::hyperdual::HyperDual;
use super::kinematics::{with_scratch, Conf, Local, Pair, MAX_OUT};
use super::products::Products;
use super::types::{
    constraint_kinds, constraints, slider_constraints, Coordinate, Equation, JointParameters,
    JointType,
};
use crate::elements::{
    Attachment, CellShape, ConstraintKind, ConstraintScaling, Element, ElementKind, ElementOutput,
    EvalContext, Need, Offsets,
};
use crate::model::Id;
use crate::so3::{self, Vec3};
use crate::state::State;

/// `(k, p)` of an equation kind.
pub(crate) fn scale_of(s: &ConstraintScaling, e: Equation) -> (f64, f64) {
    s.of(constraint_kind(e))
}

/// What an equation of the joint library measures.
pub(crate) fn constraint_kind(e: Equation) -> ConstraintKind {
    match e {
        Equation::Force => ConstraintKind::Distance,
        Equation::Moment => ConstraintKind::Angle,
    }
}

/// Adds the augmented-Lagrangian contributions of constraints `f` (with
/// equation kinds `kinds`) to a local system laid out as
/// `[q (nq = local.n() unknowns), λ (kinds.len())]`; `lambda` holds the
/// multipliers. Returns nothing; `work` is scratch of length ≥ m·nq.
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_constraints<F>(
    ctx: &EvalContext,
    local: &mut Local,
    grad: &mut Vec<f64>,
    active: &[usize],
    affine: bool,
    kinds: &[Equation],
    f: &F,
    lambda: &[f64],
    out: &mut ElementOutput,
) where
    F: Fn(&Conf, &mut [HyperDual]),
{
    let m = kinds.len();
    let nq = local.n();
    let mut phi = [0.0; MAX_OUT];
    grad.clear();
    grad.resize(m * nq, 0.0);
    local.gradient(m, active, f, &mut phi[..m], grad);
    let w = add_first_order(ctx, nq, active, kinds, &phi[..m], grad, lambda, out);
    if let Some(t) = out.stiffness.as_deref_mut() {
        local.add_weighted_hessian(m, active, f, &w[..m], grad, affine, t, nq + m);
    }
}

/// The same for constraints written as dot products (every unknown
/// active), differentiated in closed form.
fn add_product_constraints(
    ctx: &EvalContext,
    local: &Local,
    grad: &mut Vec<f64>,
    products: &Products,
    kinds: &[Equation],
    lambda: &[f64],
    out: &mut ElementOutput,
) {
    let m = kinds.len();
    let nq = local.n();
    let mut phi = [0.0; MAX_OUT];
    grad.clear();
    grad.resize(m * nq, 0.0);
    products.gradient(local, &mut phi[..m], grad);
    let active = &ALL_DOFS[..nq];
    let w = add_first_order(ctx, nq, active, kinds, &phi[..m], grad, lambda, out);
    if let Some(t) = out.stiffness.as_deref_mut() {
        products.add_weighted_hessian(local, &w[..m], t, nq + m);
    }
}

/// Local unknowns `0, 1, …` of a joint between two nodes.
pub(crate) const ALL_DOFS: [usize; 12] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11];

/// The terms of [`add_constraints`] of the first derivatives, given the
/// values `phi` and gradients `grad` (`m × nq`): the residual
/// `Bᵀ(pΦ − kλ)`, `−kΦ` and the tangent `p BᵀB`, `−k B`, `−k Bᵀ`.
/// Returns the weights `wᵢ = pΦᵢ − kλᵢ` of the second-derivative term.
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_first_order(
    ctx: &EvalContext,
    nq: usize,
    active: &[usize],
    kinds: &[Equation],
    phi: &[f64],
    grad: &[f64],
    lambda: &[f64],
    out: &mut ElementOutput,
) -> [f64; MAX_OUT] {
    let m = kinds.len();
    let n = nq + m;
    let mut w = [0.0; MAX_OUT];
    let mut kk = [0.0; MAX_OUT];
    let mut pp = [0.0; MAX_OUT];
    for i in 0..m {
        let (k, p) = scale_of(&ctx.scaling, kinds[i]);
        kk[i] = k;
        pp[i] = p;
        w[i] = p * phi[i] - k * lambda[i];
        out.residual[nq + i] += -k * phi[i];
        for &c in active {
            out.residual[c] += grad[i * nq + c] * w[i];
        }
    }
    let Some(t) = out.stiffness.as_deref_mut() else {
        return w;
    };
    for i in 0..m {
        let g = &grad[i * nq..(i + 1) * nq];
        for &c in active {
            if g[c] == 0.0 {
                continue;
            }
            t[(nq + i) * n + c] += -kk[i] * g[c];
            t[c * n + nq + i] += -kk[i] * g[c];
            let pg = pp[i] * g[c];
            for &r in active {
                t[c * n + r] += pg * g[r];
            }
        }
    }
    w
}

/// A kinematic pair of the joint library.
#[derive(Clone, Debug)]
pub struct Joint {
    id: Id,
    joint_type: JointType,
    /// Node A then node B; the node alone (body B) for a joint to the
    /// ground; for a slider the sliding node then the curve's nodes.
    nodes: Vec<usize>,
    pair: Pair,
    parameters: JointParameters,
    kinds: &'static [Equation],
    /// Local unknowns the constraints depend on.
    active: Vec<usize>,
    /// Where its slider parameter (if any), multipliers and unwrap
    /// references of the angles are in the state.
    offsets: Offsets,
    /// Reference value of the slider parameter.
    s0: f64,
    /// The constraints as dot products, differentiated in closed form
    /// (every type but the helical joint and the slider).
    products: Option<Products>,
}

impl Joint {
    /// A joint of type `joint_type` (not a slider) between nodes `first`
    /// (body A) and `second` (body B), or without `second` between the
    /// ground (body A) and `first` (body B), placed by `pair` (built the
    /// same way by [`Pair::from_reference`]).
    pub fn new(
        id: Id,
        joint_type: JointType,
        first: usize,
        second: Option<usize>,
        pair: Pair,
        parameters: JointParameters,
    ) -> Self {
        assert!(joint_type != JointType::Slider, "use Joint::slider");
        let mut nodes = vec![first];
        nodes.extend(second);
        let active = (0..6 * nodes.len()).collect();
        let kinds = constraint_kinds(joint_type, parameters.lock_rotations);
        let products = Products::of(joint_type, &pair, parameters.lock_rotations);
        debug_assert!(products.as_ref().is_none_or(|p| p.len() == kinds.len()));
        Self {
            id,
            joint_type,
            nodes,
            pair,
            parameters,
            kinds,
            active,
            offsets: Offsets::default(),
            s0: 0.0,
            products,
        }
    }

    /// A slider: node `node` (joint point at offset `a` in its material
    /// frame) on the curve through `curve_nodes`, starting at parameter
    /// `s0`.
    pub fn slider(
        id: Id,
        node: usize,
        a: Vec3,
        curve_nodes: &[usize],
        spline: bool,
        s0: f64,
    ) -> Self {
        let mut nodes = vec![node];
        nodes.extend_from_slice(curve_nodes);
        // the sliding node (all 6), the curve nodes' translations, s
        let mut active: Vec<usize> = (0..6).collect();
        for k in 1..nodes.len() {
            active.extend(6 * k..6 * k + 3);
        }
        active.push(6 * nodes.len());
        Self {
            id,
            joint_type: JointType::Slider,
            nodes,
            pair: Pair {
                a,
                ea: so3::Mat3::identity(),
                b: Vec3::zeros(),
                eb: so3::Mat3::identity(),
                ground: None,
            },
            parameters: JointParameters {
                lead: 0.0,
                lock_rotations: false,
                curve: Some(super::types::SliderCurve { spline }),
            },
            kinds: JointType::Slider.equations(),
            active,
            offsets: Offsets::default(),
            s0,
            products: None,
        }
    }

    /// The joint type.
    pub fn joint_type(&self) -> JointType {
        self.joint_type
    }

    /// The pair (geometry on both bodies).
    pub fn pair(&self) -> &Pair {
        &self.pair
    }

    /// Number of coordinate unknowns (1 for a slider).
    fn n_coords(&self) -> usize {
        usize::from(self.joint_type == JointType::Slider)
    }

    fn angle_references<'s>(&self, state: &'s State) -> &'s [f64] {
        let i = self.offsets.internal;
        &state.internal[i..i + self.n_internal()]
    }

    /// The constraint function of this joint.
    fn phi<'a>(&'a self, refs: &'a [f64]) -> impl Fn(&Conf, &mut [HyperDual]) + 'a {
        move |c: &Conf, out: &mut [HyperDual]| {
            if let Some(curve) = &self.parameters.curve {
                slider_constraints(&self.pair, curve, c, out);
                return;
            }
            let f = self.pair.frames(c);
            let angle = if self.joint_type == JointType::Helical {
                Coordinate::Angle.unwrapped(&f, refs[0])
            } else {
                HyperDual::default()
            };
            constraints(self.joint_type, &f, angle, &self.parameters, out);
        }
    }

    /// The joint's relative coordinates (angles unwrapped) at `state`.
    pub fn coordinates(&self, state: &State, out: &mut [f64]) {
        let coords = self.joint_type.coordinates();
        if self.joint_type == JointType::Slider {
            out[0] = state.coordinates[self.offsets.coordinates];
            return;
        }
        let mut local = Local::default();
        local.gather(state, &self.nodes, 0..0);
        let refs = self.angle_references(state);
        let mut ia = 0;
        for (k, c) in coords.iter().enumerate() {
            let r = if c.is_angle() {
                ia += 1;
                refs[ia - 1]
            } else {
                0.0
            };
            let mut v = [0.0];
            let f =
                |conf: &Conf, o: &mut [HyperDual]| o[0] = c.unwrapped(&self.pair.frames(conf), r);
            local.value(1, &f, &mut v);
            out[k] = v[0];
        }
    }

    /// Load the joint applies to the element's first node (body A, or
    /// the node of a joint to the ground, or a slider's sliding node):
    /// force, and moment about the joint point, global frame.
    pub fn reaction(&self, ctx: &EvalContext, state: &State) -> (Vec3, Vec3) {
        let mut r = vec![0.0; self.n_local()];
        let c = EvalContext {
            dynamics: false,
            ..ctx.with_need(Need::RESIDUAL)
        };
        self.evaluate(&c, state, &mut ElementOutput::residual(&mut r));
        let node = self.nodes[0];
        let f = -Vec3::new(r[0], r[1], r[2]);
        let rm = so3::matrix(&state.q[node]);
        let m_node = rm * -Vec3::new(r[3], r[4], r[5]);
        let offset = if self.pair.ground.is_some() {
            self.pair.b
        } else {
            self.pair.a
        };
        let arm = rm * offset;
        (f, m_node - arm.cross(&f))
    }

    /// The joint axes of body A at `state` (global components, columns);
    /// the global axes for a slider.
    pub fn axes(&self, state: &State) -> so3::Mat3 {
        match (&self.pair.ground, self.joint_type) {
            (_, JointType::Slider) => so3::Mat3::identity(),
            (Some((_, e)), _) => *e,
            (None, _) => so3::matrix(&state.q[self.nodes[0]]) * self.pair.ea,
        }
    }
}

/// Names of the loads among a joint's results, after its coordinates: the
/// load the joint applies to its first node, in the joint axes of body A
/// (see [`Joint::reaction`] and [`Joint::axes`]), then the same load in
/// the global axes.
pub const JOINT_LOADS: [&str; 12] = [
    "F1", "F2", "F3", "M1", "M2", "M3", "Fx", "Fy", "Fz", "Mx", "My", "Mz",
];

/// The names of `coordinates` ([`Coordinate::name`]) followed by `tail`,
/// as an array of `N` names (evaluated at compile time).
const fn named<const N: usize>(
    coordinates: &[Coordinate],
    tail: &[&'static str],
) -> [&'static str; N] {
    assert!(coordinates.len() + tail.len() == N);
    let mut out = [""; N];
    let mut k = 0;
    while k < coordinates.len() {
        out[k] = coordinates[k].name();
        k += 1;
    }
    while k < N {
        out[k] = tail[k - coordinates.len()];
        k += 1;
    }
    out
}

/// Every column of a joint's results, in the order of `joints.csv`: the
/// coordinates of [`Coordinate::ALL`], then [`JOINT_LOADS`]. A file (and
/// a table of joints) has those of its joints.
pub const JOINT_COLUMNS: [&str; 19] = named(&Coordinate::ALL, &JOINT_LOADS);

/// Names of the results of a joint of type `t`: its coordinates by name
/// (`angle`, `slide`...; [`JointType::coordinates`]), then
/// [`JOINT_LOADS`].
pub fn result_names(t: JointType) -> &'static [&'static str] {
    use JointType::*;
    const REVOLUTE: [&str; 13] = named(Revolute.coordinates(), &JOINT_LOADS);
    const PRISMATIC: [&str; 13] = named(Prismatic.coordinates(), &JOINT_LOADS);
    const CYLINDRICAL: [&str; 14] = named(Cylindrical.coordinates(), &JOINT_LOADS);
    const HELICAL: [&str; 14] = named(Helical.coordinates(), &JOINT_LOADS);
    const PLANAR: [&str; 15] = named(Planar.coordinates(), &JOINT_LOADS);
    const UNIVERSAL: [&str; 14] = named(Universal.coordinates(), &JOINT_LOADS);
    const SLIDER: [&str; 13] = named(Slider.coordinates(), &JOINT_LOADS);
    match t {
        Revolute => &REVOLUTE,
        Prismatic => &PRISMATIC,
        Cylindrical => &CYLINDRICAL,
        Helical => &HELICAL,
        Planar => &PLANAR,
        Universal => &UNIVERSAL,
        Slider => &SLIDER,
        Spherical | Rigid | Glue => &JOINT_LOADS,
    }
}

impl Element for Joint {
    fn kind(&self) -> ElementKind {
        ElementKind::Joint
    }
    fn id(&self) -> Id {
        self.id
    }
    fn nodes(&self) -> &[usize] {
        &self.nodes
    }
    fn n_coordinates(&self) -> usize {
        self.n_coords()
    }
    fn n_multipliers(&self) -> usize {
        self.kinds.len()
    }
    fn n_internal(&self) -> usize {
        self.joint_type
            .coordinates()
            .iter()
            .filter(|c| c.is_angle())
            .count()
    }
    fn set_offsets(&mut self, offsets: Offsets) {
        self.offsets = offsets;
    }
    fn multiplier_kind(&self, k: usize) -> ConstraintKind {
        constraint_kind(self.kinds[k])
    }
    fn initial_coordinates(&self, out: &mut [f64]) {
        if self.joint_type == JointType::Slider {
            out[0] = self.s0;
        }
    }
    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let (c, m) = (self.offsets.coordinates, self.offsets.multipliers);
        let lambda = &state.multipliers[m..m + self.kinds.len()];
        let refs = self.angle_references(state);
        with_scratch(|sc| {
            sc.local.gather(state, &self.nodes, c..c + self.n_coords());
            if let Some(products) = &self.products {
                add_product_constraints(
                    ctx,
                    &sc.local,
                    &mut sc.grad,
                    products,
                    self.kinds,
                    lambda,
                    out,
                );
                return;
            }
            add_constraints(
                ctx,
                &mut sc.local,
                &mut sc.grad,
                &self.active,
                // every formula but the slider's curve is affine in the
                // nodes' translations
                self.joint_type != JointType::Slider,
                self.kinds,
                &self.phi(refs),
                lambda,
                out,
            );
        });
    }
    fn update_internal(&self, _ctx: &EvalContext, state: &State, internal: &mut [f64]) {
        let mut c = [0.0; 3];
        self.coordinates(state, &mut c);
        let mut ia = 0;
        for (k, coord) in self.joint_type.coordinates().iter().enumerate() {
            if coord.is_angle() {
                internal[ia] = c[k];
                ia += 1;
            }
        }
    }
    fn result_names(&self) -> &'static [&'static str] {
        result_names(self.joint_type)
    }
    /// Fills the first `out.len()` values of [`result_names`].
    fn results(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let nc = self.joint_type.coordinates().len();
        let mut all = [f64::NAN; JOINT_COLUMNS.len()];
        self.coordinates(state, &mut all[..nc]);
        let (f, m) = self.reaction(ctx, state);
        let e = self.axes(state);
        let (fl, ml) = (e.transpose() * f, e.transpose() * m);
        for (k, v) in [fl, ml, f, m].iter().enumerate() {
            all[nc + 3 * k..nc + 3 * k + 3].copy_from_slice(v.as_slice());
        }
        let n = out.len().min(nc + JOINT_LOADS.len());
        out[..n].copy_from_slice(&all[..n]);
    }
    fn as_joint(&self) -> Option<&Joint> {
        Some(self)
    }
    /// The joint point and axes of body A (unless it is the ground) and
    /// of body B; a slider's joint point on its sliding node.
    fn attachments(&self, state: &State, out: &mut Vec<Attachment>) {
        let on = |node: usize, offset: &Vec3, axes: &so3::Mat3| {
            let r = so3::matrix(&state.q[node]);
            Attachment {
                node: Some(node),
                point: state.x[node] + r * offset,
                axes: r * axes,
            }
        };
        if self.joint_type == JointType::Slider {
            out.push(on(self.nodes[0], &self.pair.a, &self.pair.ea));
            return;
        }
        if self.pair.ground.is_none() {
            out.push(on(self.nodes[0], &self.pair.a, &self.pair.ea));
        }
        out.push(on(
            self.nodes[self.pair.node_b()],
            &self.pair.b,
            &self.pair.eb,
        ));
    }
    fn cell_shape(&self) -> CellShape {
        if self.nodes.len() >= 2 {
            CellShape::Line
        } else {
            CellShape::Vertex
        }
    }
}
