//! A flexible body reduced by Craig–Bampton, moving on a floating frame
//! (reference paper §5, eq. 20–29; Cardona & Géradin 1991; docs/theory.md
//! §18).
//!
//! ## Unknowns
//! Its nodes are the boundary nodes of the body, ordinary nodes of the
//! model (joints, latches, hinge laws and beams attach to them); its
//! coordinates are the amplitudes `η` of the fixed-interface modes
//! ([`crate::reduction::ReducedBody`]).
//!
//! ## The floating frame: the frame of one boundary node
//! The frame has the origin `x₀` and the rotation `A = R₀ R₀,refᵀ` of one
//! boundary node, the *frame node* (paper eq. 20): at the reference
//! `A = I`, and the frame axes are the model's global axes. The body's
//! large motion is the frame's; its elastic displacements are small in
//! the frame. For each other boundary node `b`:
//!
//! ```text
//! u_b = Aᵀ(x_b − x₀) − (X_b − X₀),     E_b = Aᵀ R_b R_b,refᵀ,     ε_b = axial(E_b),
//! ```
//!
//! `ε_b = sin ψ n` for `E_b = exp(ψ n~)`: the elastic rotation to first
//! order (a linear model holds only there), with the simple variation
//! `δε = P(E)δβ − P(Eᵀ)δα`, `P(E) = ½(tr E I − Eᵀ)`, `δα = R₀,ref δΘ₀`,
//! `δβ = R_b,ref δΘ_b`. The elastic coordinates are
//! `y = (u_b, ε_b for each b ≠ frame node, η)`.
//!
//! Why this frame: the frame node's six dofs are exactly the six
//! rigid-body dofs the frame takes from the body, so the elastic basis is
//! the Craig–Bampton basis with that node clamped (its reduced stiffness
//! must be positive definite, a clear check); `u`, `E` and `η` do not
//! change under a rigid motion of the whole element, so an undeformed
//! superelement in any rigid motion has no elastic force, exactly; every
//! kinematic quantity is a polynomial in the node positions and rotation
//! matrices, whose derivatives are exact and cheap; and a body with one
//! boundary node (an appendage on one attachment) needs no other frame.
//! The price: the elastic displacements are measured from that node's
//! frame, so a body should be attached through it where it is stiff (the
//! frame node of a panel at a hinge bracket, not at a soft corner). A
//! least-squares (Tisserand-like) frame of the boundary nodes measures
//! smaller elastic displacements but its rotation is an implicit function
//! of every boundary node, and it has no meaning with one boundary node.
//!
//! ## Forces
//! With the body-level vector of velocities `ξ = (v̄, ω, ẏ)` (`v̄ = Aᵀẋ₀`,
//! `ω = R₀,ref Ω₀`) and the variations `δz = (Aᵀδx₀, δα, δy) = Υ δq`
//! (paper eq. 25), the element's residual is `r = Υᵀ s` with the
//! body-level force
//!
//! ```text
//! s = s_inertia(y, ξ, ξ̇) + [0, 0, K̄y + C̄ẏ] − F_weight(A, y)
//! ```
//!
//! (eq. 26 for the elastic part): the inertia forces of the floating
//! frame's kinetic energy `T = ½ ξᵀ𝕄(y)ξ` with the invariants of
//! [`crate::reduction::craig_bampton::Invariants`] (Euler–Poincaré
//! equations for the frame in its own axes, Lagrange's for `y`), modal
//! damping `C̄`, and the weight `−∂V/∂z` of `V = −g·(m x₀ + A(m c₀ + L y))`.
//! Its tangent is exact:
//!
//! ```text
//! ∂r/∂q = ∂(Υᵀs)/∂q|_s + Υᵀ(S_y Υ_y + S_ξ Ξ_q + S_ξ̇ Ξ̇_q + S_α Υ_α),
//! ∂r/∂v = Υᵀ(S_ξ Υ + S_ξ̇ ∂κ/∂v),   ∂r/∂v̇ = Υᵀ 𝕄(y) Υ,
//! ```
//!
//! with `S_•` the derivatives of `s` (analytic, polynomial in `y`, `ξ`,
//! `ξ̇`), `ξ = Υ v`, `ξ̇ = Υ v̇ + κ(q, v)`. The derivatives of the
//! kinematic map (`Υ`, `Ξ_q = ∂ξ/∂q`, `Ξ̇_q`, `∂κ/∂v` and the geometric
//! term `∂(Υᵀs)/∂q`, the terms of the frame's rotation) are taken by dual
//! numbers on one formula per boundary node, as the joints'
//! (docs/joints.md §2): exact, and they cannot disagree with it.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector};

use super::{CellShape, Element, ElementKind, ElementOutput, EvalContext, Offsets};
use crate::joints::hyperdual::{HyperDual, Real, M3, V3};
use crate::model::Id;
use crate::reduction::ReducedBody;
use crate::so3::{self, Mat3, Rotation, Vec3};
use crate::state::State;

/// The largest elastic rotation of a boundary node relative to the frame
/// (rad) before the analysis is stopped: a linear superelement stands for
/// small deformations, and its rotation measure `sin ψ n` turns back at
/// a quarter turn.
pub const LARGEST_ELASTIC_ROTATION: f64 = 1.0;

/// A superelement: a reduced flexible body on a floating frame (see the
/// module documentation).
#[derive(Debug)]
pub struct Superelement {
    id: Id,
    /// The boundary nodes (model node indices), in the body's boundary
    /// order.
    nodes: Vec<usize>,
    /// Which of them is the frame node.
    frame: usize,
    /// The boundary nodes with elastic coordinates (all but the frame
    /// node), in the order of `y`.
    elastic: Vec<usize>,
    /// `X_b − X₀` of each boundary node (reference, global axes).
    arms: Vec<Vec3>,
    /// Reference orientations `R_b,ref` of the boundary nodes.
    reference: Vec<Mat3>,
    /// The reduced body.
    body: Arc<ReducedBody>,
    offsets: Offsets,
}

/// The original mesh of a superelement at a state
/// ([`Superelement::recovered_mesh`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RecoveredMesh {
    /// Position of each mesh node, global frame.
    pub position: Vec<Vec3>,
    /// Orientation of each mesh node.
    pub orientation: Vec<Rotation>,
    /// Position of each mesh node in the floating frame (the reference
    /// axes), `X + u`.
    pub local_position: Vec<Vec3>,
    /// Orientation of each mesh node in the floating frame,
    /// `exp(θ~) R_ref`.
    pub local_orientation: Vec<Rotation>,
    /// Velocity of each mesh node, global frame:
    /// `ẋ₀ + A(ω × (X − X₀ + u) + u̇)`.
    pub velocity: Vec<Vec3>,
    /// Angular velocity of each mesh node, global frame: `A(ω + θ̇)`.
    pub angular_velocity: Vec<Vec3>,
}

/// Generic 3 × 3 algebra on [`M3`] (stored by columns).
mod algebra {
    use super::*;

