//! A flat four-node shell element of laminated sections: MITC4 plate
//! bending (Bathe & Dvorkin, *A four-node plate bending element based on
//! Mindlin/Reissner plate theory and a mixed interpolation*, IJNME 21,
//! 1985), a bilinear membrane with the Hughes–Brezzi drilling rotation
//! (Hughes & Brezzi, *On drilling degrees of freedom*, CMAME 72, 1989),
//! full `A`, `B`, `D`, `H` section matrices from [`super::laminate`], and
//! a consistent mass with rotary inertia (docs/theory.md §17).
//!
//! **Linear.** The element is linear in the displacements and rotations
//! measured from its reference configuration: a shell model is meant for
//! linear static and modal checks of a panel, and for its reduction to a
//! superelement (whose floating frame carries the large motion). A node's
//! displacement is `u = x − X`, its rotation the vector
//! `ψ = log(R₀ᵀ R)` (components in the node's reference frame `R₀`), and
//! with `d = (u, ψ)` of the four nodes the residual is
//! `r = K d − f_g` (`f_g` the weight; docs/theory.md S7). The unknowns of
//! a node are the increments `(Δx, ΔΘ)` with `R ← R exp(ΔΘ~)`
//! (docs/theory.md §2), along which `δψ = T⁻¹(ψ) δΘ`, so the tangent is
//!
//! ```text
//! ∂r/∂q = K D,   D = diag(I, T⁻¹(ψ)) for each node        (S8)
//! ```
//!
//! which at the reference configuration (`ψ = 0`) is exactly `K`: the
//! stiffness a reduction takes, and a static analysis from there converges
//! in one Newton iteration. `r` is the gradient of the energy
//! `½ dᵀ K d − f_gᵀ d` in `d`; along the material update the two differ
//! by `T⁻ᵀ(ψ) − I = O(ψ)`. A converged state in which a node of a shell
//! has turned by more than [`ROTATION_LIMIT`] from its reference stops
//! the analysis ([`super::Element::law_violated`]): a linear shell
//! carried through a large rotation would strain spuriously (`1 − cos ψ`).
//!
//! Frames: the element's axes `(x, y, n)` ([`Shell::axes`]) have `n`
//! normal to the mean plane (right-handed about the node order), `x` the
//! material axis projected on the plane (the laminate's `x`: ply angles
//! are measured from it; by default global x, or global y for an element
//! whose normal is along x), `y = n × x`. Stress resultants and layer
//! stresses are given in these axes.

mod mitc4;
mod stress;

use std::sync::Arc;

use nalgebra::{Matrix4, SMatrix, SVector};

use super::inertia::Momenta;
use super::laminate::Laminate;
use super::{CellShape, Element, ElementKind, ElementOutput, EvalContext};
use crate::model::Id;
use crate::so3::{self, Mat3, Operator, Rotation, SkewSeries, Vec3};
use crate::state::State;
use mitc4::{Geometry, Mat24, Vec24};

pub use stress::{NodalDisplacements, ShellResultants, ShellStrains, SkinStress, StressPoint};

/// The drilling penalty `γ_d` of the Hughes–Brezzi term
/// `½ γ_d ∫ (θz − ω)² dA` relative to the laminate's in-plane shear
/// stiffness `A₆₆` (docs/theory.md §17.1, S4). Small, so that the
/// membrane is that of the bilinear element (a cantilever loaded in its
/// plane changes by less than 1e-3 between 1e-3 and 1e-5, measured in the
/// tests), large enough that the drilling rotation is not a mechanism.
/// The penalty vanishes for every linear displacement field with
/// `θz = ω`, so the patch tests stay exact.
pub const DRILLING_PENALTY: f64 = 1e-3;

/// The largest rotation of a node of a shell from its reference
/// orientation (radians) before an analysis stops: at 0.05 rad a rigid
/// rotation would give the linear element a spurious strain of
/// `1 − cos ψ ≈ 1.25e-3`, the order of the strains a panel is designed
/// for.
pub const ROTATION_LIMIT: f64 = 0.05;

/// The largest distance of a corner from the element's mean plane,
/// relative to its longer diagonal: beyond it the flat element is refused.
pub const WARP_LIMIT: f64 = 1e-2;

