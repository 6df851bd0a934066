//! Inertia forces of rigid bodies, point masses and beams on the group
//! SO(3) × R³ (docs/theory.md §11, equations I1–I10).
//!
//! Each node carries a position `x` (global frame) and an orientation `R`
//! (material frame → global frame), updated by `x ← x + Δx`,
//! `R ← R exp(ΔΘ~)` (material increments, docs/theory.md §2). Velocities and
//! accelerations live in the same frames: `ẋ`, `ẍ` global, `Ω`, `Ω̇`
//! material (`RᵀṘ = Ω~`, paper eq. 5).
//!
//! Every kernel returns the inertia residual `r = M(q) a + g(q, v)`, the
//! generalised inertia forces conjugate to `(δx, δΘ)` derived from the
//! kinetic energy by Hamilton's principle, and its three tangent blocks
//! - `M = ∂r/∂a` (mass),
//! - `C = ∂r/∂v` (gyroscopic and Coriolis),
//! - `K = ∂r/∂q` (centrifugal), taken along the update above with `v` and
//!   `a` held fixed as the global/material quantities listed above,
//!
//! which are the blocks of the iteration matrix `β' M + γ' C + K` of the
//! Lie group generalised-α method (Brüls, Cardona & Arnold 2012). The
//! residual enters `r = f_int − f_ext` with the sign of an internal force.
//! Weight is not included: it is a static load (docs/theory.md §4, eq. M1).
//!
//! Beams use a consistent translational mass, constant in the global frame
//! (paper eq. 12), and their sectional rotational inertia lumped at the two
//! nodes in the section frames `Rᵢ Qᵢ` (docs/theory.md §11.3 gives the
//! reasons). Kinetic energy and momenta are provided for energy and
//! momentum outputs.
//!
//! Vectors and matrices are ordered `(x, Θ)` per node, `(x₁, Θ₁, x₂, Θ₂)`
//! for beams, as in the element residuals.

use nalgebra::{SMatrix, SVector};

use super::beam::BeamSection;
use crate::so3::{self, skew, Mat3, Rotation, Vec3};

/// 6-vector (one node).
pub type Vec6 = SVector<f64, 6>;
/// 12-vector (two nodes).
pub type Vec12 = SVector<f64, 12>;

/// Motion of one node: configuration, velocity and acceleration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeMotion {
    /// Position `x`, global frame.
    pub position: Vec3,
    /// Orientation `R`, material frame → global frame.
    pub rotation: Rotation,
    /// Velocity `ẋ`, global frame.
    pub velocity: Vec3,
    /// Angular velocity `Ω`, material frame (`RᵀṘ = Ω~`).
    pub angular_velocity: Vec3,
    /// Acceleration `ẍ`, global frame.
    pub acceleration: Vec3,
    /// Angular acceleration `Ω̇`, material frame (time derivative of `Ω`).
    pub angular_acceleration: Vec3,
}

impl NodeMotion {
    /// A node at rest at the given pose.
    pub fn at_rest(position: Vec3, rotation: Rotation) -> Self {
        Self {
            position,
            rotation,
            velocity: Vec3::zeros(),
            angular_velocity: Vec3::zeros(),
            acceleration: Vec3::zeros(),
            angular_acceleration: Vec3::zeros(),
        }
    }
}

/// Inertia residual and its tangent blocks for `N` local unknowns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InertiaForces<const N: usize> {
    /// Residual `r = M(q) a + g(q, v)`.
    pub residual: SVector<f64, N>,
    /// Mass matrix `M = ∂r/∂a`.
    pub mass: SMatrix<f64, N, N>,
    /// Gyroscopic matrix `C = ∂r/∂v`.
    pub gyroscopic: SMatrix<f64, N, N>,
    /// Inertial (centrifugal) stiffness `K = ∂r/∂q` along the update rule.
    pub stiffness: SMatrix<f64, N, N>,
}

impl<const N: usize> InertiaForces<N> {
    fn zeros() -> Self {
        Self {
            residual: SVector::zeros(),
            mass: SMatrix::zeros(),
            gyroscopic: SMatrix::zeros(),
            stiffness: SMatrix::zeros(),
        }
    }
}

/// Linear momentum and angular momentum about the global origin, both in
/// global components.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Momenta {
    /// Linear momentum `p`.
    pub linear: Vec3,
    /// Angular momentum `H_O` about the global origin.
    pub angular: Vec3,
}

/// Inertia of a rigid body carried by one node: mass `m`, centre of mass at
/// the offset `c` from the node and inertia tensor `J` about the centre of
/// mass, both in the node material frame. A point mass has `c = 0`,
/// `J = 0`.
///
/// The data are taken as validated by the model (`m ≥ 0`, `J` positive
/// semi-definite); only the symmetric part of `J` carries kinetic energy,
/// and that is the part used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidBodyInertia {
    /// Mass `m`.
    mass: f64,
    /// Centre-of-mass offset `c`, node material frame.
    offset: Vec3,
    /// Inertia `J` about the centre of mass, node material frame.
    inertia: Mat3,
    /// Inertia about the node, `J_O = J + m (|c|² I − c cᵀ)` (I2).
    inertia_at_node: Mat3,
}

impl RigidBodyInertia {
    /// A rigid body of mass `mass`, inertia `inertia` about its centre of
    /// mass and centre of mass at `offset` (both in the node material
    /// frame), in the argument order of [`super::mass::RigidBody::new`].
    pub fn new(mass: f64, inertia: Mat3, offset: Vec3) -> Self {
        let inertia = (inertia + inertia.transpose()) * 0.5;
        // parallel-axis theorem, I2
        let inertia_at_node = inertia
            + (Mat3::identity() * offset.norm_squared() - offset * offset.transpose()) * mass;
        Self {
            mass,
            offset,
            inertia,
            inertia_at_node,
        }
    }

    /// A point mass at the node.
    pub fn point_mass(mass: f64) -> Self {
        Self::new(mass, Mat3::zeros(), Vec3::zeros())
    }

    /// Mass `m`.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// Centre-of-mass offset `c` (node material frame).
    pub fn offset(&self) -> &Vec3 {
        &self.offset
    }

    /// Inertia `J` about the centre of mass (node material frame).
    pub fn inertia(&self) -> &Mat3 {
        &self.inertia
    }