    #[inline]
    pub fn at<T: Real>(m: &M3<T>, i: usize, j: usize) -> T {
        m.0[j].0[i]
    }
    pub fn apply<T: Real>(a: &M3<T>, v: &V3<T>) -> V3<T> {
        let c = &a.0;
        V3(std::array::from_fn(|i| {
            c[0].0[i] * v.0[0] + c[1].0[i] * v.0[1] + c[2].0[i] * v.0[2]
        }))
    }
    pub fn apply_t<T: Real>(a: &M3<T>, v: &V3<T>) -> V3<T> {
        V3(std::array::from_fn(|j| a.0[j].dot(v)))
    }
    pub fn cst_apply<T: Real>(c: &Mat3, v: &V3<T>) -> V3<T> {
        V3(std::array::from_fn(|i| {
            v.0[0] * c[(i, 0)] + v.0[1] * c[(i, 1)] + v.0[2] * c[(i, 2)]
        }))
    }
    pub fn cst_apply_t<T: Real>(c: &Mat3, v: &V3<T>) -> V3<T> {
        V3(std::array::from_fn(|i| {
            v.0[0] * c[(0, i)] + v.0[1] * c[(1, i)] + v.0[2] * c[(2, i)]
        }))
    }
    /// `a cᵀ` with a constant `c`.
    pub fn mul_cst_t<T: Real>(a: &M3<T>, c: &Mat3) -> M3<T> {
        a.mul_cst(&c.transpose())
    }
    pub fn trace<T: Real>(a: &M3<T>) -> T {
        at(a, 0, 0) + at(a, 1, 1) + at(a, 2, 2)
    }
    pub fn axial<T: Real>(a: &M3<T>) -> V3<T> {
        V3([
            (at(a, 2, 1) - at(a, 1, 2)) * 0.5,
            (at(a, 0, 2) - at(a, 2, 0)) * 0.5,
            (at(a, 1, 0) - at(a, 0, 1)) * 0.5,
        ])
    }
    /// `P(E) v = ½(tr E v − Eᵀ v)`.
    pub fn p<T: Real>(e: &M3<T>, v: &V3<T>) -> V3<T> {
        v.scale(trace(e)).sub(&apply_t(e, v)).scale(T::cst(0.5))
    }
    /// `P(Eᵀ) v = ½(tr E v − E v)`.
    pub fn p_t<T: Real>(e: &M3<T>, v: &V3<T>) -> V3<T> {
        v.scale(trace(e)).sub(&apply(e, v)).scale(T::cst(0.5))
    }
    /// `w~ m`.
    pub fn skew_mul<T: Real>(w: &V3<T>, m: &M3<T>) -> M3<T> {
        M3(std::array::from_fn(|j| w.cross(&m.0[j])))
    }
    /// `m w~`.
    pub fn mul_skew<T: Real>(m: &M3<T>, w: &V3<T>) -> M3<T> {
        // column j of m w~ is m (w × e_j)
        M3(std::array::from_fn(|j| {
            let e = V3(std::array::from_fn(|i| {
                T::cst(if i == j { 1.0 } else { 0.0 })
            }));
            apply(m, &w.cross(&e))
        }))
    }
    pub fn sub<T: Real>(a: &M3<T>, b: &M3<T>) -> M3<T> {
        M3(std::array::from_fn(|j| a.0[j].sub(&b.0[j])))
    }
}

use algebra::*;

/// The configuration and motion of one node in [`Real`]s.
#[derive(Clone, Copy, Debug)]
struct NodeMotion<T> {
    x: V3<T>,
    r: M3<T>,
    v: V3<T>,
    w: V3<T>,
    a: V3<T>,
    wd: V3<T>,
}

/// Which unknown of a node is seeded with ε₁.
#[derive(Clone, Copy, PartialEq)]
enum Seed {
    None,
    /// Component of `(δx, δΘ)`.
    Q(usize),
    /// Component of `(ẋ, Ω)`.
    V(usize),
}

impl NodeMotion<HyperDual> {
    /// Node `node` of `state`, seeded: `x + ε e_c`, `R (I + ε ẽ_c)`, or a
    /// velocity component `+ ε`.
    fn of(state: &State, node: usize, seed: Seed) -> Self {
        let x = state.x[node];
        let r = so3::matrix(&state.q[node]);
        let vel = state.velocity[node];
        let acc = state.acceleration[node];
        let c = |v: f64| HyperDual::new(v, 0.0, 0.0);
        let mut m = Self {
            x: V3([c(x.x), c(x.y), c(x.z)]),
            r: M3::cst(&r),
            v: V3([c(vel[0]), c(vel[1]), c(vel[2])]),
            w: V3([c(vel[3]), c(vel[4]), c(vel[5])]),
            a: V3([c(acc[0]), c(acc[1]), c(acc[2])]),
            wd: V3([c(acc[3]), c(acc[4]), c(acc[5])]),
        };
        match seed {
            Seed::None => {}
            Seed::Q(k) if k < 3 => m.x.0[k].e1 = 1.0,
            Seed::Q(k) => {
                let d = r * so3::skew(&Vec3::ith(k - 3, 1.0));
                for j in 0..3 {
                    for i in 0..3 {
                        m.r.0[j].0[i].e1 = d[(i, j)];
                    }
                }
            }
            Seed::V(k) if k < 3 => m.v.0[k].e1 = 1.0,
            Seed::V(k) => m.w.0[k - 3].e1 = 1.0,
        }
        m
    }
}

/// The frame's quantities: rotation `A`, `v̄ = Aᵀẋ₀`, `ω`, `v̄̇`, `ω̇`.
struct FrameTerms<T> {
    a: M3<T>,
    vbar: V3<T>,
    omega: V3<T>,
    vbar_dot: V3<T>,
    omega_dot: V3<T>,
}

fn frame_terms<T: Real>(m0: &NodeMotion<T>, r0ref: &Mat3) -> FrameTerms<T> {
    let a = mul_cst_t(&m0.r, r0ref);
    let vbar = apply_t(&a, &m0.v);
    let omega = cst_apply(r0ref, &m0.w);
    let omega_dot = cst_apply(r0ref, &m0.wd);
    // d/dt(Aᵀẋ₀) = Aᵀẍ₀ − ω × v̄
    let vbar_dot = apply_t(&a, &m0.a).sub(&omega.cross(&vbar));
    FrameTerms {
        a,
        vbar,
        omega,
        vbar_dot,
        omega_dot,
    }
}

/// `(u, ε, u̇, ε̇, ü, ε̈)` of boundary node `b` relative to the frame.
fn pair_terms<T: Real>(
    f: &FrameTerms<T>,
    m0: &NodeMotion<T>,
    mb: &NodeMotion<T>,
    rbref: &Mat3,
    arm: &Vec3,
) -> [V3<T>; 6] {
    let a = &f.a;
    let (w, wd) = (&f.omega, &f.omega_dot);
    let d = apply_t(a, &mb.x.sub(&m0.x));
    let u = d.sub(&V3::cst(arm));
    let e = mul_cst_t(&apply_mat_t(a, &mb.r), rbref);
    let eps = axial(&e);
    // rates
    let ab = apply_t(a, &mb.v.sub(&m0.v));
    let ud = ab.add(&d.cross(w));
    let bd = cst_apply(rbref, &mb.w);
    let epsd = p(&e, &bd).sub(&p_t(&e, w));
    // accelerations
    let udd = apply_t(a, &mb.a.sub(&m0.a))
        .add(&d.cross(wd))
        .sub(&w.cross(&ab.add(&ud)));
    let bdd = cst_apply(rbref, &mb.wd);
    // Ė = −ω~E + E β̇~
    let e_dot = sub(&mul_skew(&e, &bd), &skew_mul(w, &e));
    let epsdd = p(&e, &bdd)
        .sub(&p_t(&e, wd))
        .add(&p(&e_dot, &bd))
        .sub(&p_t(&e_dot, w));
    [u, eps, ud, epsd, udd, epsdd]
}

/// `Aᵀ R` for matrices of [`Real`]s.
fn apply_mat_t<T: Real>(a: &M3<T>, r: &M3<T>) -> M3<T> {
    M3(std::array::from_fn(|j| apply_t(a, &r.0[j])))
}

/// `Υᵀ s` of the frame rows: `(A s_v̄, R₀,refᵀ s_ω)` on the frame node.
fn frame_forces<T: Real>(f: &FrameTerms<T>, r0ref: &Mat3, s_v: &Vec3, s_w: &Vec3) -> [V3<T>; 2] {
    [
        apply(&f.a, &V3::cst(s_v)),
        cst_apply_t(r0ref, &V3::cst(s_w)),
    ]
}

/// `Υᵀ s` of the rows of boundary node `b`: on the frame node
/// `(−A s_u, R₀,refᵀ(s_u × d − P(E) s_ε))`, on node `b`
/// `(A s_u, R_b,refᵀ P(Eᵀ) s_ε)`.
fn pair_forces<T: Real>(
    f: &FrameTerms<T>,
    m0: &NodeMotion<T>,
    mb: &NodeMotion<T>,
    r0ref: &Mat3,
    rbref: &Mat3,
    s_u: &Vec3,
    s_e: &Vec3,
) -> [V3<T>; 4] {
    let a = &f.a;
    let d = apply_t(a, &mb.x.sub(&m0.x));
    let e = mul_cst_t(&apply_mat_t(a, &mb.r), rbref);
    let (su, se) = (V3::cst(s_u), V3::cst(s_e));
    let a_su = apply(a, &su);
    let zero = V3([T::cst(0.0); 3]);
    [
        zero.sub(&a_su),
        cst_apply_t(r0ref, &su.cross(&d).sub(&p(&e, &se))),
        a_su,
        cst_apply_t(rbref, &p_t(&e, &se)),
    ]
}

