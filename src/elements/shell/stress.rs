//! Stress recovery of a shell element (docs/theory.md §17.3): from the
//! displacements and rotations of its four nodes, the strains and stress
//! resultants at a point of the element and the stresses of every layer
//! (ply, face sheet ply, core) there, in the element's axes, with their
//! principal and von Mises values.
//!
//! The input is [`NodalDisplacements`]: each node's translation from its
//! reference position and its (small) rotation vector, both in **global
//! components** of the model the element was built in. A program that
//! holds the response of a reduced model (the physical displacements of a
//! superelement's original mesh, in the frame of its reference
//! configuration) gives them directly; [`Shell::displacements`] takes them
//! from a [`State`], and [`Shell::displacements_from_unknowns`] from the
//! model's unknowns (rotations in the nodes' reference frames). The
//! element is linear: stresses are linear in the displacements.
//!
//! ```
//! use std::sync::Arc;
//! use unfold::elements::laminate::Laminate;
//! use unfold::elements::shell::{NodalDisplacements, Shell, StressPoint};
//! use unfold::so3::{Rotation, Vec3};
//!
//! // a 1 m × 1 m aluminium plate element, 2 mm thick
//! let lam = Arc::new(Laminate::isotropic(70e9, 0.3, 2e-3, 2700.0).unwrap());
//! let x = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
//!     .map(|[a, b]| Vec3::new(a, b, 0.0));
//! let shell = Shell::new(1, [0, 1, 2, 3], x, [Rotation::identity(); 4], None, lam).unwrap();
//! // stretched by 1e-4 along x
//! let mut d = NodalDisplacements::default();
//! for (i, p) in x.iter().enumerate() {
//!     d.0[i][0] = 1e-4 * p.x;
//! }
//! let layers = shell.layer_stresses(&d, StressPoint::Centre);
//! let s = &layers[0].top;
//! // σxx = E ε/(1 − ν²), σyy = ν σxx
//! assert!((s.sigma[0] - 70e9 * 1e-4 / 0.91).abs() < 1e-3);
//! assert!((s.sigma[1] - 0.3 * s.sigma[0]).abs() < 1e-3);
//! assert!(s.von_mises > 0.0);
//! ```

use nalgebra::{Vector2, Vector3};

use super::mitc4::{Vec24, GAUSS_POINTS};
use super::Shell;
use crate::elements::laminate::LayerStress;
use crate::so3::{self, Vec3};
use crate::state::State;

/// Displacements of the four nodes of a shell from their reference
/// configuration, `[ux, uy, uz, θx, θy, θz]` per node in the element's
/// order: translations and small rotation vectors, global components.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NodalDisplacements(pub [[f64; 6]; 4]);

/// A point of the element where strains and stresses are recovered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StressPoint {
    /// The centre, `ξ = η = 0`.
    Centre,
    /// A 2 × 2 Gauss point: 0 to 3, the one nearest to corner 1 to 4.
    Gauss(usize),
    /// Natural coordinates `(ξ, η)` in `[−1, 1]²`.
    Natural(f64, f64),
}

impl StressPoint {
    /// `(ξ, η)`.
    ///
    /// # Panics
    /// For a Gauss point beyond 3.
    pub fn natural(self) -> (f64, f64) {
        match self {
            Self::Centre => (0.0, 0.0),
            Self::Gauss(k) => {
                assert!(k < 4, "a shell has Gauss points 0 to 3, not {k}");
                (GAUSS_POINTS[k][0], GAUSS_POINTS[k][1])
            }
            Self::Natural(xi, eta) => (xi, eta),
        }
    }
}

/// Generalised strains at a point, element axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShellStrains {
    /// Membrane strains `(εxx, εyy, γxy)` of the reference surface.
    pub membrane: [f64; 3],
    /// Curvatures `(κxx, κyy, κxy)`: `ε(z) = ε₀ + z κ`.
    pub curvature: [f64; 3],
    /// Transverse shear strains `(γxz, γyz)` (MITC4).
    pub shear: [f64; 2],
}

/// Stress resultants per unit length at a point, element axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShellResultants {
    /// Membrane forces `(Nxx, Nyy, Nxy)`.
    pub membrane: [f64; 3],
    /// Moments `(Mxx, Myy, Mxy)`, `M = ∫ σ z dz`.
    pub moment: [f64; 3],
    /// Transverse shear forces `(Qx, Qy)`.
    pub shear: [f64; 2],
}

impl Shell {
    /// The displacements of the element's nodes at `state`: `x − X` and
    /// the rotation `R₀ log(R₀ᵀR)`, global components.
    pub fn displacements(&self, state: &State) -> NodalDisplacements {
        let mut d = NodalDisplacements::default();
        for (i, &n) in self.nodes.iter().enumerate() {
            let u = state.x[n] - self.reference_x[i];
            let psi = so3::log(&(self.reference_q[i].inverse() * state.q[n]));
            let theta = self.reference_r[i] * psi;
            d.0[i] = [u.x, u.y, u.z, theta.x, theta.y, theta.z];
        }
        d
    }