    /// Inertia `J_O` about the node (node material frame).
    pub fn inertia_at_node(&self) -> &Mat3 {
        &self.inertia_at_node
    }

    /// Inertia residual, eq. I2:
    /// `r_x = m (ẍ + R (Ω̇ × c + Ω × (Ω × c)))`,
    /// `r_Θ = J_O Ω̇ + Ω × J_O Ω + m c × (Rᵀ ẍ)`.
    pub fn residual(&self, n: &NodeMotion) -> Vec6 {
        let r = so3::matrix(&n.rotation);
        let (m, c, jo) = (self.mass, &self.offset, &self.inertia_at_node);
        let (w, w_dot) = (&n.angular_velocity, &n.angular_acceleration);

        // acceleration of the centre of mass relative to the node, material
        let rel = w_dot.cross(c) + w.cross(&w.cross(c));
        let rx = (n.acceleration + r * rel) * m;
        let rt = jo * w_dot + w.cross(&(jo * w)) + c.cross(&(r.transpose() * n.acceleration)) * m;
        let mut out = Vec6::zeros();
        out.fixed_rows_mut::<3>(0).copy_from(&rx);
        out.fixed_rows_mut::<3>(3).copy_from(&rt);
        out
    }

    /// Inertia residual (I2) with its mass (I3), gyroscopic (I4) and
    /// centrifugal stiffness (I5) blocks.
    pub fn evaluate(&self, n: &NodeMotion) -> InertiaForces<6> {
        let r = so3::matrix(&n.rotation);
        let (m, c, jo) = (self.mass, &self.offset, &self.inertia_at_node);
        let (w, w_dot) = (&n.angular_velocity, &n.angular_acceleration);
        let c_skew = skew(c);
        let w_skew = skew(w);
        let mut f = InertiaForces::<6>::zeros();
        f.residual = self.residual(n);

        // mass, I3: [m I, −m R c~; m c~ Rᵀ, J_O]
        let r_c = r * c_skew * m;
        f.mass
            .fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Mat3::identity() * m));
        f.mass.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-r_c));
        f.mass
            .fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(c_skew * r.transpose() * m));
        f.mass.fixed_view_mut::<3, 3>(3, 3).copy_from(jo);

        // gyroscopic, I4: ∂/∂Ω of R Ω×(Ω×c) and of Ω × J_O Ω
        let c_xw = -r * (skew(&w.cross(c)) + w_skew * c_skew) * m;
        let c_tw = w_skew * jo - skew(&(jo * w));
        f.gyroscopic.fixed_view_mut::<3, 3>(0, 3).copy_from(&c_xw);
        f.gyroscopic.fixed_view_mut::<3, 3>(3, 3).copy_from(&c_tw);

        // centrifugal stiffness, I5: R → R (I + δΘ~) at fixed ẍ, Ω, Ω̇
        let rel = w_dot.cross(c) + w.cross(&w.cross(c));
        let k_xt = -r * skew(&rel) * m;
        let k_tt = c_skew * skew(&(r.transpose() * n.acceleration)) * m;
        f.stiffness.fixed_view_mut::<3, 3>(0, 3).copy_from(&k_xt);
        f.stiffness.fixed_view_mut::<3, 3>(3, 3).copy_from(&k_tt);
        f
    }

    /// Velocity of the centre of mass, `ẋ + R (Ω × c)` (global).
    fn centre_velocity(&self, n: &NodeMotion) -> Vec3 {
        n.velocity + n.rotation * n.angular_velocity.cross(&self.offset)
    }

    /// Kinetic energy, eq. I1: `½ m |ẋ + R (Ω × c)|² + ½ Ω·J Ω`.
    pub fn kinetic_energy(&self, n: &NodeMotion) -> f64 {
        let u = self.centre_velocity(n);
        let w = &n.angular_velocity;
        0.5 * self.mass * u.norm_squared() + 0.5 * w.dot(&(self.inertia * w))
    }

    /// Linear momentum `m u` and angular momentum about the global origin
    /// `(x + R c) × m u + R J Ω`, with `u` the centre-of-mass velocity, I6.
    pub fn momenta(&self, n: &NodeMotion) -> Momenta {
        let p = self.centre_velocity(n) * self.mass;
        let centre = n.position + n.rotation * self.offset;
        Momenta {
            linear: p,
            angular: centre.cross(&p) + n.rotation * (self.inertia * n.angular_velocity),
        }
    }
}

/// Inertia of a two-node beam: consistent translational mass, constant in
/// the global frame (I7, paper eq. 12), and the sectional rotational
/// inertia lumped at the nodes in the section frames `Rᵢ Qᵢ` (I8).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamInertia {
    /// Total mass `ρA L₀`.
    mass: f64,
    /// Half the sectional inertia at each node: zero-mass rigid bodies
    /// with `Jᵢ = ½ L₀ Qᵢ diag(ρJ, ρI₂, ρI₃) Qᵢᵀ`.
    rotary: [RigidBodyInertia; 2],
}

impl BeamInertia {
    /// The inertia of a beam of reference length `length` with the mass
    /// per length and sectional inertia per length (about the section axes
    /// 1, 2, 3) of `section`; `offsets` are the constant rotations `Qᵢ` from
    /// node frame to section frame, so that the section frame at node `i`
    /// is `Rᵢ Qᵢ` (as in [`super::beam::Beam`]).
    pub fn new(length: f64, section: &BeamSection, offsets: [Rotation; 2]) -> Self {
        let section_inertia = Mat3::from_diagonal(&section.inertia_per_length);
        let rotary = offsets.map(|q| {
            let q = so3::matrix(&q);
            let j = q * section_inertia * q.transpose() * (0.5 * length);
            RigidBodyInertia::new(0.0, j, Vec3::zeros())
        });
        Self {
            mass: section.mass_per_length * length,
            rotary,
        }
    }

    /// Total mass `ρA L₀`.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// Entry `(i, j)` of the consistent translational mass (I7):
    /// `ρA L₀ / 3` on the diagonal, `ρA L₀ / 6` off it (times `I₃`).
    fn translational(&self, i: usize, j: usize) -> f64 {
        if i == j {
            self.mass / 3.0
        } else {
            self.mass / 6.0
        }
    }