/// Everything the element takes from its kinematics at one state.
struct Kinematics {
    /// Frame rotation `A`.
    a: Mat3,
    /// `y`, `ξ`, `ξ̇`.
    y: DVector<f64>,
    xi: DVector<f64>,
    xi_dot: DVector<f64>,
    /// `Υ` (`n_z × n`), `Ξ_q = ∂ξ/∂q`, `Ξ̇_q = ∂ξ̇/∂q`, `∂κ/∂v`, when
    /// derivatives were asked.
    upsilon: DMatrix<f64>,
    xi_q: DMatrix<f64>,
    xi_dot_q: DMatrix<f64>,
    kappa_v: DMatrix<f64>,
}

/// The body-level force `s` and its derivatives.
struct BodyForces {
    s: DVector<f64>,
    s_y: DMatrix<f64>,
    s_xi: DMatrix<f64>,
    s_xi_dot: DMatrix<f64>,
    s_alpha: DMatrix<f64>,
}

impl BodyForces {
    fn zeros(nz: usize) -> Self {
        Self {
            s: DVector::zeros(nz),
            s_y: DMatrix::zeros(nz, nz - 6),
            s_xi: DMatrix::zeros(nz, nz),
            s_xi_dot: DMatrix::zeros(nz, nz),
            s_alpha: DMatrix::zeros(nz, 3),
        }
    }
}

fn v3(v: &DVector<f64>, at: usize) -> Vec3 {
    Vec3::new(v[at], v[at + 1], v[at + 2])
}

/// Adds the 3 × 3 block `m` into `a` at `(r, c)`.
fn add_block(a: &mut DMatrix<f64>, r: usize, c: usize, m: &Mat3) {
    for j in 0..3 {
        for i in 0..3 {
            a[(r + i, c + j)] += m[(i, j)];
        }
    }
}

impl Superelement {
    /// A superelement of `body` on the model nodes `nodes` (in the order
    /// of the body's boundary), with their reference positions `x` and
    /// orientations `r` in the model.
    pub fn new(
        id: Id,
        nodes: Vec<usize>,
        x: &[Vec3],
        r: &[Rotation],
        body: Arc<ReducedBody>,
    ) -> Self {
        let frame = body.frame;
        let elastic = (0..nodes.len()).filter(|&k| k != frame).collect();
        let arms = x.iter().map(|xb| xb - x[frame]).collect();
        Self {
            id,
            nodes,
            frame,
            elastic,
            arms,
            reference: r.iter().map(so3::matrix).collect(),
            body,
            offsets: Offsets::default(),
        }
    }

    /// The reduced body.
    pub fn body(&self) -> &Arc<ReducedBody> {
        &self.body
    }

    /// Which boundary node carries the frame (index into
    /// [`Element::nodes`]).
    pub fn frame_node(&self) -> usize {
        self.frame
    }

    fn n_modes(&self) -> usize {
        self.body.n_modes()
    }

    fn n_y(&self) -> usize {
        6 * self.elastic.len() + self.n_modes()
    }

