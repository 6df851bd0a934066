//! Geometrically exact 3-D beam (Reissner–Simo; Cardona & Géradin 1988),
//! two nodes, objective interpolation of rotations, one-point (reduced)
//! integration.
//!
//! Formulation (docs/theory.md §3, equation numbers B1–B9 there):
//! - section frames at the ends `Λᵢ = Rᵢ Qᵢ`, with `Qᵢ` the constant offset
//!   from the node frame to the section frame (local axis 1 along the beam,
//!   axis 2 from the reference vector);
//! - relative rotation `φ = log(Λ₁ᵀ Λ₂)` and the interpolation
//!   `Λ(s) = Λ₁ exp((s/L₀) φ~)`, which is the Crisfield–Jelenić objective
//!   interpolation about the midpoint frame `Λₘ = Λ₁ exp(½φ~)` (B1). It is
//!   invariant under rigid motions and path independent, unlike the
//!   interpolation of total rotation vectors of the reference paper (eq. 13);
//! - strains at the midpoint, measured in the section frame (paper eqs. 7-8):
//!   `Γ = Λₘᵀ (x₂ − x₁)/L₀ − Γ₀`, `K = φ/L₀ − K₀` (B2), where `(Γ₀, K₀)`
//!   are the values of the stress-free state: the reference geometry plus
//!   an optional initial strain (pretension by shortening, initial curvature);
//! - stress resultants `(N, M) = C (Γ, K)` with a full 6×6 sectional
//!   stiffness `C`, in the order (axial, shear 2, shear 3, torsion,
//!   bending 2, bending 3);
//! - internal virtual work `L₀ (N·δΓ + M·δK)` (paper eq. 11) evaluated at
//!   the midpoint only: one-point integration, exact for the constant
//!   curvature of this interpolation, and free of shear locking.
//!
//! The tangent is the exact derivative of the residual (material stiffness
//! `L₀ Bᵀ C B` plus every geometric term, B7–B9), checked against finite
//! differences in the tests below.
//!
//! Inertia (docs/theory.md §11.3, eqs. I7–I8): a consistent translational
//! mass and the sectional rotational inertia lumped at the nodes in the
//! section frames `Rᵢ Qᵢ` ([`super::inertia::BeamInertia`]). In dynamics
//! its forces join the residual; its mass and gyroscopic matrices form the
//! inertia matrix (its stiffness block is zero).

use nalgebra::{SMatrix, SVector};

use super::inertia::BeamInertia;
use super::{
    add_block, add_scaled, add_vec, node_motion, CellShape, Element, ElementKind, ElementOutput,
    EvalContext,
};
use crate::curves::{Curve, CurveIndex};
use crate::model::Id;
use crate::so3::{self, skew, Mat3, Operator, Rotation, SkewSeries, Vec3};
use crate::state::State;

/// 6×6 sectional stiffness.
pub type SectionStiffness = SMatrix<f64, 6, 6>;
type Vec6 = SVector<f64, 6>;
type Mat12 = SMatrix<f64, 12, 12>;
type Mat6x12 = SMatrix<f64, 6, 12>;
type Vec12 = SVector<f64, 12>;

/// Stress resultants of a beam section, in the section frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SectionForces {
    /// Force `(N, V₂, V₃)`.
    pub force: Vec3,
    /// Moment `(T, M₂, M₃)`: torsion and bending about local axes 2, 3.
    pub moment: Vec3,
}

/// Properties of a beam cross-section.
#[derive(Clone, Debug, PartialEq)]
pub struct BeamSection {
    /// Sectional stiffness `C` (axial, shear 2, shear 3, torsion,
    /// bending 2, bending 3).
    pub stiffness: SectionStiffness,
    /// Mass per unit length.
    pub mass_per_length: f64,
    /// Rotational inertia per unit length about the section axes 1, 2, 3.
    pub inertia_per_length: Vec3,
}

/// Sectional strains added to the stress-free state of a beam, optionally
/// applied gradually: `f(t) ε_init` with `f` a load curve (all at once if
/// `curve` is `None`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InitialStrain {
    /// `ε_init`: axial, shear 2, shear 3, torsion, curvature 2, curvature 3.
    pub strain: [f64; 6],
    /// Curve `f(t)` that scales it, if any.
    pub curve: Option<CurveIndex>,
}