/// Why four nodes do not make a shell element.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ShellGeometryError {
    /// The diagonals are parallel or of zero length: no area, or sides
    /// that cross symmetrically.
    #[error("has zero area (its diagonals are parallel or nodes coincide; a quadrilateral whose sides cross has no area either): the four nodes must run around a convex quadrilateral")]
    ZeroArea,
    /// A corner where the boundary does not turn the same way as at the
    /// others: a self-intersecting (bow-tie), re-entrant or degenerate
    /// quadrilateral.
    #[error("is not a convex quadrilateral at its corner {corner} (node {node}): its sides there turn the wrong way, are aligned or have zero length, as in a self-intersecting (sides crossing) or re-entrant quadrilateral; list the four nodes in order around a convex quadrilateral")]
    NotConvex {
        /// The corner, from 1 in the element's order.
        corner: usize,
        /// Its node id.
        node: Id,
    },
    /// The corners are too far from a plane for a flat element.
    #[error("is warped: its corners lie up to {warp:.3e} of its diagonal from their mean plane, more than the {limit:e} a flat element takes; divide the surface into flatter elements")]
    Warped {
        /// Largest distance from the mean plane over the longer diagonal.
        warp: f64,
        /// [`WARP_LIMIT`].
        limit: f64,
    },
    /// The material axis given is normal to the element.
    #[error("material_axis {axis:?} is normal to the element (its normal is {normal:?}): it must have a part in the element's plane")]
    AxisNormal {
        /// The axis given.
        axis: [f64; 3],
        /// The element's normal.
        normal: [f64; 3],
    },
    /// Positions or a material axis that are not finite.
    #[error("its node positions or its material axis are not finite")]
    NotFinite,
}

/// The four-node shell element (module documentation).
#[derive(Clone, Debug)]
pub struct Shell {
    id: Id,
    nodes: [usize; 4],
    node_ids: [Id; 4],
    /// Columns `x, y, n`: the element's axes in the global frame.
    axes: Mat3,
    reference_x: [Vec3; 4],
    reference_q: [Rotation; 4],
    /// `R₀` of each node as a matrix.
    reference_r: [Mat3; 4],
    geometry: Geometry,
    laminate: Arc<Laminate>,
    /// `K` on `d = (u, ψ)` of the nodes (S5).
    stiffness: Box<Mat24>,
    /// `∫ Nᵢ Nⱼ dA`.
    overlap: Matrix4<f64>,
    /// The weight `f_g = G g` per unit gravity acceleration (24 × 3).
    gravity_load: SMatrix<f64, 24, 3>,
    area: f64,
    /// Centre of mass of the reference configuration.
    mass_centre: Vec3,
}

impl Shell {
    /// A shell of `laminate` on `nodes` (indices) at reference positions
    /// `x` and orientations `q`, listed in order around the element (the
    /// normal follows them by the right-hand rule). `material_axis`: the
    /// direction whose projection on the element is its `x` axis, from
    /// which ply angles are measured (default global x, or global y for an
    /// element whose normal is along x).
    pub fn new(
        id: Id,
        nodes: [usize; 4],
        x: [Vec3; 4],
        q: [Rotation; 4],
        material_axis: Option<Vec3>,
        laminate: Arc<Laminate>,
    ) -> Result<Self, ShellGeometryError> {
        Self::with_node_ids(
            id,
            nodes,
            nodes.map(|n| n as Id),
            x,
            q,
            material_axis,
            laminate,
        )
    }