    /// The modal amplitudes `η` and their rates.
    fn modal<'s>(&self, state: &'s State) -> [&'s [f64]; 3] {
        let (o, m) = (self.offsets.coordinates, self.n_modes());
        [
            &state.coordinates[o..o + m],
            &state.coordinate_rates[o..o + m],
            &state.coordinate_accelerations[o..o + m],
        ]
    }

    /// The frame `(x₀, A)` at `state`.
    pub fn frame(&self, state: &State) -> (Vec3, Mat3) {
        let n0 = self.nodes[self.frame];
        (
            state.x[n0],
            so3::matrix(&state.q[n0]) * self.reference[self.frame].transpose(),
        )
    }

    /// The elastic coordinates `y` at `state` (no derivatives).
    pub fn elastic_coordinates(&self, state: &State) -> DVector<f64> {
        self.kinematics(state, false).y
    }

    /// The kinematics at `state`, with the derivatives of the map when
    /// `derivatives`.
    fn kinematics(&self, state: &State, derivatives: bool) -> Kinematics {
        let (ny, nm, nb) = (self.n_y(), self.n_modes(), self.nodes.len());
        let (nz, n) = (6 + ny, 6 * nb + nm);
        let nf = self.frame;
        let n0 = self.nodes[nf];
        let r0ref = &self.reference[nf];
        let mut k = Kinematics {
            a: Mat3::identity(),
            y: DVector::zeros(ny),
            xi: DVector::zeros(nz),
            xi_dot: DVector::zeros(nz),
            upsilon: DMatrix::zeros(if derivatives { nz } else { 0 }, n),
            xi_q: DMatrix::zeros(if derivatives { nz } else { 0 }, n),
            xi_dot_q: DMatrix::zeros(if derivatives { nz } else { 0 }, n),
            kappa_v: DMatrix::zeros(if derivatives { nz } else { 0 }, n),
        };
        let put = |v: &mut DVector<f64>, at: usize, w: &V3<HyperDual>| {
            for c in 0..3 {
                v[at + c] = w.0[c].re;
            }
        };
        let put_d = |m: &mut DMatrix<f64>, row: usize, col: usize, w: &V3<HyperDual>| {
            for c in 0..3 {
                m[(row + c, col)] = w.0[c].e1;
            }
        };

        // the frame
        let m0 = NodeMotion::of(state, n0, Seed::None);
        let f = frame_terms(&m0, r0ref);
        k.a = Mat3::from_fn(|i, j| at(&f.a, i, j).re);
        put(&mut k.xi, 0, &f.vbar);
        put(&mut k.xi, 3, &f.omega);
        put(&mut k.xi_dot, 0, &f.vbar_dot);
        put(&mut k.xi_dot, 3, &f.omega_dot);
        if derivatives {
            // Υ of the frame rows: v̄ = Aᵀẋ₀, ω = R₀,ref Ω₀
            let at_t = k.a.transpose();
            add_block(&mut k.upsilon, 0, 6 * nf, &at_t);
            add_block(&mut k.upsilon, 3, 6 * nf + 3, r0ref);
            for c in 0..6 {
                let col = 6 * nf + c;
                let fq = frame_terms(&NodeMotion::of(state, n0, Seed::Q(c)), r0ref);
                put_d(&mut k.xi_q, 0, col, &fq.vbar);
                put_d(&mut k.xi_dot_q, 0, col, &fq.vbar_dot);
                let fv = frame_terms(&NodeMotion::of(state, n0, Seed::V(c)), r0ref);
                put_d(&mut k.kappa_v, 0, col, &fv.vbar_dot);
            }
        }

        // each boundary node but the frame node
        for (e, &b) in self.elastic.iter().enumerate() {
            let nb_ = self.nodes[b];
            let (rbref, arm) = (&self.reference[b], &self.arms[b]);
            let mb = NodeMotion::of(state, nb_, Seed::None);
            let terms = pair_terms(&f, &m0, &mb, rbref, arm);
            let row = 6 + 6 * e;
            put(&mut k.y, 6 * e, &terms[0]);
            put(&mut k.y, 6 * e + 3, &terms[1]);
            put(&mut k.xi, row, &terms[2]);
            put(&mut k.xi, row + 3, &terms[3]);
            put(&mut k.xi_dot, row, &terms[4]);
            put(&mut k.xi_dot, row + 3, &terms[5]);
            if !derivatives {
                continue;
            }
            for (node, on_frame) in [(nf, true), (b, false)] {
                for c in 0..6 {
                    let col = 6 * node + c;
                    let seeded = |seed: Seed| {
                        let (s0, sb) = if on_frame {
                            (seed, Seed::None)
                        } else {
                            (Seed::None, seed)
                        };
                        let m0s = NodeMotion::of(state, n0, s0);
                        let mbs = NodeMotion::of(state, nb_, sb);
                        let fs = frame_terms(&m0s, r0ref);
                        pair_terms(&fs, &m0s, &mbs, rbref, arm)
                    };
                    let tq = seeded(Seed::Q(c));
                    put_d(&mut k.upsilon, row, col, &tq[0]);
                    put_d(&mut k.upsilon, row + 3, col, &tq[1]);
                    put_d(&mut k.xi_q, row, col, &tq[2]);
                    put_d(&mut k.xi_q, row + 3, col, &tq[3]);
                    put_d(&mut k.xi_dot_q, row, col, &tq[4]);
                    put_d(&mut k.xi_dot_q, row + 3, col, &tq[5]);
                    let tv = seeded(Seed::V(c));
                    put_d(&mut k.kappa_v, row, col, &tv[4]);
                    put_d(&mut k.kappa_v, row + 3, col, &tv[5]);
                }
            }
        }

        // modal amplitudes
        let [eta, eta_d, eta_dd] = self.modal(state);
        for j in 0..nm {
            k.y[ny - nm + j] = eta[j];
            k.xi[nz - nm + j] = eta_d[j];
            k.xi_dot[nz - nm + j] = eta_dd[j];
            if derivatives {
                k.upsilon[(nz - nm + j, 6 * nb + j)] = 1.0;
            }
        }
        k
    }

    /// Adds `Υᵀ s` (the generalised forces of the body-level force `s`)
    /// to the local vector `out`.
    fn add_forces(&self, state: &State, s: &DVector<f64>, out: &mut [f64]) {
        let nf = self.frame;
        let n0 = self.nodes[nf];
        let r0ref = &self.reference[nf];
        let mut add = |at: usize, v: &V3<HyperDual>| {
            for c in 0..3 {
                out[at + c] += v.0[c].re;
            }
        };
        let m0 = NodeMotion::of(state, n0, Seed::None);
        let f = frame_terms(&m0, r0ref);
        let [fx, ft] = frame_forces(&f, r0ref, &v3(s, 0), &v3(s, 3));
        add(6 * nf, &fx);
        add(6 * nf + 3, &ft);
        for (e, &b) in self.elastic.iter().enumerate() {
            let mb = NodeMotion::of(state, self.nodes[b], Seed::None);
            let (s_u, s_e) = (v3(s, 6 + 6 * e), v3(s, 9 + 6 * e));
            let g = pair_forces(&f, &m0, &mb, r0ref, &self.reference[b], &s_u, &s_e);
            add(6 * nf, &g[0]);
            add(6 * nf + 3, &g[1]);
            add(6 * b, &g[2]);
            add(6 * b + 3, &g[3]);
        }
        let (nm, nb) = (self.n_modes(), self.nodes.len());
        let nz = s.len();
        for j in 0..nm {
            out[6 * nb + j] += s[nz - nm + j];
        }
    }

    /// Adds `∂(Υᵀs)/∂q` at fixed `s` (the geometric terms of the frame's
    /// rotation) to the column-major `n × n` buffer `out`.
    fn add_geometric(&self, state: &State, s: &DVector<f64>, out: &mut [f64]) {
        let n = self.n_local();
        let nf = self.frame;
        let n0 = self.nodes[nf];
        let r0ref = &self.reference[nf];
        let (s_v, s_w) = (v3(s, 0), v3(s, 3));
        let mut add = |row: usize, col: usize, v: &V3<HyperDual>| {
            for c in 0..3 {
                out[col * n + row + c] += v.0[c].e1;
            }
        };
        for c in 0..6 {
            let m0 = NodeMotion::of(state, n0, Seed::Q(c));
            let f = frame_terms(&m0, r0ref);
            let [fx, ft] = frame_forces(&f, r0ref, &s_v, &s_w);
            add(6 * nf, 6 * nf + c, &fx);
            add(6 * nf + 3, 6 * nf + c, &ft);
        }
        for (e, &b) in self.elastic.iter().enumerate() {
            let nb_ = self.nodes[b];
            let rbref = &self.reference[b];
            let (s_u, s_e) = (v3(s, 6 + 6 * e), v3(s, 9 + 6 * e));
            if s_u == Vec3::zeros() && s_e == Vec3::zeros() {
                continue;
            }
            for (node, seeded_frame) in [(nf, true), (b, false)] {
                for c in 0..6 {
                    let (s0, sb) = if seeded_frame {
                        (Seed::Q(c), Seed::None)
                    } else {
                        (Seed::None, Seed::Q(c))
                    };
                    let m0 = NodeMotion::of(state, n0, s0);
                    let mb = NodeMotion::of(state, nb_, sb);
                    let f = frame_terms(&m0, r0ref);
                    let g = pair_forces(&f, &m0, &mb, r0ref, rbref, &s_u, &s_e);
                    let col = 6 * node + c;
                    add(6 * nf, col, &g[0]);
                    add(6 * nf + 3, col, &g[1]);
                    add(6 * b, col, &g[2]);
                    add(6 * b + 3, col, &g[3]);
                }
            }
        }
    }

    /// The body-level inertia forces of the floating frame (docs/theory.md
    /// §18.5) and their derivatives in `y`, `ξ`, `ξ̇`.
    fn inertia_forces(
        &self,
        y: &DVector<f64>,
        xi: &DVector<f64>,
        xi_dot: &DVector<f64>,
    ) -> (BodyForces, f64) {
        let inv = &self.body.invariants;
        let ny = y.len();
        let nz = ny + 6;
        let mut out = BodyForces::zeros(nz);
        let w = v3(xi, 3);
        let vb = v3(xi, 0);
        let yd = xi.rows(6, ny).into_owned();
        let g: [DVector<f64>; 3] = std::array::from_fn(|k| &inv.d[k] * y);
        let gd: [DVector<f64>; 3] = std::array::from_fn(|k| &inv.d[k] * &yd);
        let dt_xi: [DVector<f64>; 3] = std::array::from_fn(|k| inv.d[k].tr_mul(xi));
        let dt_xid: [DVector<f64>; 3] = std::array::from_fn(|k| inv.d[k].tr_mul(xi_dot));
        // H_kl y, H_klᵀ y, H_kl ẏ, H_klᵀ ẏ
        let hy: [[DVector<f64>; 3]; 3] =
            std::array::from_fn(|k| std::array::from_fn(|l| &inv.h[k][l] * y));
        let hty: [[DVector<f64>; 3]; 3] =
            std::array::from_fn(|k| std::array::from_fn(|l| inv.h[k][l].tr_mul(y)));
        let hyd: [[DVector<f64>; 3]; 3] =
            std::array::from_fn(|k| std::array::from_fn(|l| &inv.h[k][l] * &yd));
        let htyd: [[DVector<f64>; 3]; 3] =
            std::array::from_fn(|k| std::array::from_fn(|l| inv.h[k][l].tr_mul(&yd)));
        let h = Mat3::from_fn(|k, l| y.dot(&hy[k][l]));
        let h_dot = Mat3::from_fn(|k, l| yd.dot(&hy[k][l]) + yd.dot(&hty[k][l]));

        // 𝕄(y) = 𝕄₀ + Σ_k (g_k e_ωkᵀ + e_ωk g_kᵀ) + P h Pᵀ
        let mut mass = inv.m0.clone();
        for k in 0..3 {
            for i in 0..nz {
                mass[(i, 3 + k)] += g[k][i];
                mass[(3 + k, i)] += g[k][i];
            }
            for l in 0..3 {
                mass[(3 + k, 3 + l)] += h[(k, l)];
            }
        }
        // p = 𝕄(y) ξ; ṗ = 𝕄(y) ξ̇ + (d𝕄/dt) ξ
        let p = &mass * xi;
        let mut p_dot = &mass * xi_dot;
        for k in 0..3 {
            p_dot.axpy(w[k], &gd[k], 1.0);
            p_dot[3 + k] += gd[k].dot(xi);
            for l in 0..3 {
                p_dot[3 + k] += h_dot[(k, l)] * w[l];
            }
        }
        // T_y = Σ_k ω_k D_kᵀ ξ + H(ω) y
        let mut t_y = DVector::zeros(ny);
        for k in 0..3 {
            t_y.axpy(w[k], &dt_xi[k], 1.0);
            for l in 0..3 {
                t_y.axpy(w[k] * w[l], &hy[k][l], 1.0);
            }
        }
        let (pv, pw) = (v3(&p, 0), v3(&p, 3));
        out.s = p_dot;
        let rv = w.cross(&pv);
        let rw = w.cross(&pw) + vb.cross(&pv);
        for c in 0..3 {
            out.s[c] += rv[c];
            out.s[3 + c] += rw[c];
        }
        for i in 0..ny {
            out.s[6 + i] -= t_y[i];
        }
        let kinetic = 0.5 * xi.dot(&p);

        // ∂s/∂ξ̇ = 𝕄(y)
        out.s_xi_dot = mass.clone();

        // D(ω) = Σ ω_k D_k, H(ω) = Σ ω_k ω_l H_kl
        let mut d_w = DMatrix::zeros(nz, ny);
        let mut h_w = DMatrix::zeros(ny, ny);
        for k in 0..3 {
            d_w += &inv.d[k] * w[k];
            for l in 0..3 {
                h_w += &inv.h[k][l] * (w[k] * w[l]);
            }
        }

        // ∂s/∂ξ
        let sx = &mut out.s_xi;
        for k in 0..3 {
            // Σ ω_k ġ_k: ġ_k on column ω_k
            for i in 0..nz {
                sx[(i, 3 + k)] += gd[k][i];
                // row ω_k: ġ_kᵀ
                sx[(3 + k, i)] += gd[k][i];
            }
            for j in 0..ny {
                // row ω_k on ẏ: D_kᵀξ + Σ_l ω_l (H_kl + H_klᵀ) y
                let mut v = dt_xi[k][j];
                for l in 0..3 {
                    v += w[l] * (hy[k][l][j] + hty[k][l][j]);
                }
                sx[(3 + k, 6 + j)] += v;
            }
            for l in 0..3 {
                sx[(3 + k, 3 + l)] += h_dot[(k, l)];
            }
        }
        {
            let mut v = sx.view_mut((0, 6), (nz, ny));
            v += &d_w;
        }
        // ad* terms: ω × p_v̄, ω × p_ω + v̄ × p_v̄
        let (wt, vt) = (so3::skew(&w), so3::skew(&vb));
        let (pvt, pwt) = (so3::skew(&pv), so3::skew(&pw));
        let mv = mass.rows(0, 3).into_owned();
        let mw = mass.rows(3, 3).into_owned();
        let mat3 = |m: &Mat3| DMatrix::from_fn(3, 3, |i, j| m[(i, j)]);
        let (wt_d, vt_d) = (mat3(&wt), mat3(&vt));
        {
            let top = &wt_d * &mv;
            let mut v = sx.rows_mut(0, 3);
            v += &top;
            let mid = &wt_d * &mw + &vt_d * &mv;
            let mut v = sx.rows_mut(3, 3);
            v += &mid;
        }
        add_block(sx, 0, 3, &(-pvt));
        add_block(sx, 3, 3, &(-pwt));
        add_block(sx, 3, 0, &(-pvt));
        // −T_y
        {
            let dwt = d_w.transpose();
            let mut v = sx.view_mut((6, 0), (ny, nz));
            v -= &dwt;
            for k in 0..3 {
                for j in 0..ny {
                    let mut v = dt_xi[k][j];
                    for l in 0..3 {
                        v += w[l] * (hy[k][l][j] + hty[k][l][j]);
                    }
                    sx[(6 + j, 3 + k)] -= v;
                }
            }
        }

        // ∂s/∂y
        // J(y, u) = D(u_ω) + P_ω [rows k: (D_kᵀu)ᵀ + Σ_l u_ωl (H_kl y + H_klᵀ y)ᵀ]
        let jac = |u: &DVector<f64>, dt_u: &[DVector<f64>; 3]| -> DMatrix<f64> {
            let mut j = DMatrix::zeros(nz, ny);
            for k in 0..3 {
                j += &inv.d[k] * u[3 + k];
            }
            for k in 0..3 {
                for c in 0..ny {
                    let mut v = dt_u[k][c];
                    for l in 0..3 {
                        v += u[3 + l] * (hy[k][l][c] + hty[k][l][c]);
                    }
                    j[(3 + k, c)] += v;
                }
            }
            j
        };
        let sy = &mut out.s_y;
        *sy += jac(xi_dot, &dt_xid);
        for k in 0..3 {
            for c in 0..ny {
                let mut v = 0.0;
                for l in 0..3 {
                    v += w[l] * (hyd[k][l][c] + htyd[k][l][c]);
                }
                sy[(3 + k, c)] += v;
            }
        }
        let j_xi = jac(xi, &dt_xi);
        let jv = j_xi.rows(0, 3).into_owned();
        let jw = j_xi.rows(3, 3).into_owned();
        {
            let mut v = sy.rows_mut(0, 3);
            v += &wt_d * &jv;
        }
        {
            let mut v = sy.rows_mut(3, 3);
            v += &wt_d * &jw + &vt_d * &jv;
        }
        {
            let mut v = sy.view_mut((6, 0), (ny, ny));
            v -= &h_w;
        }
        (out, kinetic)
    }

    /// Adds the elastic, damping and weight forces to `f` (the body
    /// level), with their derivatives.
    fn add_other_forces(
        &self,
        ctx: &EvalContext,
        k: &Kinematics,
        dynamics: bool,
        f: &mut BodyForces,
    ) {
        let body = &self.body;
        let ny = k.y.len();
        // elastic, eq. 26: K̄y
        let ky = &body.stiffness_y * &k.y;
        for i in 0..ny {
            f.s[6 + i] += ky[i];
        }
        {
            let mut v = f.s_y.view_mut((6, 0), (ny, ny));
            v += &body.stiffness_y;
        }
        // modal damping C̄ẏ
        if dynamics {
            for i in 0..ny {
                let c = body.damping_y[i];
                if c != 0.0 {
                    f.s[6 + i] += c * k.xi[6 + i];
                    f.s_xi[(6 + i, 6 + i)] += c;
                }
            }
        }
        // weight: F = [m ḡ; (m c₀ + L y) × ḡ; Lᵀ ḡ], ḡ = Aᵀ g
        if ctx.gravity != Vec3::zeros() {
            let inv = &body.invariants;
            let g = k.a.transpose() * ctx.gravity;
            let l = inv.m0.view((0, 6), (3, ny));
            let first = inv.first_moment + Vec3::from_iterator((l * &k.y).iter().copied());
            let fv = g * inv.mass;
            let fw = first.cross(&g);
            let fy = l.tr_mul(&DVector::from_column_slice(g.as_slice()));
            for c in 0..3 {
                f.s[c] -= fv[c];
                f.s[3 + c] -= fw[c];
            }
            for i in 0..ny {
                f.s[6 + i] -= fy[i];
            }
            // ∂F/∂y: rows ω, −g~ L
            let gt = so3::skew(&g);
            let gl = DMatrix::from_fn(3, 3, |i, j| gt[(i, j)]) * l;
            {
                let mut v = f.s_y.rows_mut(3, 3);
                v += &gl;
            }
            // ∂F/∂α with δḡ = ḡ~ δα: [m ḡ~; S~ ḡ~; Lᵀ ḡ~]
            let sa = &mut f.s_alpha;
            let mg = gt * inv.mass;
            let sg = so3::skew(&first) * gt;
            for i in 0..3 {
                for j in 0..3 {
                    sa[(i, j)] -= mg[(i, j)];
                    sa[(3 + i, j)] -= sg[(i, j)];
                }
            }
            let lg = l.transpose() * DMatrix::from_fn(3, 3, |i, j| gt[(i, j)]);
            let mut v = f.s_alpha.view_mut((6, 0), (ny, 3));
            v -= &lg;
        }
    }

    /// The recovered elastic displacement `Φ_y y` at every dof of the
    /// mesh (frame axes).
    pub fn recovered(&self, state: &State) -> DVector<f64> {
        let y = self.elastic_coordinates(state);
        let body = &self.body;
        let mut u = DVector::zeros(body.basis.nrows());
        for (j, &c) in body.y_columns.iter().enumerate() {
            if y[j] != 0.0 {
                u.axpy(y[j], &body.basis.column(c), 1.0);
            }
        }
        u
    }

    /// The original mesh at `state` (docs/theory.md §18.7): the elastic
    /// displacements `u = Φ_y y` recovered in the frame, and every mesh
    /// node placed by the frame, `x = x₀ + A(X − X₀ + u)`,
    /// `R = A exp(θ~) R_ref`, with its velocities. Returns the positions
    /// and orientations in the model (global) and in the frame (`X + u`,
    /// `exp(θ~) R_ref`: the state of the original elements, for their
    /// results).
    pub fn recovered_mesh(&self, state: &State) -> RecoveredMesh {
        let k = self.kinematics(state, false);
        let body = &self.body;
        let n = body.basis.nrows();
        let (mut u, mut u_dot) = (DVector::zeros(n), DVector::zeros(n));
        for (j, &c) in body.y_columns.iter().enumerate() {
            let column = body.basis.column(c);
            if k.y[j] != 0.0 {
                u.axpy(k.y[j], &column, 1.0);
            }
            if k.xi[6 + j] != 0.0 {
                u_dot.axpy(k.xi[6 + j], &column, 1.0);
            }
        }
        let mesh = &body.body;
        let (x0, a) = self.frame(state);
        let (v0, w) = (k.a * v3(&k.xi, 0), v3(&k.xi, 3));
        let origin = mesh.positions[body.boundary[self.frame]];
        let rows = mesh.dof_rows();
        let rot_a = so3::from_matrix(&a);
        let mut out = RecoveredMesh::default();
        let at = |v: &DVector<f64>, r: &[Option<usize>; 6], first: usize| {
            Vec3::from_fn(|c, _| r[first + c].map_or(0.0, |row| v[row]))
        };
        for (i, r) in rows.iter().enumerate() {
            let (t, theta) = (at(&u, r, 0), at(&u, r, 3));
            let local_x = mesh.positions[i] + t;
            let local_q = so3::exp(&theta) * mesh.orientations[i];
            out.position.push(x0 + a * (local_x - origin));
            out.orientation.push(rot_a * local_q);
            out.local_position.push(local_x);
            out.local_orientation.push(local_q);
            out.velocity
                .push(v0 + a * (w.cross(&(local_x - origin)) + at(&u_dot, r, 0)));
            out.angular_velocity.push(a * (w + at(&u_dot, r, 3)));
        }
        out
    }

    /// The results of every original element of the body (the beams'
    /// section forces; a shell's skin stresses) at the recovered mesh
    /// `mesh`: each element's own [`Element::results`] on the state of the
    /// mesh in the floating frame (objective elements give there what
    /// they give in the model's frame). Empty for imported matrices,
    /// which have no elements.
    pub fn element_results(&self, mesh: &RecoveredMesh) -> Vec<Vec<f64>> {
        let Some(model) = &self.body.body.elements else {
            return Vec::new();
        };
        let state = self.local_state(mesh);
        let ctx = EvalContext {
            gravity: Vec3::zeros(),
            ..model.context(0.0, super::Need::RESIDUAL)
        };
        model
            .elements
            .iter()
            .map(|e| {
                let mut out = vec![0.0; e.result_names().len()];
                e.results(&ctx, &state, &mut out);
                out
            })
            .collect()
    }

    /// The stresses of the skins, `[bottom, top]`, at the centre of every
    /// shell of the body at the recovered mesh `mesh` (`None` for its
    /// other elements; empty for imported matrices): each shell's own
    /// layer stress recovery ([`super::shell::Shell::layer_stresses`],
    /// [`super::shell::Shell::skin_stresses`]) on the displacements of the
    /// mesh in the floating frame (docs/theory.md §18.7).
    pub fn skin_stresses(
        &self,
        mesh: &RecoveredMesh,
    ) -> Vec<Option<[super::shell::SkinStress; 2]>> {
        let Some(model) = &self.body.body.elements else {
            return Vec::new();
        };
        let state = self.local_state(mesh);
        let mut layers = Vec::new();
        model
            .elements
            .iter()
            .map(|e| {
                e.as_shell().map(|shell| {
                    let d = shell.displacements(&state);
                    shell.layer_stresses_into(&d, super::shell::StressPoint::Centre, &mut layers);
                    shell.skin_stresses(&layers)
                })
            })
            .collect()
    }

    /// The state of the body's own model at the recovered mesh: in the
    /// floating frame, taken back to the coordinates the original
    /// elements were built in (`X_own = Qᵀ (X − p)` for a body placed by
    /// `(p, Q)`), at rest.
    fn local_state(&self, mesh: &RecoveredMesh) -> State {
        let (p, q) = &self.body.body.placement;
        let back = q.inverse();
        State::at_rest(
            0.0,
            mesh.local_position.iter().map(|x| back * (x - p)).collect(),
            mesh.local_orientation.iter().map(|r| back * r).collect(),
        )
    }

    /// A mode shape on the mesh: the translation and rotation (global) of
    /// every mesh node for the small motion of the boundary nodes
    /// `boundary` (translation and rotation of each, global) and of the
    /// modal amplitudes `eta`, linearised about `state`:
    /// `δx = δx₀ + δφ₀ × (x − x₀) + A Φ_t δy`, `δθ = δφ₀ + A Φ_θ δy`,
    /// `δy = Υ_y δq`.
    pub fn mode_shape(
        &self,
        state: &State,
        boundary: &[(Vec3, Vec3)],
        eta: &[f64],
    ) -> Vec<(Vec3, Vec3)> {
        let k = self.kinematics(state, true);
        let (nb, nm) = (self.nodes.len(), self.n_modes());
        let mut dq = DVector::zeros(6 * nb + nm);
        for (b, (t, th)) in boundary.iter().enumerate() {
            let material = so3::matrix(&state.q[self.nodes[b]]).transpose() * th;
            for c in 0..3 {
                dq[6 * b + c] = t[c];
                dq[6 * b + 3 + c] = material[c];
            }
        }
        for (j, e) in eta.iter().enumerate().take(nm) {
            dq[6 * nb + j] = *e;
        }
        let ny = k.y.len();
        let dy = k.upsilon.rows(6, ny) * &dq;
        let body = &self.body;
        let mut du = DVector::zeros(body.basis.nrows());
        for (j, &c) in body.y_columns.iter().enumerate() {
            du.axpy(dy[j], &body.basis.column(c), 1.0);
        }
        let mesh = self.recovered_mesh(state);
        let (x0, a) = self.frame(state);
        let (t0, phi0) = boundary[self.frame];
        let rows = body.body.dof_rows();
        rows.iter()
            .enumerate()
            .map(|(i, r)| {
                let t = Vec3::from_fn(|c, _| r[c].map_or(0.0, |row| du[row]));
                let th = Vec3::from_fn(|c, _| r[3 + c].map_or(0.0, |row| du[row]));
                (
                    t0 + phi0.cross(&(mesh.position[i] - x0)) + a * t,
                    phi0 + a * th,
                )
            })
            .collect()
    }
}