/// A two-node geometrically exact beam element.
#[derive(Clone, Debug)]
pub struct Beam {
    id: Id,
    nodes: [usize; 2],
    /// Reference length `L₀`.
    length: f64,
    /// Section properties.
    section: BeamSection,
    /// Offsets `Qᵢ` from node frame to section frame.
    offsets: [Rotation; 2],
    /// Strains of the reference configuration, `(Γ_ref, K_ref)`.
    reference_strain: Vec6,
    /// Strain added to the stress-free state.
    initial: InitialStrain,
    /// Inertia (consistent translational mass, lumped rotational inertia).
    inertia: BeamInertia,
    /// Whether the beam has mass or rotational inertia.
    has_inertia: bool,
}

/// Everything computed from one configuration of the element.
struct Kinematics {
    /// Midpoint frame `Λₘ` as a matrix.
    lm: Mat3,
    /// `dₘ = Λₘᵀ (x₂ − x₁)`.
    dm: Vec3,
    /// Relative rotation `φ`.
    phi: Vec3,
    /// Generalised strains `(Γ, K)`.
    strain: Vec6,
}

impl Beam {
    /// Creates a beam between `nodes` (with reference positions `x` and
    /// orientations `r`), with section axis 2 taken from `reference_vector`
    /// (its part normal to the beam axis). The stress-free state is the
    /// reference geometry shifted by the initial strain.
    ///
    /// Returns `None` if the beam has zero length or the reference vector is
    /// parallel to its axis.
    pub fn new(
        id: Id,
        nodes: [usize; 2],
        x: [Vec3; 2],
        r: [Rotation; 2],
        reference_vector: Vec3,
        section: BeamSection,
        initial: InitialStrain,
    ) -> Option<Self> {
        let axis = x[1] - x[0];
        let length = axis.norm();
        if length <= 0.0 || !length.is_finite() {
            return None;
        }
        let frame = so3::frame_from_axis_and_vector(&axis, &reference_vector)?;
        let frame = so3::from_matrix(&frame);
        let offsets = [r[0].inverse() * frame, r[1].inverse() * frame];
        let inertia = BeamInertia::new(length, &section, offsets);
        let has_inertia =
            section.mass_per_length != 0.0 || section.inertia_per_length != Vec3::zeros();
        let mut beam = Self {
            id,
            nodes,
            length,
            section,
            offsets,
            reference_strain: Vec6::zeros(),
            initial,
            inertia,
            has_inertia,
        };
        // strains of the reference configuration: stress-free
        beam.reference_strain = beam.kinematics(&x, &r, &Vec6::zeros()).strain;
        Some(beam)
    }

    /// Strains `(Γ₀, K₀)` of the stress-free state at load parameter `t`:
    /// the reference strains plus `f(t) ε_init`.
    fn free_strain(&self, curves: &[Curve], t: f64) -> Vec6 {
        let scale = self.initial.curve.map_or(1.0, |c| curves[c].value(t));
        self.reference_strain + Vec6::from_row_slice(&self.initial.strain) * scale
    }

    /// Reference length `L₀`.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Section properties.
    pub fn section(&self) -> &BeamSection {
        &self.section
    }

    /// The constant rotations `Qᵢ` from the node frames to the section
    /// frames: the section frame at node `i` is `Rᵢ Qᵢ`.
    pub fn section_offsets(&self) -> &[Rotation; 2] {
        &self.offsets
    }

    /// The beam's inertia.
    pub fn inertia(&self) -> &BeamInertia {
        &self.inertia
    }

    /// Kinematics for node positions `x` and orientations `r`, with the
    /// strains measured from the stress-free strains `free`.
    fn kinematics(&self, x: &[Vec3; 2], r: &[Rotation; 2], free: &Vec6) -> Kinematics {
        // section frames and relative rotation, B1
        let l1 = r[0] * self.offsets[0];
        let l2 = r[1] * self.offsets[1];
        let phi = so3::log(&(l1.inverse() * l2));
        let lm = so3::matrix(&(l1 * so3::exp(&(phi * 0.5))));
        // strains, B2
        let dm = lm.transpose() * (x[1] - x[0]);
        let mut strain = Vec6::zeros();
        strain.fixed_rows_mut::<3>(0).copy_from(&(dm / self.length));
        strain
            .fixed_rows_mut::<3>(3)
            .copy_from(&(phi / self.length));
        strain -= free;
        Kinematics {
            lm,
            dm,
            phi,
            strain,
        }
    }