    /// The displacements from the model's unknowns of the element's nodes
    /// (a solution of the linear system `K q = f`, a mode shape in the
    /// unknowns): translations global, rotations in each node's reference
    /// frame `R₀`, turned here to global components.
    pub fn displacements_from_unknowns(&self, unknowns: &[[f64; 6]; 4]) -> NodalDisplacements {
        let mut d = NodalDisplacements::default();
        for i in 0..4 {
            let u = &unknowns[i];
            let theta = self.reference_r[i] * Vec3::new(u[3], u[4], u[5]);
            d.0[i] = [u[0], u[1], u[2], theta.x, theta.y, theta.z];
        }
        d
    }

    /// The 24 local unknowns in the element's axes.
    fn local(&self, d: &NodalDisplacements) -> Vec24 {
        let et = self.axes.transpose();
        let mut out = Vec24::zeros();
        for i in 0..4 {
            let u = et * Vec3::new(d.0[i][0], d.0[i][1], d.0[i][2]);
            let t = et * Vec3::new(d.0[i][3], d.0[i][4], d.0[i][5]);
            out.fixed_rows_mut::<3>(6 * i).copy_from(&u);
            out.fixed_rows_mut::<3>(6 * i + 3).copy_from(&t);
        }
        out
    }

    fn strain_vectors(
        &self,
        d: &NodalDisplacements,
        at: StressPoint,
    ) -> (Vector3<f64>, Vector3<f64>, Vector2<f64>) {
        let (xi, eta) = at.natural();
        self.geometry.strains(&self.local(d), xi, eta)
    }

    /// Membrane strains, curvatures and transverse shear strains at `at`.
    pub fn strains(&self, d: &NodalDisplacements, at: StressPoint) -> ShellStrains {
        let (e, k, g) = self.strain_vectors(d, at);
        ShellStrains {
            membrane: e.into(),
            curvature: k.into(),
            shear: g.into(),
        }
    }

    /// Stress resultants at `at`: `N = A ε₀ + B κ`, `M = B ε₀ + D κ`,
    /// `Q = H γ`.
    pub fn resultants(&self, d: &NodalDisplacements, at: StressPoint) -> ShellResultants {
        let (e, k, g) = self.strain_vectors(d, at);
        let lam = &self.laminate;
        let n = lam.a() * e + lam.b() * k;
        let m = lam.b() * e + lam.d() * k;
        let q = lam.shear() * g;
        ShellResultants {
            membrane: n.into(),
            moment: m.into(),
            shear: q.into(),
        }
    }

    /// The stresses of every layer at `at` (from the bottom layer up): the
    /// in-plane stresses at the bottom and top of each, with principal and
    /// von Mises values, and the transverse shear stresses at its middle
    /// ([`crate::elements::laminate::Laminate::layer_stresses`]).
    pub fn layer_stresses(&self, d: &NodalDisplacements, at: StressPoint) -> Vec<LayerStress> {
        let mut out = Vec::with_capacity(self.laminate.layers().len());
        self.layer_stresses_into(d, at, &mut out);
        out
    }

    /// [`Shell::layer_stresses`] into `out` (cleared first), for a caller
    /// that recovers stresses at every output step without allocating.
    pub fn layer_stresses_into(
        &self,
        d: &NodalDisplacements,
        at: StressPoint,
        out: &mut Vec<LayerStress>,
    ) {
        let (e, k, g) = self.strain_vectors(d, at);
        let q = self.laminate.shear() * g;
        self.laminate.layer_stresses(&e, &k, &q, out);
    }
}

/// The largest stress of one skin (face sheet) of a shell at a point:
/// its von Mises stress and the principal stresses where it is largest,
/// over the skin's layers and their two surfaces.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SkinStress {
    /// The layer (index in [`crate::elements::laminate::Laminate::layers`],
    /// from the bottom) where the von Mises stress is largest.
    pub layer: usize,
    /// von Mises stress there.
    pub von_mises: f64,
    /// Principal stresses `σ₁ ≥ σ₂` there.
    pub principal: [f64; 2],
}

impl Shell {
    /// The stresses of the two skins, `[bottom, top]`, from the layer
    /// stresses `layers` of [`Shell::layer_stresses`] at one point: a
    /// sandwich's face sheets (its `BottomFace` and `TopFace` layers), or,
    /// for a plain stack of plies, its outermost plies. Each skin gives its
    /// largest von Mises stress over its layers and their two surfaces,
    /// with the layer and the principal stresses there (paper figure 15:
    /// stresses on the upper skin of a panel).
    pub fn skin_stresses(&self, layers: &[LayerStress]) -> [SkinStress; 2] {
        use crate::elements::laminate::LayerRole;
        let sandwich = layers.iter().any(|l| l.role == LayerRole::Core);
        let last = layers.len().saturating_sub(1);
        let mut skins = [SkinStress::default(); 2];
        for (k, l) in layers.iter().enumerate() {
            let skin = match l.role {
                LayerRole::BottomFace => 0,
                LayerRole::TopFace => 1,
                LayerRole::Ply if !sandwich && k == 0 => 0,
                LayerRole::Ply if !sandwich && k == last => 1,
                _ => continue,
            };
            for s in [&l.bottom, &l.top] {
                if s.von_mises > skins[skin].von_mises {
                    skins[skin] = SkinStress {
                        layer: l.layer,
                        von_mises: s.von_mises,
                        principal: s.principal,
                    };
                }
            }
        }
        skins
    }
}