impl Element for Superelement {
    fn kind(&self) -> ElementKind {
        ElementKind::Superelement
    }

    fn id(&self) -> Id {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn n_coordinates(&self) -> usize {
        self.n_modes()
    }

    fn set_offsets(&mut self, offsets: Offsets) {
        self.offsets = offsets;
    }

    /// A mode's largest nodal translation per unit amplitude.
    fn coordinate_length(&self, k: usize) -> f64 {
        match self.body.mode_lengths.get(k) {
            Some(&l) if l > 0.0 && l.is_finite() => l,
            _ => 1.0,
        }
    }

    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let n = self.n_local();
        let want_k = out.stiffness.is_some();
        let weights = ctx.need.inertia.filter(|_| out.inertia.is_some());
        let derivatives = want_k || weights.is_some();
        let k = self.kinematics(state, derivatives);
        let ny = k.y.len();
        let nz = ny + 6;
        let has_inertia = self.body.invariants.mass > 0.0;

        // body-level forces: inertia (dynamics), elastic, damping, weight
        let inertia = (has_inertia && (ctx.dynamics || weights.is_some()))
            .then(|| self.inertia_forces(&k.y, &k.xi, &k.xi_dot).0);
        let mut f = BodyForces::zeros(nz);
        if ctx.dynamics {
            if let Some(i) = &inertia {
                f.s += &i.s;
                f.s_y += &i.s_y;
                f.s_xi += &i.s_xi;
                f.s_xi_dot += &i.s_xi_dot;
            }
        }
        self.add_other_forces(ctx, &k, ctx.dynamics, &mut f);

        // residual r = Υᵀ s
        self.add_forces(state, &f.s, out.residual);
        if !derivatives {
            return;
        }
        let ups = &k.upsilon;
        let ups_y = ups.rows(6, ny).into_owned();
        let ups_a = ups.rows(3, 3).into_owned();

        // stiffness: ∂(Υᵀs)/∂q|_s + Υᵀ(S_y Υ_y + S_ξ Ξ_q + S_ξ̇ Ξ̇_q + S_α Υ_α)
        if let Some(kt) = out.stiffness.as_deref_mut() {
            self.add_geometric(state, &f.s, kt);
            let inner = &f.s_y * &ups_y
                + &f.s_xi * &k.xi_q
                + &f.s_xi_dot * &k.xi_dot_q
                + &f.s_alpha * &ups_a;
            let kq = ups.tr_mul(&inner);
            for j in 0..n {
                for i in 0..n {
                    kt[j * n + i] += kq[(i, j)];
                }
            }
        }

        // inertia matrix w_d ∂r/∂v + w_m ∂r/∂v̇
        if let (Some(w), Some(buf)) = (weights, out.inertia.as_deref_mut()) {
            // the damping and inertia terms, whether or not in dynamics
            let mut s_xi = DMatrix::zeros(nz, nz);
            let mut s_xi_dot = DMatrix::zeros(nz, nz);
            if let Some(i) = &inertia {
                s_xi += &i.s_xi;
                s_xi_dot += &i.s_xi_dot;
            }
            for i in 0..ny {
                s_xi[(6 + i, 6 + i)] += self.body.damping_y[i];
            }
            let c = ups.tr_mul(&(&s_xi * ups + &s_xi_dot * &k.kappa_v));
            let m = ups.tr_mul(&(&s_xi_dot * ups));
            for j in 0..n {
                for i in 0..n {
                    buf[j * n + i] += w.damping * c[(i, j)] + w.mass * m[(i, j)];
                }
            }
        }
    }