    fn pose(&self, state: &State) -> ([Vec3; 2], [Rotation; 2]) {
        let [a, b] = self.nodes;
        ([state.x[a], state.x[b]], [state.q[a], state.q[b]])
    }

    /// Kinematics of the current state.
    fn current(&self, ctx: &EvalContext, state: &State) -> Kinematics {
        let (x, r) = self.pose(state);
        self.kinematics(&x, &r, &self.free_strain(ctx.curves, ctx.time))
    }

    /// Section forces at the integration point for the given state.
    pub fn section_forces(&self, ctx: &EvalContext, state: &State) -> SectionForces {
        let k = self.current(ctx, state);
        let s = self.section.stiffness * k.strain;
        SectionForces {
            force: s.fixed_rows::<3>(0).into(),
            moment: s.fixed_rows::<3>(3).into(),
        }
    }

    /// Local residual and tangent in the section variables
    /// `(δx₁, δα₁, δx₂, δα₂)`, `δαᵢ = Qᵢᵀ δΘᵢ`.
    fn local(&self, k: &Kinematics, need_tangent: bool) -> (Vec12, Option<Mat12>) {
        let l0 = self.length;
        let c = &self.section.stiffness;
        let sigma = c * k.strain;
        let n: Vec3 = sigma.fixed_rows::<3>(0).into();
        let m: Vec3 = sigma.fixed_rows::<3>(3).into();

        // operators of the interpolation, B3
        let ti = SkewSeries::new(Operator::TangentInv, &k.phi);
        let th = SkewSeries::new(Operator::Tangent, &(k.phi * 0.5));
        let eh = SkewSeries::new(Operator::Exp, &(k.phi * 0.5));
        let ti_m = ti.matrix();
        let th_m = th.matrix();
        let eh_m = eh.matrix();
        // δφ = Bφ₁ δα₁ + Bφ₂ δα₂, δβ = Bβ₁ δα₁ + Bβ₂ δα₂ (spin of Λₘ), B4
        let bphi = [-ti_m.transpose(), ti_m];
        let bbeta = [
            eh_m.transpose() - th_m * ti_m.transpose() * 0.5,
            th_m * ti_m * 0.5,
        ];

        // residual, B5: f_x = ∓Λₘ N, f_α = Bβᵀ (N × dₘ) + Bφᵀ M
        let h = n.cross(&k.dm);
        let lm_n = k.lm * n;
        let mut f = Vec12::zeros();
        f.fixed_rows_mut::<3>(0).copy_from(&(-lm_n));
        f.fixed_rows_mut::<3>(6).copy_from(&lm_n);
        for i in 0..2 {
            let fa = bbeta[i].transpose() * h + bphi[i].transpose() * m;
            f.fixed_rows_mut::<3>(6 * i + 3).copy_from(&fa);
        }
        if !need_tangent {
            return (f, None);
        }

        // strain-displacement matrix, B6
        let g = k.dm / l0;
        let g_skew = skew(&g);
        let lmt = k.lm.transpose() / l0;
        let mut b = Mat6x12::zeros();
        b.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-lmt));
        b.fixed_view_mut::<3, 3>(0, 6).copy_from(&lmt);
        for i in 0..2 {
            b.fixed_view_mut::<3, 3>(0, 6 * i + 3)
                .copy_from(&(g_skew * bbeta[i]));
            b.fixed_view_mut::<3, 3>(3, 6 * i + 3)
                .copy_from(&(bphi[i] / l0));
        }
        // material stiffness, B7
        let mut kt: Mat12 = b.transpose() * (c * b) * l0;

        // geometric stiffness, B8: derivatives of Bᵀσ at fixed σ
        let n_skew = skew(&n);
        let dm_skew = skew(&k.dm);
        // derivatives of Bβᵢᵀ w and Bφᵢᵀ w with respect to φ, B9
        let th_t_h = th.apply_transpose(&h);
        let d_th_t_h = th.derivative_of_apply_transpose(&h) * 0.5;
        let d_beta = [
            eh.derivative_of_apply(&h) * 0.5
                - (ti.derivative_of_apply(&th_t_h) + ti_m * d_th_t_h) * 0.5,
            (ti.derivative_of_apply_transpose(&th_t_h) + ti_m.transpose() * d_th_t_h) * 0.5,
        ];
        let d_phi = [
            -ti.derivative_of_apply(&m),
            ti.derivative_of_apply_transpose(&m),
        ];
        let lm_nskew = k.lm * n_skew;
        let n_lmt = n_skew * k.lm.transpose();
        let n_dm = n_skew * dm_skew;
        for j in 0..2 {
            let cj = 6 * j + 3;
            // rows x: ∓Λₘ N~ Bβⱼ
            let blk = lm_nskew * bbeta[j];
            add_mat(&mut kt, 0, cj, &blk);
            add_mat(&mut kt, 6, cj, &(-blk));
        }
        for i in 0..2 {
            let ri = 6 * i + 3;
            let bbt = bbeta[i].transpose();
            // columns x: Bβᵢᵀ N~ Λₘᵀ (δx₂ − δx₁)
            let blk = bbt * n_lmt;
            add_mat(&mut kt, ri, 0, &(-blk));
            add_mat(&mut kt, ri, 6, &blk);
            for j in 0..2 {
                let cj = 6 * j + 3;
                let blk = bbt * n_dm * bbeta[j] + (d_beta[i] + d_phi[i]) * bphi[j];
                add_mat(&mut kt, ri, cj, &blk);
            }
        }
        (f, Some(kt))
    }
}