    /// The mass matrix `M` of I8, constant: `[Mᵢⱼ] I₃` on the
    /// translations (global), `Jᵢ` on the rotations (material).
    pub fn mass_matrix(&self) -> SMatrix<f64, 12, 12> {
        let mut m = SMatrix::<f64, 12, 12>::zeros();
        for i in 0..2 {
            m.fixed_view_mut::<3, 3>(6 * i + 3, 6 * i + 3)
                .copy_from(self.rotary[i].inertia_at_node());
            for j in 0..2 {
                m.fixed_view_mut::<3, 3>(6 * i, 6 * j)
                    .copy_from(&(Mat3::identity() * self.translational(i, j)));
            }
        }
        m
    }

    /// Inertia residual, eq. I8: `r_xᵢ = Σⱼ Mᵢⱼ ẍⱼ`,
    /// `r_Θᵢ = Jᵢ Ω̇ᵢ + Ωᵢ × Jᵢ Ωᵢ`.
    pub fn residual(&self, n: &[NodeMotion; 2]) -> Vec12 {
        let mut out = Vec12::zeros();
        for i in 0..2 {
            let mut rx = self.rotary[i].residual(&n[i]);
            for j in 0..2 {
                let a = n[j].acceleration * self.translational(i, j);
                let mut top = rx.fixed_rows_mut::<3>(0);
                top += a;
            }
            out.fixed_rows_mut::<6>(6 * i).copy_from(&rx);
        }
        out
    }

    /// Inertia residual (I8) with its mass, gyroscopic and stiffness
    /// blocks. `K` is zero: the translational mass is constant in the
    /// global frame and the rotational terms involve only material
    /// quantities (`Ωᵢ`, `Ω̇ᵢ`, constant `Jᵢ`).
    pub fn evaluate(&self, n: &[NodeMotion; 2]) -> InertiaForces<12> {
        let mut f = InertiaForces::<12>::zeros();
        f.residual = self.residual(n);
        for i in 0..2 {
            // rotational, lumped: the blocks of a rigid body with c = 0
            let node = self.rotary[i].evaluate(&n[i]);
            f.mass
                .fixed_view_mut::<6, 6>(6 * i, 6 * i)
                .copy_from(&node.mass);
            f.gyroscopic
                .fixed_view_mut::<6, 6>(6 * i, 6 * i)
                .copy_from(&node.gyroscopic);
            f.stiffness
                .fixed_view_mut::<6, 6>(6 * i, 6 * i)
                .copy_from(&node.stiffness);
            // translational, consistent
            for j in 0..2 {
                let mij = Mat3::identity() * self.translational(i, j);
                let mut blk = f.mass.fixed_view_mut::<3, 3>(6 * i, 6 * j);
                blk += mij;
            }
        }
        f
    }

    /// Adds what [`BeamInertia::residual`] and [`BeamInertia::evaluate`]
    /// give, in one pass and only on their nonzero blocks: the residual
    /// (I8) into `residual` when given, and `w_m M + w_d C` into the
    /// column-major 12 × 12 buffer `matrix` when given (`weights =
    /// (w_m, w_d)`). Per node the rotational blocks are those of a rigid
    /// body with `c = 0`: `Mᵢ = Jᵢ`, `Cᵢ = Ωᵢ~ Jᵢ − (Jᵢ Ωᵢ)~` (I3–I4), no
    /// rotation matrix needed; the translational mass is `Mᵢⱼ I₃` (I7). The
    /// same arithmetic as the general kernels, entry by entry.
    pub fn add_to(
        &self,
        velocity: [&[f64; 6]; 2],
        acceleration: [&[f64; 6]; 2],
        residual: Option<&mut [f64]>,
        matrix: Option<(&mut [f64], [f64; 2])>,
    ) {
        let v3 = |a: &[f64; 6], k: usize| Vec3::new(a[k], a[k + 1], a[k + 2]);
        if let Some(out) = residual {
            for i in 0..2 {
                let jo = self.rotary[i].inertia_at_node();
                let (w, w_dot) = (v3(velocity[i], 3), v3(acceleration[i], 3));
                // r_xᵢ = Σⱼ Mᵢⱼ ẍⱼ, r_Θᵢ = Jᵢ Ω̇ᵢ + Ωᵢ × Jᵢ Ωᵢ
                let mut rx = Vec3::zeros();
                for (j, a) in acceleration.iter().enumerate() {
                    rx += v3(a, 0) * self.translational(i, j);
                }
                let rt = jo * w_dot + w.cross(&(jo * w));
                for k in 0..3 {
                    out[6 * i + k] += rx[k];
                    out[6 * i + 3 + k] += rt[k];
                }
            }
        }
        let Some((d, [w_mass, w_damping])) = matrix else {
            return;
        };
        // the 12 × 12 buffer, its length checked once
        let d = &mut d[..144];
        for i in 0..2 {
            let jo = self.rotary[i].inertia_at_node();
            let w = v3(velocity[i], 3);
            let c_tw = skew(&w) * jo - skew(&(jo * w));
            let r = 6 * i + 3;
            for col in 0..3 {
                for row in 0..3 {
                    let e = &mut d[(r + col) * 12 + r + row];
                    *e += w_mass * jo[(row, col)];
                    *e += w_damping * c_tw[(row, col)];
                }
            }
            for j in 0..2 {
                let m = w_mass * self.translational(i, j);
                for k in 0..3 {
                    d[(6 * j + k) * 12 + 6 * i + k] += m;
                }
            }
        }
    }

    /// Kinetic energy, eq. I7:
    /// `½ Σᵢⱼ Mᵢⱼ ẋᵢ·ẋⱼ + ½ Σᵢ Ωᵢ·Jᵢ Ωᵢ`.
    pub fn kinetic_energy(&self, n: &[NodeMotion; 2]) -> f64 {
        let mut t = 0.0;
        for i in 0..2 {
            t += self.rotary[i].kinetic_energy(&n[i]);
            for j in 0..2 {
                t += 0.5 * self.translational(i, j) * n[i].velocity.dot(&n[j].velocity);
            }
        }
        t
    }