    /// [`Shell::new`] with the ids of the nodes, for messages.
    pub fn with_node_ids(
        id: Id,
        nodes: [usize; 4],
        node_ids: [Id; 4],
        x: [Vec3; 4],
        q: [Rotation; 4],
        material_axis: Option<Vec3>,
        laminate: Arc<Laminate>,
    ) -> Result<Self, ShellGeometryError> {
        let finite = |p: &Vec3| p.iter().all(|v| v.is_finite());
        if !x.iter().all(finite) || !material_axis.as_ref().is_none_or(finite) {
            return Err(ShellGeometryError::NotFinite);
        }
        // mean plane from the diagonals
        let centre = (x[0] + x[1] + x[2] + x[3]) / 4.0;
        let (d1, d2) = (x[2] - x[0], x[3] - x[1]);
        let scale = d1.norm().max(d2.norm());
        let cross = d1.cross(&d2);
        if cross.norm() <= 1e-12 * scale * scale {
            return Err(ShellGeometryError::ZeroArea);
        }
        let normal = cross.normalize();
        let warp = x
            .iter()
            .map(|p| (p - centre).dot(&normal).abs())
            .fold(0.0, f64::max)
            / scale;
        if warp > WARP_LIMIT {
            return Err(ShellGeometryError::Warped {
                warp,
                limit: WARP_LIMIT,
            });
        }
        // material axis on the plane
        let project = |a: &Vec3| a - normal * a.dot(&normal);
        let e1 = match material_axis {
            Some(a) => {
                let p = project(&a);
                if p.norm() <= 1e-3 * a.norm() {
                    return Err(ShellGeometryError::AxisNormal {
                        axis: [a.x, a.y, a.z],
                        normal: [normal.x, normal.y, normal.z],
                    });
                }
                p.normalize()
            }
            None => {
                let p = project(&Vec3::x());
                if p.norm() > 1e-3 {
                    p.normalize()
                } else {
                    project(&Vec3::y()).normalize()
                }
            }
        };
        let e2 = normal.cross(&e1);
        let axes = Mat3::from_columns(&[e1, e2, normal]);
        let geometry = Geometry {
            xy: x.map(|p| {
                let r = p - centre;
                [r.dot(&e1), r.dot(&e2)]
            }),
        };
        let det = geometry.corner_determinants();
        let area = geometry.area();
        for (k, d) in det.iter().enumerate() {
            if *d <= 1e-8 * area {
                return Err(ShellGeometryError::NotConvex {
                    corner: k + 1,
                    node: node_ids[k],
                });
            }
        }
        let reference_r = q.map(|r| so3::matrix(&r));
        let mut shell = Self {
            id,
            nodes,
            node_ids,
            axes,
            reference_x: x,
            reference_q: q,
            reference_r,
            geometry,
            laminate,
            stiffness: Box::new(Mat24::zeros()),
            overlap: Matrix4::zeros(),
            gravity_load: SMatrix::zeros(),
            area,
            mass_centre: centre,
        };
        shell.assemble_constants();
        Ok(shell)
    }

    /// Stiffness, area integrals, weight and centre of mass.
    fn assemble_constants(&mut self) {
        let lam = &self.laminate;
        let drilling = DRILLING_PENALTY * lam.a()[(2, 2)];
        let local = self.geometry.stiffness(lam, drilling);
        *self.stiffness = self.to_node_frames(&local);
        self.overlap = self.geometry.overlap();
        let m = self.mass_matrix();
        for c in 0..3 {
            for j in 0..4 {
                let col = m.column(6 * j + c);
                for r in 0..24 {
                    self.gravity_load[(r, c)] += col[r];
                }
            }
        }
        // Σ mᵢ Xᵢ with mᵢ = ρ₀ ∫ Nᵢ: the centroid of the area
        let shares: [f64; 4] = std::array::from_fn(|i| self.overlap.row(i).sum());
        let total: f64 = shares.iter().sum();
        self.mass_centre = (0..4)
            .map(|i| self.reference_x[i] * shares[i])
            .fold(Vec3::zeros(), |a, b| a + b)
            / total;
    }

    /// `Tᵢ`: node unknowns `(u, ψ)` (global, node reference frame) to the
    /// element's axes.
    fn transforms(&self) -> [[Mat3; 2]; 4] {
        let et = self.axes.transpose();
        std::array::from_fn(|i| [et, et * self.reference_r[i]])
    }

    /// `Tᵀ M T` for a matrix `M` in the element's axes.
    fn to_node_frames(&self, local: &Mat24) -> Mat24 {
        let t = self.transforms();
        let mut out = Mat24::zeros();
        for bi in 0..8 {
            for bj in 0..8 {
                let ti = &t[bi / 2][bi % 2];
                let tj = &t[bj / 2][bj % 2];
                let b = ti.transpose() * mitc4::block(local, 3 * bi, 3 * bj) * tj;
                out.fixed_view_mut::<3, 3>(3 * bi, 3 * bj).copy_from(&b);
            }
        }
        out
    }

    /// The consistent mass matrix on `d = (u, ψ)` of the nodes (S6):
    /// `Mᵢⱼ = Sᵢⱼ Tᵢᵀ m Tⱼ`, `m` the 6 × 6 density of
    /// [`mitc4::mass_density`].
    pub fn mass_matrix(&self) -> ShellMatrix {
        let m = mitc4::mass_density(&self.laminate);
        let t = self.transforms();
        let tn: [SMatrix<f64, 6, 6>; 4] = std::array::from_fn(|i| {
            let mut b = SMatrix::<f64, 6, 6>::zeros();
            b.fixed_view_mut::<3, 3>(0, 0).copy_from(&t[i][0]);
            b.fixed_view_mut::<3, 3>(3, 3).copy_from(&t[i][1]);
            b
        });
        let mut out = Mat24::zeros();
        for i in 0..4 {
            for j in 0..4 {
                let b = tn[i].transpose() * m * tn[j] * self.overlap[(i, j)];
                out.fixed_view_mut::<6, 6>(6 * i, 6 * j).copy_from(&b);
            }
        }
        out
    }