#[inline]
fn add_mat(k: &mut Mat12, r: usize, c: usize, m: &Mat3) {
    let mut v = k.fixed_view_mut::<3, 3>(r, c);
    v += m;
}

impl Element for Beam {
    /// An element whose end sections turn relative to each other past half
    /// a turn: `φ = log(Λ₁ᵀ Λ₂)` (B1) jumps there by a full turn and the
    /// interpolation with it (docs/theory.md §3.1); the mesh is too coarse
    /// for the bending or twist reached.
    fn law_violated(&self, before: &State, after: &State) -> Option<String> {
        let phi = |s: &State| {
            let l1 = s.q[self.nodes[0]] * self.offsets[0];
            let l2 = s.q[self.nodes[1]] * self.offsets[1];
            so3::log(&(l1.inverse() * l2))
        };
        let (a, b) = (phi(before), phi(after));
        ((b - a).norm() > std::f64::consts::PI).then(|| {
            format!(
                "the relative rotation of its end sections passed half a turn (from {:.4} to {:.4} rad, measured the other way round), which one element cannot represent (docs/theory.md §3.1); divide the beam into more elements",
                a.norm(),
                b.norm()
            )
        })
    }

    fn kind(&self) -> ElementKind {
        ElementKind::Beam
    }

    fn id(&self) -> Id {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let k = self.current(ctx, state);
        let (f, kt) = self.local(&k, out.stiffness.is_some());
        let q = [so3::matrix(&self.offsets[0]), so3::matrix(&self.offsets[1])];

        // residual, rotated from section to node frames: f_Θ = Q f_α
        let weight = -0.5 * self.section.mass_per_length * self.length;
        for i in 0..2 {
            let fx: Vec3 = f.fixed_rows::<3>(6 * i).into();
            let fa: Vec3 = f.fixed_rows::<3>(6 * i + 3).into();
            // gravity: half the weight at each node (dead load)
            add_vec(out.residual, 6 * i, &(fx + ctx.gravity * weight));
            add_vec(out.residual, 6 * i + 3, &(q[i] * fa));
        }
        if let (Some(kt), Some(stiffness)) = (kt, out.stiffness.as_deref_mut()) {
            // K_ΘΘ = Qᵢ K_αα Qⱼᵀ, K_xΘ = K_xα Qⱼᵀ, K_Θx = Qᵢ K_αx
            for bi in 0..4 {
                for bj in 0..4 {
                    let mut blk: Mat3 = kt.fixed_view::<3, 3>(3 * bi, 3 * bj).into();
                    if bi % 2 == 1 {
                        blk = q[bi / 2] * blk;
                    }
                    if bj % 2 == 1 {
                        blk *= q[bj / 2].transpose();
                    }
                    add_block(stiffness, 12, 3 * bi, 3 * bj, &blk);
                }
            }
        }

        // inertia, I8: forces in dynamics; M and C in the inertia matrix
        // (its stiffness block is zero: constant global translational mass,
        // material rotational terms)
        let weights = ctx.need.inertia.filter(|_| out.inertia.is_some());
        if !self.has_inertia || !(ctx.dynamics || weights.is_some()) {
            return;
        }
        let motion = [
            node_motion(state, self.nodes[0]),
            node_motion(state, self.nodes[1]),
        ];
        if ctx.dynamics {
            let r = self.inertia.residual(&motion);
            for (o, v) in out.residual.iter_mut().zip(r.iter()) {
                *o += v;
            }
        }
        if let (Some(w), Some(d)) = (weights, out.inertia.as_deref_mut()) {
            let blocks = self.inertia.evaluate(&motion);
            add_scaled(d, 12, 0, w.mass, &blocks.mass);
            add_scaled(d, 12, 0, w.damping, &blocks.gyroscopic);
        }
    }