    /// Linear momentum `Σᵢⱼ Mᵢⱼ ẋⱼ` and angular momentum about the global
    /// origin `∫ ρA x₀ × ẋ₀ ds + Σᵢ Rᵢ Jᵢ Ωᵢ = Σᵢⱼ Mᵢⱼ xᵢ × ẋⱼ + Σᵢ Rᵢ Jᵢ Ωᵢ`
    /// (exact for the linear interpolation of positions), I6–I7.
    pub fn momenta(&self, n: &[NodeMotion; 2]) -> Momenta {
        let mut linear = Vec3::zeros();
        let mut angular = Vec3::zeros();
        for i in 0..2 {
            angular += self.rotary[i].momenta(&n[i]).angular;
            for j in 0..2 {
                let p = n[j].velocity * self.translational(i, j);
                linear += p;
                angular += n[i].position.cross(&p);
            }
        }
        Momenta { linear, angular }
    }
}

/// Rayleigh damping matrix `C_R = α M + β K_mat` (eq. I10) from a mass
/// matrix and a *material* stiffness `K_mat = L₀ Bᵀ C B` (docs/theory.md
/// B7), to be applied as the damping force `C_R v`.
///
/// `K_mat` must be the material part only: it annihilates rigid-body
/// velocities (`B v` is the rate of the objective strains), whereas the full
/// tangent of a stressed element does not (a rigidly spinning prestressed
/// beam would be damped). The mass part `α M` damps rigid-body motion
/// itself, the deployment included; docs/theory.md §11.5 states how the
/// force and its tangents are assembled.
pub fn rayleigh_damping<const N: usize>(
    alpha: f64,
    beta: f64,
    mass: &SMatrix<f64, N, N>,
    material_stiffness: &SMatrix<f64, N, N>,
) -> SMatrix<f64, N, N> {
    mass * alpha + material_stiffness * beta
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::beam::{Beam, InitialStrain, SectionStiffness};
    use crate::elements::testing::eval;
    use crate::elements::EvalContext;
    use crate::state::State;
    use proptest::prelude::*;
    use proptest::test_runner::RngSeed;

    /// 64 cases from a fixed seed: the same states on every run.
    fn config(seed: u64) -> ProptestConfig {
        ProptestConfig {
            cases: 64,
            rng_seed: RngSeed::Fixed(seed),
            ..ProptestConfig::default()
        }
    }

    fn vec3(max: f64) -> impl Strategy<Value = Vec3> {
        (-max..max, -max..max, -max..max).prop_map(|(a, b, c)| Vec3::new(a, b, c))
    }

    /// A vector of norm in `[lo, hi]` with a random direction.
    fn with_norm(lo: f64, hi: f64) -> impl Strategy<Value = Vec3> {
        (vec3(1.0), lo..hi).prop_filter_map("zero direction", |(a, t)| {
            let n = a.norm();
            (n > 1e-3).then(|| a * (t / n))
        })
    }

    /// A rotation by up to 3 rad about a random axis.
    fn rotation() -> impl Strategy<Value = Rotation> {
        with_norm(0.0, 3.0).prop_map(|psi| so3::exp(&psi))
    }

    /// Random motion: rotation up to 3 rad, spin |Ω| from 20 to 50 rad/s,
    /// angular acceleration up to ~900 rad/s², accelerations up to ~170 m/s².
    fn motion() -> impl Strategy<Value = NodeMotion> {
        (
            vec3(2.0),
            rotation(),
            vec3(10.0),
            with_norm(20.0, 50.0),
            vec3(100.0),
            vec3(500.0),
        )
            .prop_map(|(x, r, v, w, a, w_dot)| NodeMotion {
                position: x,
                rotation: r,
                velocity: v,
                angular_velocity: w,
                acceleration: a,
                angular_acceleration: w_dot,
            })
    }

    /// The motion of [`motion`] spun up: |Ω| from 100 to 300 rad/s (the
    /// heavy top of Arnold & Brüls turns at 150 rad/s), angular
    /// acceleration up to ~9000 rad/s².
    fn fast_motion() -> impl Strategy<Value = NodeMotion> {
        (motion(), with_norm(100.0, 300.0), vec3(5000.0)).prop_map(|(n, w, w_dot)| NodeMotion {
            angular_velocity: w,
            angular_acceleration: w_dot,
            ..n
        })
    }

    /// A rigid body with mass in [0.1, 10], offset up to 1 and an inertia
    /// tensor with principal values in [0.05, 2] along random axes.
    fn body() -> impl Strategy<Value = RigidBodyInertia> {
        (0.1..10.0f64, vec3(1.0), vec3(1.0), rotation()).prop_map(|(m, c, p, axes)| {
            let principal = Vec3::new(0.05, 0.05, 0.05) + p.abs() * 1.95;
            let a = so3::matrix(&axes);
            let j = a * Mat3::from_diagonal(&principal) * a.transpose();
            RigidBodyInertia::new(m, j, c)
        })
    }

    /// A beam section with ρA in [0.5, 5] and sectional inertias in
    /// [0.01, 0.2] per length.
    fn section() -> impl Strategy<Value = BeamSection> {
        (0.5..5.0f64, vec3(1.0)).prop_map(|(rho_a, i)| BeamSection {
            stiffness: SectionStiffness::identity(),
            mass_per_length: rho_a,
            inertia_per_length: Vec3::new(0.01, 0.01, 0.01) + i.abs() * 0.19,
            damping: Default::default(),
        })
    }

    #[derive(Clone, Copy, Debug)]
    enum Var {
        /// Configuration, along `x ← x + h`, `R ← R exp(h e~)`.
        Q,
        /// Velocity `(ẋ, Ω)`.
        V,
        /// Acceleration `(ẍ, Ω̇)`.
        A,
    }

    /// Moves local unknown `k` of variable `var` by `h`, configurations
    /// along the update rule of [`State::displace_node`].
    fn moved<const K: usize>(n: &[NodeMotion; K], var: Var, k: usize, h: f64) -> [NodeMotion; K] {
        let mut p = *n;
        let node = &mut p[k / 6];
        let c = k % 6;
        let mut e = Vec3::zeros();
        e[c % 3] = h;
        match (var, c < 3) {
            (Var::Q, translation) => {
                let mut s = State::at_rest(0.0, vec![node.position], vec![node.rotation]);
                let (dx, dth) = if translation {
                    (e, Vec3::zeros())
                } else {
                    (Vec3::zeros(), e)
                };
                s.displace_node(0, &dx, &dth);
                (node.position, node.rotation) = (s.x[0], s.q[0]);
            }
            (Var::V, true) => node.velocity += e,
            (Var::V, false) => node.angular_velocity += e,
            (Var::A, true) => node.acceleration += e,
            (Var::A, false) => node.angular_acceleration += e,
        }
        p
    }

    /// Largest difference between `analytic` and central finite differences
    /// of `residual` in `var`, relative to the largest entry of either (a
    /// zero analytic block passes only if the differences vanish too).
    fn fd_error<const N: usize, const K: usize>(
        residual: impl Fn(&[NodeMotion; K]) -> SVector<f64, N>,
        n: &[NodeMotion; K],
        var: Var,
        analytic: &SMatrix<f64, N, N>,
        h: f64,
    ) -> f64 {
        assert_eq!(N, 6 * K);
        let mut fd = SMatrix::<f64, N, N>::zeros();
        for k in 0..N {
            let d = (residual(&moved(n, var, k, h)) - residual(&moved(n, var, k, -h))) / (2.0 * h);
            fd.set_column(k, &d);
        }
        let scale = analytic.amax().max(fd.amax());
        if scale == 0.0 {
            0.0
        } else {
            (fd - analytic).amax() / scale
        }
    }

    // Step sizes of the finite differences. The residual is linear in a
    // and quadratic in v, so central differences are exact there up to
    // round-off and a large step keeps the round-off small; in q the
    // truncation error is O(h²) ≈ 1e-12 relative with h = 1e-6 rad/m.
    const H_Q: f64 = 1e-6;
    const H_V: f64 = 1e-3;
    const H_A: f64 = 1e-3;

    /// The motion at time `t` along a curve through `n` with its velocities
    /// and accelerations at `t = 0`: `x(t) = x + t ẋ + ½t² ẍ`,
    /// `R(t) = R exp(ψ(t)~)`, `ψ(t) = t Ω + ½t² Ω̇`, so `ẋ(t) = ẋ + t ẍ`
    /// and `Ω(t) = T(ψ) ψ̇` (paper eq. 5), whose derivative at 0 is `Ω̇`.
    fn along(n: &NodeMotion, t: f64) -> NodeMotion {
        let psi = n.angular_velocity * t + n.angular_acceleration * (0.5 * t * t);
        let psi_dot = n.angular_velocity + n.angular_acceleration * t;
        NodeMotion {
            position: n.position + n.velocity * t + n.acceleration * (0.5 * t * t),
            rotation: n.rotation * so3::exp(&psi),
            velocity: n.velocity + n.acceleration * t,
            angular_velocity: so3::tangent(&psi) * psi_dot,
            ..*n
        }
    }

    /// Time derivative at 0 of `f(along(n, t))`, by the five-point stencil
    /// (error O(h⁴): ~1e-11 relative with h|Ω| ≤ 5e-3).
    fn rate<const D: usize, const K: usize>(
        n: &[NodeMotion; K],
        f: impl Fn(&[NodeMotion; K]) -> SVector<f64, D>,
    ) -> SVector<f64, D> {
        let h = 1e-4;
        let at = |t: f64| f(&n.map(|m| along(&m, t)));
        (at(-2.0 * h) - at(2.0 * h) + (at(h) - at(-h)) * 8.0) / (12.0 * h)
    }

    /// Power of the inertia forces `Σ r_x·ẋ + r_Θ·Ω` and the sum of the
    /// magnitudes of its terms.
    fn power<const K: usize>(r: &[f64], n: &[NodeMotion; K]) -> (f64, f64) {
        let (mut p, mut scale) = (0.0, 0.0);
        for (i, m) in n.iter().enumerate() {
            for c in 0..3 {
                let terms = [
                    r[6 * i + c] * m.velocity[c],
                    r[6 * i + 3 + c] * m.angular_velocity[c],
                ];
                p += terms[0] + terms[1];
                scale += terms[0].abs() + terms[1].abs();
            }
        }
        (p, scale)
    }

    /// Resultant force `Σ r_x` and moment about the origin
    /// `Σ xᵢ × r_xᵢ + Rᵢ r_Θᵢ` of the inertia forces (global).
    fn resultants<const K: usize>(r: &[f64], n: &[NodeMotion; K]) -> (Vec3, Vec3) {
        let (mut f, mut m) = (Vec3::zeros(), Vec3::zeros());
        for (i, node) in n.iter().enumerate() {
            let rx = Vec3::from_column_slice(&r[6 * i..6 * i + 3]);
            let rt = Vec3::from_column_slice(&r[6 * i + 3..6 * i + 6]);
            f += rx;
            m += node.position.cross(&rx) + node.rotation * rt;
        }
        (f, m)
    }

    /// Checks the power and momentum identities (I9) of a kernel at one
    /// motion: `r·v = dT/dt`, `Σ r_x = dp/dt`, `Σ (x × r_x + R r_Θ) = dH_O/dt`.
    fn check_balance<const K: usize>(
        n: &[NodeMotion; K],
        residual: &[f64],
        energy: impl Fn(&[NodeMotion; K]) -> f64,
        momenta: impl Fn(&[NodeMotion; K]) -> Momenta,
    ) -> Result<(), TestCaseError> {
        // energy: the inertia forces are d/dt ∂T/∂v − ∂T/∂q with T
        // quadratic in v, hence their power is dT/dt (Lagrange); tolerance
        // 1e-8 of the sum of the magnitudes of the power terms (the stencil
        // error is ~1e-11)
        let (p, scale) = power(residual, n);
        let dt = rate(n, |m| SVector::<f64, 1>::new(energy(m)))[0];
        prop_assert!(
            (p - dt).abs() <= 1e-8 * scale,
            "power {p} vs dT/dt {dt} (scale {scale})"
        );
        // momenta: the virtual work of the inertia forces on a rigid
        // virtual translation/rotation is the rate of linear/angular
        // momentum (Newton–Euler); same tolerance relative to the
        // largest resultant
        let (f, m) = resultants(residual, n);
        let dp = rate(n, |s| momenta(s).linear);
        let dh = rate(n, |s| momenta(s).angular);
        let scale = f.norm().max(m.norm()).max(1.0);
        prop_assert!((f - dp).norm() <= 1e-8 * scale, "force {f} vs dp/dt {dp}");
        prop_assert!((m - dh).norm() <= 1e-8 * scale, "moment {m} vs dH/dt {dh}");
        Ok(())
    }

    proptest! {
        #![proptest_config(config(0x1e27))]

        /// Acceptance: M, C and K of the rigid body (I3–I5) equal central
        /// finite differences of its residual (I2) in a, v and q, relative
        /// error ≤ 1e-6, on random states with rotations up to 3 rad and
        /// spins up to 50 rad/s.
        #[test]
        fn rigid_body_tangents_match_finite_differences(b in body(), n in motion()) {
            let f = b.evaluate(&n);
            let res = |s: &[NodeMotion; 1]| b.residual(&s[0]);
            // the residual returned with the blocks is the residual
            prop_assert_eq!(f.residual, b.residual(&n));
            let n = [n];
            let em = fd_error(res, &n, Var::A, &f.mass, H_A);
            let ec = fd_error(res, &n, Var::V, &f.gyroscopic, H_V);
            let ek = fd_error(res, &n, Var::Q, &f.stiffness, H_Q);
            prop_assert!(em <= 1e-6, "M: {em:e}");
            prop_assert!(ec <= 1e-6, "C: {ec:e}");
            prop_assert!(ek <= 1e-6, "K: {ek:e}");
            // the mass matrix is symmetric
            prop_assert!((f.mass - f.mass.transpose()).amax() <= 1e-14 * f.mass.amax());
        }

        /// Acceptance: the same for the beam (I8), with arbitrary offsets Qᵢ
        /// from node to section frames.
        #[test]
        fn beam_tangents_match_finite_differences(
            s in section(), l in 0.1..3.0f64, q1 in rotation(), q2 in rotation(),
            n1 in motion(), n2 in motion(),
        ) {
            let beam = BeamInertia::new(l, &s, [q1, q2]);
            let n = [n1, n2];
            let f = beam.evaluate(&n);
            prop_assert_eq!(f.residual, beam.residual(&n));
            let res = |m: &[NodeMotion; 2]| beam.residual(m);
            let em = fd_error(res, &n, Var::A, &f.mass, H_A);
            let ec = fd_error(res, &n, Var::V, &f.gyroscopic, H_V);
            // K is zero: the differences must vanish exactly
            let ek = fd_error(res, &n, Var::Q, &f.stiffness, H_Q);
            prop_assert!(em <= 1e-6, "M: {em:e}");
            prop_assert!(ec <= 1e-6, "C: {ec:e}");
            prop_assert!(ek <= 1e-6, "K: {ek:e}");
            prop_assert!((f.mass - f.mass.transpose()).amax() <= 1e-14 * f.mass.amax());
        }

        /// Acceptance at high spin: the tangents of the rigid body (offset
        /// centre of mass) and of the beam against central differences as
        /// above, relative error ≤ 1e-6, with |Ω| from 100 to 300 rad/s,
        /// where the gyroscopic and centrifugal blocks dominate the mass.
        #[test]
        fn tangents_match_finite_differences_at_high_spin(
            b in body(), s in section(), l in 0.1..3.0f64, q1 in rotation(), q2 in rotation(),
            n1 in fast_motion(), n2 in fast_motion(),
        ) {
            let f = b.evaluate(&n1);
            let res = |m: &[NodeMotion; 1]| b.residual(&m[0]);
            let n = [n1];
            let em = fd_error(res, &n, Var::A, &f.mass, H_A);
            let ec = fd_error(res, &n, Var::V, &f.gyroscopic, H_V);
            let ek = fd_error(res, &n, Var::Q, &f.stiffness, H_Q);
            prop_assert!(em <= 1e-6 && ec <= 1e-6 && ek <= 1e-6, "body: M {em:e}, C {ec:e}, K {ek:e}");
            let beam = BeamInertia::new(l, &s, [q1, q2]);
            let n = [n1, n2];
            let f = beam.evaluate(&n);
            let res = |m: &[NodeMotion; 2]| beam.residual(m);
            let em = fd_error(res, &n, Var::A, &f.mass, H_A);
            let ec = fd_error(res, &n, Var::V, &f.gyroscopic, H_V);
            let ek = fd_error(res, &n, Var::Q, &f.stiffness, H_Q);
            prop_assert!(em <= 1e-6 && ec <= 1e-6 && ek <= 1e-6, "beam: M {em:e}, C {ec:e}, K {ek:e}");
        }

        /// Energy and momentum balance of the rigid body (I9): an
        /// independent check of the residual against the kinetic energy
        /// (I1) and momenta (I6).
        #[test]
        fn rigid_body_forces_balance_energy_and_momenta(b in body(), n in motion()) {
            let n = [n];
            check_balance(
                &n,
                b.residual(&n[0]).as_slice(),
                |s| b.kinetic_energy(&s[0]),
                |s| b.momenta(&s[0]),
            )?;
        }

        /// The same for the beam (I7–I8).
        #[test]
        fn beam_forces_balance_energy_and_momenta(
            s in section(), l in 0.1..3.0f64, q1 in rotation(), q2 in rotation(),
            n1 in motion(), n2 in motion(),
        ) {
            let beam = BeamInertia::new(l, &s, [q1, q2]);
            let n = [n1, n2];
            check_balance(
                &n,
                beam.residual(&n).as_slice(),
                |m| beam.kinetic_energy(m),
                |m| beam.momenta(m),
            )?;
        }

        /// A body with its centre of mass at the offset c equals a body
        /// with c = 0 and the same J on a second node at x + R c with the
        /// same orientation, rigidly linked: the second node's motion is
        /// ẋ_B = ẋ + R(Ω × c), ẍ_B = ẍ + R(Ω̇ × c + Ω × (Ω × c)), Ω_B = Ω,
        /// and the link carries its forces back by virtual work
        /// (δx_B = δx − R c~ δΘ): r_x = r_Bx, r_Θ = r_BΘ + c~ Rᵀ r_Bx.
        /// Residual, energy and momenta agree to round-off (1e-12 relative).
        #[test]
        fn offset_body_equals_a_body_at_its_centre_of_mass(b in body(), n in motion()) {
            let centred = RigidBodyInertia::new(b.mass(), *b.inertia(), Vec3::zeros());
            let (r, c) = (so3::matrix(&n.rotation), b.offset());
            let w = &n.angular_velocity;
            let at_centre = NodeMotion {
                position: n.position + r * c,
                velocity: n.velocity + r * w.cross(c),
                acceleration: n.acceleration
                    + r * (n.angular_acceleration.cross(c) + w.cross(&w.cross(c))),
                ..n
            };
            let rb = centred.residual(&at_centre);
            let rbx: Vec3 = rb.fixed_rows::<3>(0).into();
            let rbt: Vec3 = rb.fixed_rows::<3>(3).into();
            let mut expected = Vec6::zeros();
            expected.fixed_rows_mut::<3>(0).copy_from(&rbx);
            expected.fixed_rows_mut::<3>(3).copy_from(&(rbt + c.cross(&(r.transpose() * rbx))));
            let got = b.residual(&n);
            prop_assert!((got - expected).amax() <= 1e-12 * got.amax(), "{got} vs {expected}");
            let (t, tb) = (b.kinetic_energy(&n), centred.kinetic_energy(&at_centre));
            prop_assert!((t - tb).abs() <= 1e-12 * t);
            let (p, pb) = (b.momenta(&n), centred.momenta(&at_centre));
            prop_assert!((p.linear - pb.linear).norm() <= 1e-12 * p.linear.norm());
            // relative to the size of its two terms, (x + R c) × p and R J Ω
            let scale = at_centre.position.norm() * p.linear.norm() + (b.inertia() * w).norm();
            prop_assert!((p.angular - pb.angular).norm() <= 1e-12 * scale);
        }

        /// Acceptance: the kinetic energy and momenta of a beam moving as a
        /// rigid body (velocity v_P at an arbitrary point P, angular
        /// velocity ω) equal those of the rigid rod, ½ m |v_G|² + ½ ω·I_G ω
        /// with I_G = ρA L³/12 (I − e eᵀ) + L Λ diag(ρJ, ρI₂, ρI₃) Λᵀ, to
        /// round-off (1e-12 relative). Nodes carry arbitrary orientations
        /// (the section frame is Rᵢ Qᵢ).
        #[test]
        fn rigid_motion_of_a_beam_has_the_kinetic_energy_of_the_rod(
            s in section(), x1 in vec3(2.0), axis in with_norm(0.1, 3.0),
            r1 in rotation(), r2 in rotation(), body_rotation in rotation(),
            shift in vec3(2.0), p in vec3(3.0), v_p in vec3(10.0), omega in with_norm(0.0, 50.0),
        ) {
            // reference: section frame F from the axis and a reference vector
            let x0 = [x1, x1 + axis];
            let f = so3::frame_from_axis_and_vector(&axis, &Vec3::new(0.3, 1.0, -0.2));
            prop_assume!(f.is_some());
            let f = so3::from_matrix(&f.unwrap());
            let r0 = [r1, r2];
            let l = axis.norm();
            let beam = BeamInertia::new(l, &s, [r0[0].inverse() * f, r0[1].inverse() * f]);
            // rigid motion: x = Rb X + shift, R = Rb R₀
            let rb = body_rotation;
            let n: [NodeMotion; 2] = std::array::from_fn(|i| {
                let x = rb * x0[i] + shift;
                let rot = rb * r0[i];
                NodeMotion {
                    velocity: v_p + omega.cross(&(x - p)),
                    angular_velocity: rot.inverse() * omega,
                    ..NodeMotion::at_rest(x, rot)
                }
            });
            // the rigid rod
            let m = s.mass_per_length * l;
            let xg = (n[0].position + n[1].position) * 0.5;
            let vg = v_p + omega.cross(&(xg - p));
            let lam = so3::matrix(&(rb * f));
            let e = lam.column(0).into_owned();
            let ig = (Mat3::identity() - e * e.transpose()) * (m * l * l / 12.0)
                + lam * Mat3::from_diagonal(&s.inertia_per_length) * lam.transpose() * l;
            let t_rod = 0.5 * m * vg.norm_squared() + 0.5 * omega.dot(&(ig * omega));
            let t = beam.kinetic_energy(&n);
            prop_assert!((t - t_rod).abs() <= 1e-12 * t_rod.max(1e-300), "{t} vs {t_rod}");
            let mom = beam.momenta(&n);
            let h_rod = xg.cross(&(vg * m)) + ig * omega;
            prop_assert!((mom.linear - vg * m).norm() <= 1e-12 * (m * vg.norm()).max(1e-300));
            let scale = h_rod.norm().max(xg.norm() * m * vg.norm()).max(1e-300);
            prop_assert!((mom.angular - h_rod).norm() <= 1e-12 * scale);
        }
    }

    #[test]
    fn beam_spinning_about_its_centre() {
        // rod of length L = 2 along x, ρA = 3, spinning at ω = 5 rad/s about
        // z through its centre: T = m ω² L²/24 + ½ L ρI₃ ω² exactly
        // (a lumped translational mass would give m ω² L²/8, three times
        // the translational part)
        let s = BeamSection {
            stiffness: SectionStiffness::identity(),
            mass_per_length: 3.0,
            inertia_per_length: Vec3::new(0.2, 0.1, 0.05),
            damping: Default::default(),
        };
        let (l, w) = (2.0, 5.0);
        let beam = BeamInertia::new(l, &s, [Rotation::identity(); 2]);
        let omega = Vec3::new(0.0, 0.0, w);
        let n = [-1.0, 1.0].map(|x| NodeMotion {
            velocity: omega.cross(&Vec3::new(x, 0.0, 0.0)),
            angular_velocity: omega,
            ..NodeMotion::at_rest(Vec3::new(x, 0.0, 0.0), Rotation::identity())
        });
        let m = 3.0 * l;
        let expected = m * w * w * l * l / 24.0 + 0.5 * l * 0.05 * w * w;
        // exact arithmetic on small numbers: 1e-14 relative
        approx::assert_relative_eq!(beam.kinetic_energy(&n), expected, max_relative = 1e-14);
        // steady spin about a principal axis of the section with a = 0: no
        // inertia force at all (Ω × J Ω = 0), exactly
        assert_eq!(beam.residual(&n), Vec12::zeros());
        // with the centripetal accelerations ẍᵢ = ω × (ω × xᵢ), so that
        // ẍ₂ = −ẍ₁, the consistent mass gives r_x₁ = (m/3 − m/6) ẍ₁
        let n_acc = n.map(|mut s| {
            s.acceleration = omega.cross(&omega.cross(&s.position));
            s
        });
        let r_acc = beam.residual(&n_acc);
        let a1 = n_acc[0].acceleration;
        approx::assert_relative_eq!(
            Vec3::from_column_slice(&r_acc.as_slice()[0..3]),
            a1 * (m / 6.0),
            max_relative = 1e-14
        );
    }

    #[test]
    fn point_mass_has_only_m_xddot() {
        // c = 0, J = 0: r = (m ẍ, 0), M = diag(m I, 0), C = K = 0, for any
        // rotation and spin (exact: no arithmetic on the zero terms)
        let b = RigidBodyInertia::point_mass(2.5);
        let n = NodeMotion {
            position: Vec3::new(1.0, 2.0, 3.0),
            rotation: so3::exp(&Vec3::new(0.3, -2.0, 1.0)),
            velocity: Vec3::new(1.0, -1.0, 2.0),
            angular_velocity: Vec3::new(30.0, 20.0, -10.0),
            acceleration: Vec3::new(-3.0, 4.0, 9.0),
            angular_acceleration: Vec3::new(100.0, 0.0, 5.0),
        };
        let f = b.evaluate(&n);
        let mut r = Vec6::zeros();
        r.fixed_rows_mut::<3>(0).copy_from(&(n.acceleration * 2.5));
        assert_eq!(f.residual, r);
        let mut m = SMatrix::<f64, 6, 6>::zeros();
        m.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Mat3::identity() * 2.5));
        assert_eq!(f.mass, m);
        assert_eq!(f.gyroscopic, SMatrix::<f64, 6, 6>::zeros());
        assert_eq!(f.stiffness, SMatrix::<f64, 6, 6>::zeros());
        // T = ½ m |ẋ|², p = m ẋ, H = x × m ẋ
        assert_eq!(b.kinetic_energy(&n), 0.5 * 2.5 * 6.0);
        assert_eq!(b.momenta(&n).angular, n.position.cross(&(n.velocity * 2.5)));
    }

    #[test]
    fn material_stiffness_damping_spares_rigid_motion() {
        // C_R = α M + β K_mat (I10). K_mat annihilates rigid-body
        // velocities; the full tangent of a prestressed beam does not: a
        // rigid rotation ω turns its nodal forces, K v = (ω × f_x, 0).
        let x = [Vec3::new(0.1, 0.2, 0.0), Vec3::new(1.1, 0.5, 0.3)];
        let r = [
            so3::exp(&Vec3::new(0.4, -0.2, 1.0)),
            so3::exp(&Vec3::new(-1.0, 0.3, 0.2)),
        ];
        let section = BeamSection {
            stiffness: SectionStiffness::from_diagonal(&SVector::<f64, 6>::new(
                1e4, 5e3, 5e3, 50.0, 80.0, 90.0,
            )),
            mass_per_length: 2.0,
            inertia_per_length: Vec3::new(0.02, 0.01, 0.01),
            damping: Default::default(),
        };
        let ctx = EvalContext {
            time: 1.0,
            curves: &[],
            gravity: Vec3::zeros(),
            need: crate::elements::Need::STIFFNESS,
            dynamics: false,
            scaling: Default::default(),
        };
        let state = State::at_rest(0.0, x.to_vec(), r.to_vec());
        let omega = Vec3::new(0.3, -1.2, 0.7);
        let mut v = SVector::<f64, 12>::zeros();
        for i in 0..2 {
            v.fixed_rows_mut::<3>(6 * i).copy_from(&omega.cross(&x[i]));
            v.fixed_rows_mut::<3>(6 * i + 3)
                .copy_from(&(r[i].inverse() * omega));
        }
        let tangent = |initial: [f64; 6]| {
            let strain = InitialStrain {
                strain: initial,
                curve: None,
            };
            let beam = Beam::new(1, [0, 1], x, r, Vec3::z(), section.clone(), strain).unwrap();
            let (f, k) = eval(&beam, &ctx, &state);
            (
                SVector::<f64, 12>::from_column_slice(&f),
                SMatrix::<f64, 12, 12>::from_column_slice(&k),
            )
        };

        // stress-free reference: K = K_mat (no stress, no geometric
        // stiffness), and K_mat v = 0 (1e-12 of the |K| |v| scale)
        let (_, k_mat) = tangent([0.0; 6]);
        let scale = k_mat.amax() * v.amax();
        assert!((k_mat * v).amax() <= 1e-12 * scale, "{}", k_mat * v);
        let beam = BeamInertia::new((x[1] - x[0]).norm(), &section, [Rotation::identity(); 2]);
        let m = beam.evaluate(&[
            NodeMotion::at_rest(x[0], r[0]),
            NodeMotion::at_rest(x[1], r[1]),
        ]);
        let c = rayleigh_damping(0.0, 0.01, &m.mass, &k_mat);
        assert!((c * v).amax() <= 1e-12 * scale * 0.01);
        // whereas the mass part damps the rigid motion: α M v ≠ 0
        let c = rayleigh_damping(0.5, 0.01, &m.mass, &k_mat);
        assert!(((c * v) - m.mass * v * 0.5).amax() <= 1e-12 * scale * 0.01);
        assert!((m.mass * v).amax() > 0.1);

        // prestressed by 1 % shortening (N = 100): the full tangent gives
        // K v = (ω × f_x, 0) to the accuracy of the tangent (1e-9 of the
        // |K| |v| scale), which is not zero
        let (f, k) = tangent([-0.01, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let kv = k * v;
        for i in 0..2 {
            let fx: Vec3 = f.fixed_rows::<3>(6 * i).into();
            let kvx: Vec3 = kv.fixed_rows::<3>(6 * i).into();
            let kvt: Vec3 = kv.fixed_rows::<3>(6 * i + 3).into();
            assert!((kvx - omega.cross(&fx)).norm() <= 1e-9 * k.amax() * v.amax());
            assert!(kvt.norm() <= 1e-9 * k.amax() * v.amax());
            assert!(omega.cross(&fx).norm() > 10.0);
        }
    }
}