    fn result_names(&self) -> &'static [&'static str] {
        &["strain_energy", "elastic_displacement"]
    }

    /// The strain energy and the largest elastic translation of a mesh
    /// node in the frame.
    fn results(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        out[0] = self.strain_energy(ctx, state);
        let u = self.recovered(state);
        let mut largest = 0.0f64;
        let rows = self.body.body.dof_rows();
        for r in &rows {
            let t = Vec3::from_fn(|c, _| r[c].map_or(0.0, |row| u[row]));
            largest = largest.max(t.norm());
        }
        out[1] = largest;
    }

    /// `½ yᵀK̄y` (eq. 23).
    fn strain_energy(&self, _ctx: &EvalContext, state: &State) -> f64 {
        let y = self.elastic_coordinates(state);
        0.5 * y.dot(&(&self.body.stiffness_y * &y))
    }

    /// `½ ξᵀ𝕄(y)ξ`.
    fn kinetic_energy(&self, state: &State) -> f64 {
        if self.body.invariants.mass == 0.0 {
            return 0.0;
        }
        let k = self.kinematics(state, false);
        let p = self.momentum(&k);
        0.5 * k.xi.dot(&p)
    }

    /// `A p_v̄` and `x₀ × A p_v̄ + A p_ω`.
    fn momenta(&self, state: &State) -> super::inertia::Momenta {
        if self.body.invariants.mass == 0.0 {
            return Default::default();
        }
        let k = self.kinematics(state, false);
        let p = self.momentum(&k);
        let (x0, a) = self.frame(state);
        let linear = a * v3(&p, 0);
        super::inertia::Momenta {
            linear,
            angular: x0.cross(&linear) + a * v3(&p, 3),
        }
    }

    /// `−g·(m x₀ + A(m c₀ + L y))`.
    fn weight_potential(&self, ctx: &EvalContext, state: &State) -> f64 {
        let inv = &self.body.invariants;
        let y = self.elastic_coordinates(state);
        let ny = y.len();
        let l = inv.m0.view((0, 6), (3, ny));
        let first = inv.first_moment + Vec3::from_iterator((l * &y).iter().copied());
        let (x0, a) = self.frame(state);
        -ctx.gravity.dot(&(x0 * inv.mass + a * first))
    }

    /// `ẏᵀC̄ẏ`, in dynamics.
    fn dissipated_power(&self, ctx: &EvalContext, state: &State) -> f64 {
        if !ctx.dynamics || self.body.damping_y.iter().all(|&c| c == 0.0) {
            return 0.0;
        }
        let k = self.kinematics(state, false);
        let ny = k.y.len();
        (0..ny)
            .map(|i| self.body.damping_y[i] * k.xi[6 + i].powi(2))
            .sum()
    }

    /// `Υᵀ(0, 0, C̄ẏ)`, in dynamics.
    fn nonconservative_forces(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        if !ctx.dynamics || self.body.damping_y.iter().all(|&c| c == 0.0) {
            return;
        }
        let k = self.kinematics(state, false);
        let ny = k.y.len();
        let mut s = DVector::zeros(ny + 6);
        for i in 0..ny {
            s[6 + i] = self.body.damping_y[i] * k.xi[6 + i];
        }
        self.add_forces(state, &s, out);
    }

    /// A boundary node turned elastically by more than
    /// [`LARGEST_ELASTIC_ROTATION`] relative to the frame.
    fn law_violated(&self, _before: &State, after: &State) -> Option<String> {
        let (_, a) = self.frame(after);
        for &b in &self.elastic {
            let e = a.transpose()
                * so3::matrix(&after.q[self.nodes[b]])
                * self.reference[b].transpose();
            let psi = so3::axial(&e).norm().atan2(0.5 * (e.trace() - 1.0));
            if psi > LARGEST_ELASTIC_ROTATION {
                return Some(format!(
                    "a boundary node turned by {psi:.3} rad relative to its floating frame: a superelement is a linear model of small elastic deformations (docs/theory.md §18); split the body, or model it with beams"
                ));
            }
        }
        None
    }

    fn cell_shape(&self) -> CellShape {
        CellShape::None
    }

    fn mass(&self) -> f64 {
        self.body.invariants.mass
    }

    fn as_superelement(&self) -> Option<&Superelement> {
        Some(self)
    }
}