    fn result_names(&self) -> &'static [&'static str] {
        &["N", "V2", "V3", "T", "M2", "M3"]
    }

    fn results(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let s = self.section_forces(ctx, state);
        out[..3].copy_from_slice(s.force.as_slice());
        out[3..6].copy_from_slice(s.moment.as_slice());
    }

    /// Strain energy `½ L₀ εᵀ C ε`.
    fn strain_energy(&self, ctx: &EvalContext, state: &State) -> f64 {
        let k = self.current(ctx, state);
        0.5 * self.length * k.strain.dot(&(self.section.stiffness * k.strain))
    }

    fn kinetic_energy(&self, state: &State) -> f64 {
        if !self.has_inertia {
            return 0.0;
        }
        self.inertia.kinetic_energy(&[
            node_motion(state, self.nodes[0]),
            node_motion(state, self.nodes[1]),
        ])
    }

    fn momenta(&self, state: &State) -> super::inertia::Momenta {
        if !self.has_inertia {
            return Default::default();
        }
        self.inertia.momenta(&[
            node_motion(state, self.nodes[0]),
            node_motion(state, self.nodes[1]),
        ])
    }

    /// `−ρA L₀ g·(x₁ + x₂)/2`: the weight of §3.4, half at each node.
    fn weight_potential(&self, ctx: &EvalContext, state: &State) -> f64 {
        let centre = 0.5 * (state.x[self.nodes[0]] + state.x[self.nodes[1]]);
        -self.section.mass_per_length * self.length * ctx.gravity.dot(&centre)
    }

    fn cell_shape(&self) -> CellShape {
        CellShape::Line
    }

    fn mass(&self) -> f64 {
        self.section.mass_per_length * self.length
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::{eval, motion, rate_errors, set_motion, tangent_error};
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    /// A step that turns the end sections of an element past half a turn
    /// relative to each other (0.9π to 1.1π about the beam's axis, which
    /// the logarithm measures as −0.9π) violates its law; steps below half
    /// a turn (0.3π to 0.9π), or backwards, do not.
    #[test]
    fn relative_rotations_past_half_a_turn_are_found() {
        let x = [Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0)];
        let r = [Rotation::identity(); 2];
        let beam = test_beam(x, r, [0.0; 6]);
        let twisted = |a: f64| {
            state_of(
                x,
                [
                    Rotation::identity(),
                    so3::exp(&Vec3::new(a * std::f64::consts::PI, 0.0, 0.0)),
                ],
            )
        };
        let (s3, s9, s11) = (twisted(0.3), twisted(0.9), twisted(1.1));
        assert!(beam.law_violated(&s3, &s9).is_none());
        assert!(beam.law_violated(&s9, &s3).is_none());
        let why = beam.law_violated(&s9, &s11).expect("half a turn passed");
        assert!(why.contains("passed half a turn"), "{why}");
        assert!(beam.law_violated(&s11, &s9).is_some());
    }

    fn ctx(curves: &[crate::curves::Curve]) -> EvalContext<'_> {
        EvalContext {
            time: 1.0,
            curves,
            gravity: Vec3::new(0.0, 0.0, -9.81),
            need: crate::elements::Need::STIFFNESS,
            dynamics: false,
            scaling: Default::default(),
        }
    }

    fn section(stiffness: SectionStiffness, mass_per_length: f64) -> BeamSection {
        BeamSection {
            stiffness,
            mass_per_length,
            inertia_per_length: Vec3::zeros(),
        }
    }

    /// A beam with a full, coupled 6×6 section (all terms exercised).
    fn test_beam(x: [Vec3; 2], r: [Rotation; 2], initial: [f64; 6]) -> Beam {
        let mut c =
            SectionStiffness::from_diagonal(&Vec6::new(3.0e3, 1.2e3, 1.1e3, 0.8e2, 1.5e2, 2.0e2));
        // symmetric coupling terms (composite-like section)
        c[(0, 4)] = 50.0;
        c[(4, 0)] = 50.0;
        c[(1, 3)] = -20.0;
        c[(3, 1)] = -20.0;
        let section = BeamSection {
            stiffness: c,
            mass_per_length: 2.0,
            inertia_per_length: Vec3::new(0.1, 0.05, 0.05),
        };
        let initial = InitialStrain {
            strain: initial,
            curve: None,
        };
        Beam::new(1, [0, 1], x, r, Vec3::new(0.2, 1.0, 0.3), section, initial).unwrap()
    }

    fn state_of(x: [Vec3; 2], r: [Rotation; 2]) -> State {
        State::at_rest(0.0, x.to_vec(), r.to_vec())
    }

    fn small_vec(max: f64) -> impl Strategy<Value = Vec3> {
        (-max..max, -max..max, -max..max).prop_map(|(a, b, c)| Vec3::new(a, b, c))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Acceptance: the tangent equals central finite differences of the
        /// residual (relative error ≤ 1e-6; the O(h²) truncation with
        /// h = 1e-6 is ~1e-10, round-off ~1e-9) on random deformed
        /// configurations with large rotations.
        #[test]
        fn tangent_matches_finite_differences(
            r1 in small_vec(3.0), r2 in small_vec(3.0),
            dr1 in small_vec(1.2), dr2 in small_vec(1.2),
            dx1 in small_vec(0.3), dx2 in small_vec(0.3),
            e in small_vec(0.05),
        ) {
            // reference: a beam of length ~1 with random node orientations
            let x = [Vec3::new(0.1, -0.2, 0.3), Vec3::new(1.0, 0.3, 0.1)];
            let r = [so3::exp(&r1), so3::exp(&r2)];
            let beam = test_beam(x, r, [e.x, e.y, e.z, 0.02, -0.01, 0.03]);
            // deformed: translated and rotated by up to ~1.2 rad per node,
            // relative element rotation kept below π
            let xs = [x[0] + dx1, x[1] + dx2];
            let rs = [r[0] * so3::exp(&dr1), r[1] * so3::exp(&dr2)];
            let state = state_of(xs, rs);
            let curves = [];
            let err = tangent_error(&beam, &ctx(&curves), &state, 1e-6);
            prop_assert!(err < 1e-6, "relative tangent error {err:e}");
        }

        /// Acceptance, in dynamics: the full element residual (elastic,
        /// weight and inertia forces, I8) has the stiffness as its
        /// derivative in q, and the inertia matrix with weights (1, 0) and
        /// (0, 1) as its derivatives in v and v̇, against central
        /// differences (relative error ≤ 1e-6), on random deformed states
        /// with large rotations and spins of 20 to 50 rad/s. Steps: 1e-6 in
        /// q (truncation ~1e-10); 1e-3 in v and v̇ (the residual is
        /// quadratic in v and linear in v̇: central differences are exact
        /// but for round-off).
        #[test]
        fn dynamic_matrices_match_finite_differences(
            r1 in small_vec(3.0), r2 in small_vec(3.0),
            dr1 in small_vec(1.2), dr2 in small_vec(1.2),
            dx1 in small_vec(0.3), dx2 in small_vec(0.3),
            m1 in motion(), m2 in motion(),
        ) {
            let x = [Vec3::new(0.1, -0.2, 0.3), Vec3::new(1.0, 0.3, 0.1)];
            let r = [so3::exp(&r1), so3::exp(&r2)];
            let beam = test_beam(x, r, [0.01, 0.0, 0.0, 0.02, -0.01, 0.03]);
            let mut state = state_of(
                [x[0] + dx1, x[1] + dx2],
                [r[0] * so3::exp(&dr1), r[1] * so3::exp(&dr2)],
            );
            set_motion(&mut state, 0, &m1);
            set_motion(&mut state, 1, &m2);
            let curves = [];
            let c = EvalContext { dynamics: true, ..ctx(&curves) };
            let eq = tangent_error(&beam, &c, &state, 1e-6);
            let (ev, ea) = rate_errors(&beam, &c, &state, 1e-3, 1e-3);
            prop_assert!(eq < 1e-6, "∂r/∂q: {eq:e}");
            prop_assert!(ev < 1e-6, "∂r/∂v: {ev:e}");
            prop_assert!(ea < 1e-6, "∂r/∂v̇: {ea:e}");
            // the inertia forces are there: the residual differs from the
            // static one
            let (rd, _) = eval(&beam, &c, &state);
            let (rs, _) = eval(&beam, &ctx(&curves), &state);
            prop_assert!(rd.iter().zip(&rs).any(|(a, b)| (a - b).abs() > 1.0));
        }
    }

    #[test]
    fn reference_configuration_is_stress_free() {
        // curved and twisted reference (node frames not aligned), no
        // initial strain: zero residual apart from gravity
        let x = [Vec3::zeros(), Vec3::new(1.0, 0.5, 0.0)];
        let r = [
            so3::exp(&Vec3::new(0.1, 0.2, 0.3)),
            so3::exp(&Vec3::new(-0.3, 0.1, 0.5)),
        ];
        let beam = test_beam(x, r, [0.0; 6]);
        let curves = [];
        let mut c = ctx(&curves);
        c.gravity = Vec3::zeros();
        let (f, _) = eval(&beam, &c, &state_of(x, r));
        assert!(f.iter().all(|v| v.abs() < 1e-12), "{f:?}");
        assert_eq!(beam.strain_energy(&c, &state_of(x, r)), 0.0);
    }

    #[test]
    fn initial_shortening_gives_tension() {
        // stress-free when 1 % shorter: at the reference length, N = EA·0.01
        let x = [Vec3::zeros(), Vec3::new(2.0, 0.0, 0.0)];
        let r = [Rotation::identity(); 2];
        let c = SectionStiffness::from_diagonal(&Vec6::new(1e4, 1e3, 1e3, 1e2, 1e2, 1e2));
        let shortening = [-0.01, 0.0, 0.0, 0.0, 0.0, 0.0];
        let all_at_once = InitialStrain {
            strain: shortening,
            curve: None,
        };
        let beam = Beam::new(1, [0, 1], x, r, Vec3::z(), section(c, 0.0), all_at_once).unwrap();
        let curves = [crate::curves::Curve::ramp()];
        let s = beam.section_forces(&ctx(&curves), &state_of(x, r));
        assert_relative_eq!(s.force.x, 100.0, epsilon = 1e-9);
        assert_relative_eq!(s.moment.norm(), 0.0, epsilon = 1e-12);
        // applied along the ramp: at t = 0.25, a quarter of it
        let gradual = InitialStrain {
            strain: shortening,
            curve: Some(0),
        };
        let beam = Beam::new(1, [0, 1], x, r, Vec3::z(), section(c, 0.0), gradual).unwrap();
        let mut at = ctx(&curves);
        at.time = 0.25;
        assert_relative_eq!(
            beam.section_forces(&at, &state_of(x, r)).force.x,
            25.0,
            epsilon = 1e-9
        );
    }

    #[test]
    fn gravity_puts_half_the_weight_on_each_node() {
        let x = [Vec3::zeros(), Vec3::new(2.0, 0.0, 0.0)];
        let r = [Rotation::identity(); 2];
        let c = SectionStiffness::identity();
        let beam = Beam::new(
            1,
            [0, 1],
            x,
            r,
            Vec3::z(),
            section(c, 3.0),
            InitialStrain::default(),
        )
        .unwrap();
        let curves = [];
        let (f, _) = eval(&beam, &ctx(&curves), &state_of(x, r));
        // residual = −f_ext = −(−m L g/2) in z: 3·2·9.81/2 = 29.43
        assert_relative_eq!(f[2], 29.43, epsilon = 1e-12);
        assert_relative_eq!(f[8], 29.43, epsilon = 1e-12);
    }

    #[test]
    fn rejects_degenerate_geometry() {
        let r = [Rotation::identity(); 2];
        let c = section(SectionStiffness::identity(), 0.0);
        let p = Vec3::new(1.0, 1.0, 1.0);
        let none = InitialStrain::default();
        assert!(Beam::new(1, [0, 1], [p, p], r, Vec3::z(), c.clone(), none).is_none());
        let along_z = [Vec3::zeros(), Vec3::z()];
        assert!(Beam::new(1, [0, 1], along_z, r, Vec3::z(), c, none).is_none());
    }
}