    /// The stiffness matrix on `d = (u, ψ)` of the nodes: the tangent at
    /// the reference configuration.
    pub fn stiffness_matrix(&self) -> &ShellMatrix {
        &self.stiffness
    }

    /// The element's axes: columns `x`, `y` (in its plane, `x` the
    /// material axis) and the normal `n`, global components.
    pub fn axes(&self) -> &Mat3 {
        &self.axes
    }

    /// The laminate.
    pub fn laminate(&self) -> &Laminate {
        &self.laminate
    }

    /// The area of the reference configuration.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// `∫ Nᵢ dA` of each node: the share of a uniform load per area that
    /// goes to it.
    pub fn nodal_areas(&self) -> [f64; 4] {
        std::array::from_fn(|i| self.overlap.row(i).sum())
    }

    /// The corners in the element's plane, relative to their centroid.
    pub fn corners(&self) -> [[f64; 2]; 4] {
        self.geometry.xy
    }

    /// `d = (u, ψ)` of the nodes at `state`, with `ψ = log(R₀ᵀR)`.
    fn unknowns(&self, state: &State) -> (Vec24, [Vec3; 4]) {
        let mut d = Vec24::zeros();
        let mut psi = [Vec3::zeros(); 4];
        for (i, &n) in self.nodes.iter().enumerate() {
            let u = state.x[n] - self.reference_x[i];
            let q = &state.q[n];
            psi[i] = if *q == self.reference_q[i] {
                Vec3::zeros()
            } else {
                so3::log(&(self.reference_q[i].inverse() * q))
            };
            d.fixed_rows_mut::<3>(6 * i).copy_from(&u);
            d.fixed_rows_mut::<3>(6 * i + 3).copy_from(&psi[i]);
        }
        (d, psi)
    }

    /// The rates `(ẋ, Ω)` or `(ẍ, Ω̇)` of the nodes.
    fn rates(&self, of: &[[f64; 6]]) -> Vec24 {
        let mut v = Vec24::zeros();
        for (i, &n) in self.nodes.iter().enumerate() {
            for c in 0..6 {
                v[6 * i + c] = of[n][c];
            }
        }
        v
    }
}

impl Element for Shell {
    fn kind(&self) -> ElementKind {
        ElementKind::Shell
    }

    fn id(&self) -> Id {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    /// A node turned beyond [`ROTATION_LIMIT`] from its reference
    /// orientation: the linear element no longer holds.
    fn law_violated(&self, _before: &State, after: &State) -> Option<String> {
        let (_, psi) = self.unknowns(after);
        let (k, angle) = psi
            .iter()
            .map(|p| p.norm())
            .enumerate()
            .fold((0, 0.0), |a, (k, v)| if v > a.1 { (k, v) } else { a });
        (angle > ROTATION_LIMIT).then(|| {
            format!(
                "its node {} turned by {angle:.4} rad ({:.2}°) from its reference orientation, beyond the {ROTATION_LIMIT} rad a shell element takes: shells are linear (small displacements and rotations from the reference configuration, docs/theory.md §17.5), for static and modal checks of a panel and its reduction to a superelement, not for large motions",
                self.node_ids[k],
                angle.to_degrees()
            )
        })
    }

    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let (d, psi) = self.unknowns(state);
        let k = &*self.stiffness;

        // residual r = K d − f_g (S7)
        let mut g = k * d;
        if ctx.gravity != Vec3::zeros() {
            g -= self.gravity_load * ctx.gravity;
        }
        for (o, v) in out.residual.iter_mut().zip(g.iter()) {
            *o += v;
        }

        // tangent (S8): K D, D = diag(I, T⁻¹(ψ)) the derivative of d
        // along the update
        if let Some(buf) = out.stiffness.as_deref_mut() {
            if psi.iter().any(|p| *p != Vec3::zeros()) {
                let mut kt = *k;
                for (i, p) in psi.iter().enumerate() {
                    if *p == Vec3::zeros() {
                        continue;
                    }
                    let tinv = SkewSeries::new(Operator::TangentInv, p).matrix();
                    for bi in 0..8 {
                        let b = mitc4::block(k, 3 * bi, 6 * i + 3) * tinv;
                        kt.fixed_view_mut::<3, 3>(3 * bi, 6 * i + 3).copy_from(&b);
                    }
                }
                add_matrix(buf, &kt);
            } else {
                add_matrix(buf, k);
            }
        }

        // inertia: constant consistent mass (S6); forces M a in dynamics
        let weights = ctx.need.inertia.filter(|_| out.inertia.is_some());
        if !(ctx.dynamics || weights.is_some()) || self.laminate.mass_per_area() == 0.0 {
            return;
        }
        let m = self.mass_matrix();
        if ctx.dynamics {
            let f = m * self.rates(&state.acceleration);
            for (o, v) in out.residual.iter_mut().zip(f.iter()) {
                *o += v;
            }
        }
        if let (Some(w), Some(buf)) = (weights, out.inertia.as_deref_mut()) {
            if w.mass != 0.0 {
                add_matrix(buf, &(m * w.mass));
            }
        }
    }