impl Superelement {
    /// `p = 𝕄(y) ξ` (docs/theory.md §18.5).
    fn momentum(&self, k: &Kinematics) -> DVector<f64> {
        let inv = &self.body.invariants;
        let y = &k.y;
        let xi = &k.xi;
        let w = v3(xi, 3);
        let mut p = &inv.m0 * xi;
        for kk in 0..3 {
            let g = &inv.d[kk] * y;
            p.axpy(w[kk], &g, 1.0);
            p[3 + kk] += g.dot(xi);
            for l in 0..3 {
                p[3 + kk] += y.dot(&(&inv.h[kk][l] * y)) * w[l];
            }
        }
        p
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::elements::testing::{eval, motion, rate_errors, set_motion, tangent_error};
    use crate::elements::Need;
    use crate::model::input::{ModelInput, SectionInput};
    use crate::model::Model;
    use crate::reduction::{reduce, FlexibleBody, InertiaModel, ModeSelection, ReductionSettings};
    use proptest::prelude::*;

    /// An L-shaped frame of beams with mass and rotational inertia (1 m
    /// and 0.63 m legs, 7 elements), free: the body of the tests.
    pub fn l_frame_input() -> ModelInput {
        let mut m = ModelInput::new("L frame");
        m.analysis.kind = "modal".into();
        m.add_node(1, [0.0, 0.0, 0.0]);
        m.add_node(2, [1.0, 0.0, 0.0]);
        m.add_node(3, [1.0, 0.6, 0.2]);
        m.sections.push(SectionInput {
            mass_per_length: Some(2.0),
            inertia_per_length: Some([0.01, 0.005, 0.005]),
            ..SectionInput::diagonal("s", [2e6, 8e5, 8e5, 300.0, 400.0, 500.0])
        });
        m.add_beam_line([1, 2], 4, "s", Some([0.0, 0.0, 1.0]));
        m.add_beam_line([2, 3], 3, "s", Some([0.0, 0.0, 1.0]));
        m
    }

    /// The L frame reduced on the boundary nodes `boundary` (ids) with
    /// `modes` modes, as a superelement on nodes `0..boundary.len()` whose
    /// reference orientations are `r`.
    pub fn l_frame(
        boundary: &[Id],
        modes: usize,
        damping: f64,
        inertia: InertiaModel,
        r: &[Rotation],
    ) -> (Superelement, Vec<Vec3>) {
        let model = Model::from_input(&l_frame_input()).unwrap();
        let body = FlexibleBody::from_model(model);
        let b: Vec<usize> = boundary
            .iter()
            .map(|&id| body.node_index(id).unwrap())
            .collect();
        let settings = ReductionSettings {
            inertia,
            damping_ratios: vec![damping],
            compare_free_free: false,
            ..ReductionSettings::new(b.clone(), ModeSelection::Count(modes))
        };
        let reduced = reduce(body, &settings).unwrap();
        let x: Vec<Vec3> = b.iter().map(|&i| reduced.body.positions[i]).collect();
        let nodes = (0..b.len()).collect();
        (Superelement::new(7, nodes, &x, r, Arc::new(reduced)), x)
    }

    /// Which share of the residual [`Shared`] gives.
    #[derive(Clone, Copy)]
    enum Share {
        /// Dynamics less statics: inertia and damping forces.
        Dynamic,
        /// With gravity less without.
        Weight,
    }

    /// A share of a superelement's residual and stiffness, as an element
    /// for the finite-difference checks.
    struct Shared<'a> {
        e: &'a Superelement,
        share: Share,
    }

    impl Element for Shared<'_> {
        fn kind(&self) -> ElementKind {
            self.e.kind()
        }
        fn id(&self) -> Id {
            self.e.id()
        }
        fn nodes(&self) -> &[usize] {
            self.e.nodes()
        }
        fn n_coordinates(&self) -> usize {
            self.e.n_coordinates()
        }
        fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
            let (plus, minus) = match self.share {
                Share::Dynamic => (
                    EvalContext {
                        dynamics: true,
                        ..*ctx
                    },
                    EvalContext {
                        dynamics: false,
                        ..*ctx
                    },
                ),
                Share::Weight => (
                    *ctx,
                    EvalContext {
                        gravity: Vec3::zeros(),
                        ..*ctx
                    },
                ),
            };
            self.e.evaluate(&plus, state, out);
            let n = self.n_local();
            let mut r = vec![0.0; n];
            let mut k = vec![0.0; if out.stiffness.is_some() { n * n } else { 0 }];
            self.e.evaluate(
                &minus.with_need(Need::stiffness(out.stiffness.is_some())),
                state,
                &mut ElementOutput {
                    residual: &mut r,
                    stiffness: out.stiffness.is_some().then_some(&mut k[..]),
                    inertia: None,
                },
            );
            for (o, v) in out.residual.iter_mut().zip(&r) {
                *o -= v;
            }
            if let Some(kt) = out.stiffness.as_deref_mut() {
                for (o, v) in kt.iter_mut().zip(&k) {
                    *o -= v;
                }
            }
        }
    }

    fn ctx(dynamics: bool) -> EvalContext<'static> {
        EvalContext {
            time: 0.0,
            curves: &[],
            gravity: Vec3::new(0.3, -2.0, -9.81),
            need: Need::STIFFNESS,
            dynamics,
            scaling: Default::default(),
        }
    }

    fn small_vec(max: f64) -> impl Strategy<Value = Vec3> {
        (-max..max, -max..max, -max..max).prop_map(|(a, b, c)| Vec3::new(a, b, c))
    }

    /// A state of the superelement: the reference turned by `turn` and
    /// moved by `shift`, each boundary node displaced elastically by
    /// `du[k]` and turned by `dr[k]`, modal amplitudes `eta`.
    fn deformed(
        x: &[Vec3],
        r: &[Rotation],
        turn: &Vec3,
        shift: &Vec3,
        du: &[Vec3],
        dr: &[Vec3],
        eta: Vec<f64>,
    ) -> State {
        let q = so3::exp(turn);
        let xs = x.iter().zip(du).map(|(x, d)| shift + q * (x + d)).collect();
        let rs = r.iter().zip(dr).map(|(r, d)| q * so3::exp(d) * r).collect();
        State::at_rest(0.0, xs, rs).with_unknowns(eta, 0, 0)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Acceptance: the stiffness is the derivative of the full residual
        /// (elastic, weight, inertia with its centrifugal and Coriolis
        /// terms, modal damping) in q, and the inertia matrix with weights
        /// (1, 0) and (0, 1) its derivatives in v and v̇, against central
        /// differences, on random states: large rigid rotations (up to 3
        /// rad), elastic displacements of 1 cm and rotations of 0.05 rad at
        /// the boundary nodes, random modal amplitudes, spins of 20 to 50
        /// rad/s (elements::testing::motion). Tolerance 1e-6 of the largest
        /// entry, as for the beam: steps 1e-6 in q (truncation ~1e-10),
        /// 1e-3 in v and v̇ (the residual is quadratic in v and linear in
        /// v̇; exact but for round-off).
        #[test]
        fn matrices_match_finite_differences(
            turn in small_vec(3.0), shift in small_vec(2.0),
            du in proptest::collection::vec(small_vec(0.01), 3),
            dr in proptest::collection::vec(small_vec(0.05), 3),
            r0 in proptest::collection::vec(small_vec(3.0), 3),
            eta in proptest::collection::vec(-0.01..0.01f64, 4),
            rates in proptest::collection::vec(-1.0..1.0f64, 8),
            m in proptest::collection::vec(motion(), 3),
            frame in 0..3usize,
            lumped in proptest::bool::ANY,
        ) {
            let r: Vec<Rotation> = r0.iter().map(so3::exp).collect();
            let inertia = if lumped { InertiaModel::Lumped } else { InertiaModel::Consistent };
            let ids = [[1, 2, 3], [2, 3, 1], [3, 1, 2]][frame];
            let (e, x) = l_frame(&ids, 4, 0.02, inertia, &r);
            let mut state = deformed(&x, &r, &turn, &shift, &du, &dr, eta);
            // slower spins for the body than for a beam element: the
            // flexible body's centrifugal loads stay moderate
            for (k, mk) in m.iter().enumerate() {
                let slow = [mk[0], mk[1] * 0.2, mk[2], mk[3] * 0.2];
                set_motion(&mut state, k, &slow);
            }
            for k in 0..4 {
                state.coordinate_rates[k] = rates[k];
                state.coordinate_accelerations[k] = 10.0 * rates[4 + k];
            }
            for dynamics in [false, true] {
                let c = ctx(dynamics);
                let eq = tangent_error(&e, &c, &state, 1e-6);
                prop_assert!(eq < 1e-6, "∂r/∂q (dynamics {dynamics}): {eq:e}");
            }
            let c = ctx(true);
            let (ev, ea) = rate_errors(&e, &c, &state, 1e-3, 1e-3);
            prop_assert!(ev < 1e-6, "∂r/∂v: {ev:e}");
            prop_assert!(ea < 1e-6, "∂r/∂v̇: {ea:e}");
            // the shares of the inertia and damping forces and of the
            // weight alone (their stiffness, 10 to 60, is 1e-5 of the
            // elastic one, which would hide an error in theirs); step 1e-4:
            // the differences of the share subtract residuals of ~1e4, so
            // a smaller step leaves round-off (measured: 1e-6 at h = 1e-6,
            // 1e-8 at 1e-4, decreasing with h as truncation does not)
            for (name, share) in [("dynamic", Share::Dynamic), ("weight", Share::Weight)] {
                let s = Shared { e: &e, share };
                let eq = tangent_error(&s, &c, &state, 1e-4);
                prop_assert!(eq < 1e-6, "∂r/∂q of the {name} share: {eq:e}");
            }
        }

        /// Acceptance (objectivity): an undeformed superelement in an
        /// arbitrary rigid motion (any rotation and translation, the modal
        /// amplitudes zero) has no elastic force: without gravity its static
        /// residual vanishes to round-off (1e-10 of the forces a 1 cm
        /// boundary displacement makes).
        #[test]
        fn rigid_motion_leaves_no_elastic_force(
            turn in small_vec(3.0), shift in small_vec(5.0),
            r0 in proptest::collection::vec(small_vec(3.0), 3),
        ) {
            let r: Vec<Rotation> = r0.iter().map(so3::exp).collect();
            let (e, x) = l_frame(&[1, 3, 2], 3, 0.0, InertiaModel::Consistent, &r);
            let zero = vec![Vec3::zeros(); 3];
            let state = deformed(&x, &r, &turn, &shift, &zero, &zero, vec![0.0; 3]);
            let c = EvalContext { gravity: Vec3::zeros(), ..ctx(false) };
            let (rigid, _) = eval(&e, &c, &state);
            let bent = deformed(&x, &r, &turn, &shift, &[Vec3::zeros(), Vec3::new(0.0, 0.0, 0.01), Vec3::zeros()], &zero, vec![0.0; 3]);
            let (elastic, _) = eval(&e, &c, &bent);
            let scale = elastic.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let worst = rigid.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            prop_assert!(scale > 1.0);
            prop_assert!(worst <= 1e-10 * scale, "{worst:e} against {scale:e}");
        }
    }
}