    fn result_names(&self) -> &'static [&'static str] {
        &[
            "Nxx",
            "Nyy",
            "Nxy",
            "Mxx",
            "Myy",
            "Mxy",
            "Qx",
            "Qy",
            "von_mises",
        ]
    }

    /// The stress resultants at the centre, element axes, and the largest
    /// von Mises stress of the layers' surfaces there.
    fn results(&self, _ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let d = self.displacements(state);
        let r = self.resultants(&d, StressPoint::Centre);
        out[..3].copy_from_slice(&r.membrane);
        out[3..6].copy_from_slice(&r.moment);
        out[6..8].copy_from_slice(&r.shear);
        let mut layers = Vec::new();
        self.layer_stresses_into(&d, StressPoint::Centre, &mut layers);
        out[8] = layers.iter().map(|l| l.von_mises()).fold(0.0, f64::max);
    }

    /// `½ dᵀ K d`.
    fn strain_energy(&self, _ctx: &EvalContext, state: &State) -> f64 {
        let (d, _) = self.unknowns(state);
        0.5 * d.dot(&(*self.stiffness * d))
    }

    /// `½ vᵀ M v`.
    fn kinetic_energy(&self, state: &State) -> f64 {
        if self.laminate.mass_per_area() == 0.0 {
            return 0.0;
        }
        let v = self.rates(&state.velocity);
        0.5 * v.dot(&(self.mass_matrix() * v))
    }

    /// `p = M v`: the linear momentum `Σ p_u`, the angular momentum
    /// `Σ (xᵢ × p_uᵢ + Rᵢ p_Θᵢ)` about the origin.
    fn momenta(&self, state: &State) -> Momenta {
        if self.laminate.mass_per_area() == 0.0 {
            return Momenta::default();
        }
        let p = self.mass_matrix() * self.rates(&state.velocity);
        let mut m = Momenta::default();
        for (i, &n) in self.nodes.iter().enumerate() {
            let pu: Vec3 = p.fixed_rows::<3>(6 * i).into();
            let pt: Vec3 = p.fixed_rows::<3>(6 * i + 3).into();
            m.linear += pu;
            m.angular += state.x[n].cross(&pu) + state.q[n] * pt;
        }
        m
    }

    /// `−m g·X_c − f_g·d`: the potential whose gradient is the weight
    /// in the residual.
    fn weight_potential(&self, ctx: &EvalContext, state: &State) -> f64 {
        if ctx.gravity == Vec3::zeros() {
            return 0.0;
        }
        let (d, _) = self.unknowns(state);
        -self.mass() * ctx.gravity.dot(&self.mass_centre)
            - (self.gravity_load * ctx.gravity).dot(&d)
    }

    fn cell_shape(&self) -> CellShape {
        CellShape::Quad
    }

    fn mass(&self) -> f64 {
        self.laminate.mass_per_area() * self.area
    }

    fn as_shell(&self) -> Option<&Shell> {
        Some(self)
    }
}

/// Adds a 24 × 24 matrix into a column-major buffer of the same size.
fn add_matrix(buf: &mut [f64], m: &Mat24) {
    for (b, v) in buf.iter_mut().zip(m.as_slice()) {
        *b += v;
    }
}

/// A vector of the 24 local unknowns.
pub type ShellVector = SVector<f64, 24>;
/// A 24 × 24 matrix of the element.
pub type ShellMatrix = SMatrix<f64, 24, 24>;

#[cfg(test)]
mod tests;
