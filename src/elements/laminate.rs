//! Laminates: the stiffness and inertia of a shell section made of
//! orthotropic plies, or of a sandwich (two face sheets, each a ply stack,
//! on a core), by classical lamination theory with first-order transverse
//! shear (docs/theory.md §17.2).
//!
//! Conventions (Jones, *Mechanics of Composite Materials*, 2nd ed. 1999,
//! §2.6 and §4.2; Reddy, *Mechanics of Laminated Composite Plates and
//! Shells*, 2nd ed. 2004, §3.3):
//! - the section's axes `x, y` are the shell's material axes, `z` its
//!   normal; `z = 0` is the middle of the stack (the shell's reference
//!   surface), layers are stacked from `z = −h/2` up;
//! - a ply's angle `θ` turns its fibre direction 1 from `x` about `z`;
//! - strains `ε = (εx, εy, γxy)` (engineering shear), curvatures
//!   `κ = (κx, κy, κxy)`, transverse shear strains `γ = (γxz, γyz)`, so
//!   that `ε(z) = ε₀ + z κ` through the thickness;
//! - resultants per unit length `N = A ε₀ + B κ`, `M = B ε₀ + D κ`,
//!   `Q = H γ` (L1), with `(A, B, D) = Σ Q̄ₖ (zₖ₊₁ⁿ − zₖⁿ)/n` for
//!   `n = 1, 2, 3` and `Q̄ = T_εᵀ Q T_ε` the ply's plane-stress stiffness
//!   turned to the section's axes (L2);
//! - the transverse shear stiffness `H` is `Σ Q̄sₖ tₖ` scaled by a shear
//!   correction factor per direction from the equality of the shear
//!   strain energy with that of the equilibrium stress distribution
//!   (L3–L4; Vlachoutsis, *Shear correction factors for plates and
//!   shells*, IJNME 33, 1992): 5/6 for a homogeneous plate, and for a
//!   sandwich with thin stiff faces `H = G_c d²/t_c` (the core carries the
//!   shear; Allen, *Analysis and Design of Structural Sandwich Panels*,
//!   1969, §2.3; Zenkert, *An Introduction to Sandwich Construction*,
//!   1995, eq. 4.9), which the same formula gives without a special case;
//! - mass per area `ρ₀ = Σ ρₖ tₖ`, first moment `ρ₁ = Σ ρₖ (zₖ₊₁² − zₖ²)/2`
//!   (zero for a symmetric stack) and rotary inertia
//!   `ρ₂ = Σ ρₖ (zₖ₊₁³ − zₖ³)/3` per area (L5).

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

/// Why a ply, a core or a laminate is not acceptable.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LaminateError {
    /// A modulus or a thickness that must be positive is not.
    #[error("{what} must be positive and finite, got {value}")]
    NonPositive {
        /// The quantity (`E1`, `thickness`).
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A density or a core modulus that must be zero or positive is not.
    #[error("{what} must be zero or positive and finite, got {value}")]
    Negative {
        /// The quantity (`density`).
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A value that must be finite is not.
    #[error("{what} must be finite, got {value}")]
    NotFinite {
        /// The quantity (`angle`).
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// Poisson's ratio makes the ply's plane-stress stiffness indefinite.
    #[error("ν12 = {nu12}: ν12² = {squared:.6} must be below E1/E2 = {ratio:.6} (ν12·ν21 < 1), or the ply's stiffness is not positive definite")]
    Poisson {
        /// `ν₁₂`.
        nu12: f64,
        /// `ν₁₂²`.
        squared: f64,
        /// `E₁/E₂`.
        ratio: f64,
    },
    /// A laminate (or a face sheet) without plies.
    #[error("has no plies")]
    Empty,
    /// A ply of the stack is not acceptable.
    #[error("ply {index}: {source}")]
    Ply {
        /// Its position in the stack, from 1.
        index: usize,
        /// What is wrong with it.
        source: Box<LaminateError>,
    },
    /// The core of a sandwich is not acceptable.
    #[error("core: {0}")]
    Core(Box<LaminateError>),
}

fn positive(what: &'static str, value: f64) -> Result<f64, LaminateError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(LaminateError::NonPositive { what, value })
    }
}

fn non_negative(what: &'static str, value: f64) -> Result<f64, LaminateError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(LaminateError::Negative { what, value })
    }
}

fn finite(what: &'static str, value: f64) -> Result<f64, LaminateError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(LaminateError::NotFinite { what, value })
    }
}

/// An orthotropic ply material (a unidirectional lamina; Nastran's MAT8):
/// moduli in its material axes 1 (fibre), 2 (transverse in the plane),
/// 3 (normal), and its density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlyMaterial {
    /// `E₁`, Young's modulus along the fibres.
    pub e1: f64,
    /// `E₂`, Young's modulus across the fibres, in the plane.
    pub e2: f64,
    /// `ν₁₂`, the contraction along 2 per unit extension along 1.
    pub nu12: f64,
    /// `G₁₂`, in-plane shear modulus.
    pub g12: f64,
    /// `G₁₃`, transverse shear modulus in the 1–3 plane.
    pub g13: f64,
    /// `G₂₃`, transverse shear modulus in the 2–3 plane.
    pub g23: f64,
    /// Density (mass per volume).
    pub density: f64,
}

impl PlyMaterial {
    /// A validated orthotropic material: moduli positive, `ν₁₂² < E₁/E₂`
    /// (so that `ν₁₂ ν₂₁ < 1` and the plane-stress stiffness is positive
    /// definite), density zero or positive.
    pub fn orthotropic(
        e1: f64,
        e2: f64,
        nu12: f64,
        g12: f64,
        g13: f64,
        g23: f64,
        density: f64,
    ) -> Result<Self, LaminateError> {
        positive("E1", e1)?;
        positive("E2", e2)?;
        positive("G12", g12)?;
        positive("G13", g13)?;
        positive("G23", g23)?;
        finite("nu12", nu12)?;
        non_negative("density", density)?;
        let ratio = e1 / e2;
        if nu12 * nu12 >= ratio {
            return Err(LaminateError::Poisson {
                nu12,
                squared: nu12 * nu12,
                ratio,
            });
        }
        Ok(Self {
            e1,
            e2,
            nu12,
            g12,
            g13,
            g23,
            density,
        })
    }

    /// A validated isotropic material: `E > 0`, `ν² < 1` (plane stress),
    /// `G = E/2(1 + ν)` in every plane.
    pub fn isotropic(e: f64, nu: f64, density: f64) -> Result<Self, LaminateError> {
        positive("E", e)?;
        finite("nu", nu)?;
        if nu * nu >= 1.0 {
            return Err(LaminateError::Poisson {
                nu12: nu,
                squared: nu * nu,
                ratio: 1.0,
            });
        }
        let g = e / (2.0 * (1.0 + nu));
        Self::orthotropic(e, e, nu, g, g, g, density)
    }

    /// `ν₂₁ = ν₁₂ E₂/E₁` (0 for a core without in-plane stiffness).
    pub fn nu21(&self) -> f64 {
        if self.e1 > 0.0 {
            self.nu12 * self.e2 / self.e1
        } else {
            0.0
        }
    }

    /// The plane-stress reduced stiffness `Q` in the material axes
    /// (Jones eq. 2.61): `σ₁₂ = Q ε₁₂`, engineering shear.
    pub fn reduced_stiffness(&self) -> Matrix3<f64> {
        let d = 1.0 - self.nu12 * self.nu21();
        let q11 = self.e1 / d;
        let q22 = self.e2 / d;
        let q12 = self.nu12 * self.e2 / d;
        Matrix3::new(q11, q12, 0.0, q12, q22, 0.0, 0.0, 0.0, self.g12)
    }
}

/// One ply of a stack: its material, thickness and angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ply {
    /// Its material.
    pub material: PlyMaterial,
    /// Its thickness.
    pub thickness: f64,
    /// The angle from the section's `x` axis to its fibres, about the
    /// normal (radians).
    pub angle: f64,
}

impl Ply {
    /// A ply of `material`, `thickness` thick, its fibres at `angle`
    /// (radians) from the section's `x` axis.
    pub fn new(material: PlyMaterial, thickness: f64, angle: f64) -> Self {
        Self {
            material,
            thickness,
            angle,
        }
    }
}

/// The core of a sandwich: its thickness, its transverse shear moduli
/// (a honeycomb's ribbon `L` direction along `13`), density and optional
/// in-plane isotropic modulus (zero for a honeycomb, whose in-plane
/// stiffness is negligible; a foam's `E`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Core {
    /// Thickness `t_c`.
    pub thickness: f64,
    /// `G₁₃`, transverse shear modulus in the plane of its direction 1.
    pub g13: f64,
    /// `G₂₃`, transverse shear modulus in the plane of its direction 2.
    pub g23: f64,
    /// Density.
    pub density: f64,
    /// In-plane Young's modulus (isotropic in the plane), default 0.
    pub modulus: f64,
    /// In-plane Poisson's ratio, default 0.
    pub poisson: f64,
    /// Angle of its direction 1 from the section's `x` axis (radians).
    pub angle: f64,
}

impl Core {
    /// A core of `thickness` with transverse shear moduli `g13`, `g23`,
    /// without density or in-plane stiffness.
    pub fn new(thickness: f64, g13: f64, g23: f64) -> Self {
        Self {
            thickness,
            g13,
            g23,
            density: 0.0,
            modulus: 0.0,
            poisson: 0.0,
            angle: 0.0,
        }
    }

    /// The core as a ply (checked).
    fn as_ply(&self) -> Result<Ply, LaminateError> {
        positive("thickness", self.thickness)?;
        positive("G13", self.g13)?;
        positive("G23", self.g23)?;
        non_negative("density", self.density)?;
        non_negative("E", self.modulus)?;
        finite("nu", self.poisson)?;
        finite("angle", self.angle)?;
        if self.poisson * self.poisson >= 1.0 {
            return Err(LaminateError::Poisson {
                nu12: self.poisson,
                squared: self.poisson * self.poisson,
                ratio: 1.0,
            });
        }
        let material = PlyMaterial {
            e1: self.modulus,
            e2: self.modulus,
            nu12: self.poisson,
            g12: self.modulus / (2.0 * (1.0 + self.poisson)),
            g13: self.g13,
            g23: self.g23,
            density: self.density,
        };
        Ok(Ply::new(material, self.thickness, self.angle))
    }
}

/// What a layer of a laminate is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LayerRole {
    /// A ply of a plain stack.
    Ply,
    /// A ply of the bottom face sheet of a sandwich (below the core).
    BottomFace,
    /// The core of a sandwich.
    Core,
    /// A ply of the top face sheet of a sandwich (above the core).
    TopFace,
}

impl LayerRole {
    /// Name used in result files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ply => "ply",
            Self::BottomFace => "bottom face",
            Self::Core => "core",
            Self::TopFace => "top face",
        }
    }
}

/// A layer of a laminate, placed through the thickness, with its
/// stiffness turned to the section's axes.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// The ply (material, thickness, angle).
    pub ply: Ply,
    /// What it is in the laminate.
    pub role: LayerRole,
    /// `z` of its bottom and top surfaces.
    pub z: [f64; 2],
    /// `Q̄`, its plane-stress stiffness in the section's axes (L2).
    pub stiffness: Matrix3<f64>,
    /// `Q̄s`, its transverse shear stiffness in the section's axes,
    /// order `(xz, yz)`.
    pub shear_stiffness: Matrix2<f64>,
}

/// `T_ε`: strains in the section's axes to strains in the axes turned by
/// `angle`, engineering shear (Jones eq. 2.84 with Reuter's matrix).
fn strain_rotation(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    Matrix3::new(
        c * c,
        s * s,
        c * s,
        s * s,
        c * c,
        -c * s,
        -2.0 * c * s,
        2.0 * c * s,
        c * c - s * s,
    )
}

impl Layer {
    fn new(ply: Ply, role: LayerRole, z: [f64; 2]) -> Self {
        let m = &ply.material;
        // L2: Q̄ = T_εᵀ Q T_ε, from the equality of the work σ·ε in
        // both axes
        let t = strain_rotation(ply.angle);
        let stiffness = t.transpose() * m.reduced_stiffness() * t;
        // transverse shear: (γ1z, γ2z) = R (γxz, γyz)
        let (s, c) = ply.angle.sin_cos();
        let r = Matrix2::new(c, s, -s, c);
        let shear_stiffness = r.transpose() * Matrix2::new(m.g13, 0.0, 0.0, m.g23) * r;
        Self {
            ply,
            role,
            z,
            stiffness,
            shear_stiffness,
        }
    }

    /// Its thickness.
    pub fn thickness(&self) -> f64 {
        self.z[1] - self.z[0]
    }
}

/// The transverse shear of one bending direction in cylindrical bending
/// (L3): the neutral surface `z_n`, the bending stiffness `D*` about it,
/// and at the bottom of each layer the first moment
/// `g(z) = ∫_{−h/2}^{z} E(ζ)(ζ − z_n) dζ`, so that equilibrium gives
/// `τ(z) = −Q g(z)/D*`.
#[derive(Clone, Debug, PartialEq)]
struct ShearShape {
    neutral: f64,
    bending: f64,
    /// `E` of each layer in this direction (`Q̄₁₁` or `Q̄₂₂`).
    modulus: Vec<f64>,
    /// `g` at the bottom of each layer.
    moment: Vec<f64>,
}

impl ShearShape {
    /// Direction `dir` (0: bending in x, shear xz; 1: bending in y, shear
    /// yz).
    fn new(layers: &[Layer], dir: usize) -> Self {
        let modulus: Vec<f64> = layers.iter().map(|l| l.stiffness[(dir, dir)]).collect();
        let (mut first, mut area) = (0.0, 0.0);
        for (l, e) in layers.iter().zip(&modulus) {
            first += e * (l.z[1] * l.z[1] - l.z[0] * l.z[0]) / 2.0;
            area += e * l.thickness();
        }
        let neutral = first / area;
        let cube = |z: f64| (z - neutral).powi(3) / 3.0;
        let bending: f64 = layers
            .iter()
            .zip(&modulus)
            .map(|(l, e)| e * (cube(l.z[1]) - cube(l.z[0])))
            .sum();
        let mut moment = Vec::with_capacity(layers.len());
        let mut g = 0.0;
        for (l, e) in layers.iter().zip(&modulus) {
            moment.push(g);
            let sq = |z: f64| (z - neutral).powi(2) / 2.0;
            g += e * (sq(l.z[1]) - sq(l.z[0]));
        }
        Self {
            neutral,
            bending,
            modulus,
            moment,
        }
    }

    /// `g(z)` in layer `k`.
    fn g(&self, layers: &[Layer], k: usize, z: f64) -> f64 {
        let sq = |z: f64| (z - self.neutral).powi(2) / 2.0;
        self.moment[k] + self.modulus[k] * (sq(z) - sq(layers[k].z[0]))
    }

    /// L4: the shear stiffness `S = D*² / Σ ∫ g²/G dz` that stores the
    /// energy of the equilibrium distribution `τ = −Q g/D*`, `G` the
    /// layers' transverse shear modulus in this direction. `g²` is a
    /// quartic in each layer: three Gauss points integrate it exactly.
    fn stiffness(&self, layers: &[Layer], dir: usize) -> f64 {
        const GAUSS: [(f64, f64); 3] = [
            (-0.774_596_669_241_483_4, 5.0 / 9.0),
            (0.0, 8.0 / 9.0),
            (0.774_596_669_241_483_4, 5.0 / 9.0),
        ];
        let mut compliance = 0.0;
        for (k, l) in layers.iter().enumerate() {
            let (mid, half) = (0.5 * (l.z[0] + l.z[1]), 0.5 * l.thickness());
            let g_shear = l.shear_stiffness[(dir, dir)];
            for (x, w) in GAUSS {
                let g = self.g(layers, k, mid + half * x);
                compliance += w * half * g * g / g_shear;
            }
        }
        self.bending * self.bending / compliance
    }
}

/// The laminate of a shell: its layers and the section matrices they give
/// (module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Laminate {
    layers: Vec<Layer>,
    thickness: f64,
    a: Matrix3<f64>,
    b: Matrix3<f64>,
    d: Matrix3<f64>,
    shear: Matrix2<f64>,
    shear_correction: [f64; 2],
    shapes: [ShearShape; 2],
    /// `(ρ₀, ρ₁, ρ₂)`.
    mass: [f64; 3],
}

impl Laminate {
    /// A stack of plies listed from the bottom (`z = −h/2`) up.
    pub fn stack(plies: &[Ply]) -> Result<Self, LaminateError> {
        check_plies(plies)?;
        Self::from_layers(plies.iter().map(|p| (*p, LayerRole::Ply)).collect())
    }

    /// A single isotropic layer of thickness `t` (a homogeneous plate).
    pub fn isotropic(e: f64, nu: f64, t: f64, density: f64) -> Result<Self, LaminateError> {
        let m = PlyMaterial::isotropic(e, nu, density)?;
        Self::stack(&[Ply::new(m, t, 0.0)])
    }

    /// A sandwich: the `bottom` face sheet, the `core`, the `top` face
    /// sheet, each face's plies listed **from the core outward** (so that
    /// the same list for both faces gives a symmetric sandwich).
    pub fn sandwich(bottom: &[Ply], core: &Core, top: &[Ply]) -> Result<Self, LaminateError> {
        check_plies(bottom)?;
        check_plies(top)?;
        let core = core
            .as_ply()
            .map_err(|e| LaminateError::Core(Box::new(e)))?;
        let mut layers: Vec<(Ply, LayerRole)> = bottom
            .iter()
            .rev()
            .map(|p| (*p, LayerRole::BottomFace))
            .collect();
        layers.push((core, LayerRole::Core));
        layers.extend(top.iter().map(|p| (*p, LayerRole::TopFace)));
        Self::from_layers(layers)
    }

    fn from_layers(plies: Vec<(Ply, LayerRole)>) -> Result<Self, LaminateError> {
        let thickness: f64 = plies.iter().map(|(p, _)| p.thickness).sum();
        let mut z = -0.5 * thickness;
        let mut layers = Vec::with_capacity(plies.len());
        let (mut a, mut b, mut d) = (Matrix3::zeros(), Matrix3::zeros(), Matrix3::zeros());
        let mut shear = Matrix2::zeros();
        let mut mass = [0.0; 3];
        for (ply, role) in plies {
            let top = z + ply.thickness;
            let layer = Layer::new(ply, role, [z, top]);
            // L1: (A, B, D) = Σ Q̄ (z₁ⁿ − z₀ⁿ)/n
            let (d1, d2, d3) = (
                top - z,
                (top * top - z * z) / 2.0,
                (top.powi(3) - z.powi(3)) / 3.0,
            );
            a += layer.stiffness * d1;
            b += layer.stiffness * d2;
            d += layer.stiffness * d3;
            shear += layer.shear_stiffness * d1;
            // L5
            let rho = ply.material.density;
            mass[0] += rho * d1;
            mass[1] += rho * d2;
            mass[2] += rho * d3;
            layers.push(layer);
            z = top;
        }
        // L3–L4: shear correction per direction, the coupling term with
        // the geometric mean of both
        let shapes = [ShearShape::new(&layers, 0), ShearShape::new(&layers, 1)];
        let k = [0, 1].map(|i| shapes[i].stiffness(&layers, i) / shear[(i, i)]);
        let shear = Matrix2::new(
            k[0] * shear[(0, 0)],
            (k[0] * k[1]).sqrt() * shear[(0, 1)],
            (k[0] * k[1]).sqrt() * shear[(1, 0)],
            k[1] * shear[(1, 1)],
        );
        Ok(Self {
            layers,
            thickness,
            a,
            b,
            d,
            shear,
            shear_correction: k,
            shapes,
            mass,
        })
    }

    /// The layers, from the bottom up.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }

    /// Total thickness `h`.
    pub fn thickness(&self) -> f64 {
        self.thickness
    }

    /// `A`, membrane stiffness (force per length).
    pub fn a(&self) -> &Matrix3<f64> {
        &self.a
    }

    /// `B`, membrane–bending coupling (zero for a symmetric stack).
    pub fn b(&self) -> &Matrix3<f64> {
        &self.b
    }

    /// `D`, bending stiffness (moment per length per curvature).
    pub fn d(&self) -> &Matrix3<f64> {
        &self.d
    }

    /// `H`, transverse shear stiffness (force per length), order
    /// `(xz, yz)`, shear correction included.
    pub fn shear(&self) -> &Matrix2<f64> {
        &self.shear
    }

    /// The shear correction factors `(k_xz, k_yz)` of L4 (5/6 for a
    /// homogeneous plate).
    pub fn shear_correction(&self) -> [f64; 2] {
        self.shear_correction
    }

    /// Mass per area `ρ₀`.
    pub fn mass_per_area(&self) -> f64 {
        self.mass[0]
    }

    /// First moment of mass per area about the reference surface `ρ₁`.
    pub fn first_moment(&self) -> f64 {
        self.mass[1]
    }

    /// Rotary inertia per area about the reference surface `ρ₂`.
    pub fn rotary_inertia(&self) -> f64 {
        self.mass[2]
    }

    /// The stresses in every layer for the membrane strains `membrane`,
    /// the curvatures `curvature` and the transverse shear forces
    /// `shear_force` (all in the section's axes), into `out` (cleared):
    /// in-plane stresses at the bottom and top of each layer,
    /// `σ = Q̄ (ε₀ + z κ)`, and the transverse shear stresses at its
    /// middle from the equilibrium distribution `τ = −Q g(z)/D*` of each
    /// direction (L3).
    pub fn layer_stresses(
        &self,
        membrane: &Vector3<f64>,
        curvature: &Vector3<f64>,
        shear_force: &Vector2<f64>,
        out: &mut Vec<LayerStress>,
    ) {
        out.clear();
        for (k, l) in self.layers.iter().enumerate() {
            let at = |z: f64| InPlaneStress::new(l.stiffness * (membrane + curvature * z));
            let mid = 0.5 * (l.z[0] + l.z[1]);
            let tau = [0, 1].map(|i| {
                let s = &self.shapes[i];
                -shear_force[i] * s.g(&self.layers, k, mid) / s.bending
            });
            out.push(LayerStress {
                layer: k,
                role: l.role,
                z: l.z,
                bottom: at(l.z[0]),
                top: at(l.z[1]),
                transverse_shear: tau,
            });
        }
    }
}

fn check_plies(plies: &[Ply]) -> Result<(), LaminateError> {
    if plies.is_empty() {
        return Err(LaminateError::Empty);
    }
    for (i, p) in plies.iter().enumerate() {
        let wrap = |e| LaminateError::Ply {
            index: i + 1,
            source: Box::new(e),
        };
        positive("thickness", p.thickness).map_err(wrap)?;
        finite("angle", p.angle).map_err(wrap)?;
    }
    Ok(())
}

/// A plane stress state `(σxx, σyy, τxy)` with its principal stresses and
/// von Mises equivalent stress.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InPlaneStress {
    /// `(σxx, σyy, τxy)`, in the shell's material axes.
    pub sigma: [f64; 3],
    /// Principal stresses `σ₁ ≥ σ₂`.
    pub principal: [f64; 2],
    /// Angle from the `x` axis to the direction of `σ₁` (radians, in
    /// `(−π/2, π/2]`).
    pub principal_angle: f64,
    /// von Mises stress `√(σxx² − σxx σyy + σyy² + 3 τxy²)`.
    pub von_mises: f64,
}

impl InPlaneStress {
    /// The state of `σ = (σxx, σyy, τxy)`.
    pub fn new(sigma: Vector3<f64>) -> Self {
        let [sx, sy, t] = [sigma.x, sigma.y, sigma.z];
        let mean = 0.5 * (sx + sy);
        let radius = (0.25 * (sx - sy) * (sx - sy) + t * t).sqrt();
        Self {
            sigma: [sx, sy, t],
            principal: [mean + radius, mean - radius],
            principal_angle: 0.5 * (2.0 * t).atan2(sx - sy),
            von_mises: (sx * sx - sx * sy + sy * sy + 3.0 * t * t).max(0.0).sqrt(),
        }
    }

    /// The same stress in axes turned by `angle` about the normal (a
    /// ply's material axes: `(σ₁₁, σ₂₂, τ₁₂)`, for a failure criterion).
    pub fn in_axes(&self, angle: f64) -> [f64; 3] {
        // σ' = T_σ σ with T_σ = T_ε⁻ᵀ, which for a rotation is T_ε with
        // the shear row and column rescaled
        let (s, c) = angle.sin_cos();
        let [sx, sy, t] = self.sigma;
        [
            c * c * sx + s * s * sy + 2.0 * c * s * t,
            s * s * sx + c * c * sy - 2.0 * c * s * t,
            -c * s * sx + c * s * sy + (c * c - s * s) * t,
        ]
    }
}

/// The stresses of one layer at one point of a shell (see
/// [`Laminate::layer_stresses`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerStress {
    /// The layer's index in [`Laminate::layers`] (from the bottom, 0).
    pub layer: usize,
    /// What the layer is (ply, face sheet ply, core).
    pub role: LayerRole,
    /// `z` of its bottom and top surfaces.
    pub z: [f64; 2],
    /// In-plane stresses at its bottom surface.
    pub bottom: InPlaneStress,
    /// In-plane stresses at its top surface.
    pub top: InPlaneStress,
    /// Transverse shear stresses `(τxz, τyz)` at its middle (the core's
    /// shear stress in a sandwich).
    pub transverse_shear: [f64; 2],
}

impl LayerStress {
    /// The larger von Mises stress of its two surfaces.
    pub fn von_mises(&self) -> f64 {
        self.bottom.von_mises.max(self.top.von_mises)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// A carbon/epoxy ply (T300/5208, Reddy 2004 table 1.3.1, in Pa and
    /// kg/m³).
    fn carbon() -> PlyMaterial {
        PlyMaterial::orthotropic(181e9, 10.3e9, 0.28, 7.17e9, 7.17e9, 3.78e9, 1600.0).unwrap()
    }

    /// An isotropic plate: `A = Eh/(1−ν²)[..]`, `B = 0`,
    /// `D = Eh³/12(1−ν²)[..]` (Timoshenko & Woinowsky-Krieger 1959, eq.
    /// 3), `H = (5/6) G h` (Reissner), mass `ρh`, `ρh³/12`; to round-off.
    #[test]
    fn isotropic_plate() {
        let (e, nu, h, rho) = (70e9, 0.3, 2e-3, 2700.0);
        let lam = Laminate::isotropic(e, nu, h, rho).unwrap();
        let d = e * h.powi(3) / (12.0 * (1.0 - nu * nu));
        let expected = Matrix3::new(1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - nu));
        assert_relative_eq!(
            *lam.d(),
            expected * d,
            max_relative = 1e-13,
            epsilon = 1e-9 * d
        );
        assert_relative_eq!(
            *lam.a(),
            expected * (e * h / (1.0 - nu * nu)),
            max_relative = 1e-13,
            epsilon = 1e-6
        );
        assert!(lam.b().amax() <= 1e-12 * lam.a().amax() * h);
        let g = e / (2.0 * (1.0 + nu));
        for k in lam.shear_correction() {
            assert_relative_eq!(k, 5.0 / 6.0, max_relative = 1e-13);
        }
        assert_relative_eq!(lam.shear()[(0, 0)], 5.0 / 6.0 * g * h, max_relative = 1e-13);
        assert_relative_eq!(lam.shear()[(1, 1)], 5.0 / 6.0 * g * h, max_relative = 1e-13);
        assert_eq!(lam.shear()[(0, 1)], 0.0);
        assert_relative_eq!(lam.mass_per_area(), rho * h, max_relative = 1e-14);
        assert!(lam.first_moment().abs() <= 1e-15 * rho * h * h);
        assert_relative_eq!(
            lam.rotary_inertia(),
            rho * h.powi(3) / 12.0,
            max_relative = 1e-13
        );
    }

    /// A stack symmetric about its middle has `B = 0` and `ρ₁ = 0`
    /// (Jones §4.3.1), whatever its angles; an antisymmetric angle-ply
    /// `[+45/−45]` has `B ≠ 0` with only `B₁₆`, `B₂₆` (Jones §4.3.2.2), and
    /// `A₁₆ = A₂₆ = D₁₆ = D₂₆ = 0`.
    #[test]
    fn symmetric_stacks_have_no_coupling() {
        let m = carbon();
        let t = 0.125e-3;
        let deg = std::f64::consts::PI / 180.0;
        let angles = [0.0, 45.0, -45.0, 90.0];
        let plies: Vec<Ply> = angles
            .iter()
            .chain(angles.iter().rev())
            .map(|a| Ply::new(m, t, a * deg))
            .collect();
        let lam = Laminate::stack(&plies).unwrap();
        assert!(lam.b().amax() <= 1e-12 * lam.a().amax() * lam.thickness());
        assert!(lam.first_moment().abs() <= 1e-12 * lam.mass_per_area() * lam.thickness());

        let anti =
            Laminate::stack(&[Ply::new(m, t, 45.0 * deg), Ply::new(m, t, -45.0 * deg)]).unwrap();
        let (a, b, d) = (anti.a(), anti.b(), anti.d());
        let scale = b.amax();
        assert!(scale > 1e-3 * a.amax() * anti.thickness());
        for (i, j) in [(0, 0), (0, 1), (1, 1), (2, 2)] {
            assert!(b[(i, j)].abs() <= 1e-10 * scale, "B{i}{j} = {}", b[(i, j)]);
        }
        for (i, j) in [(0, 2), (1, 2)] {
            assert!(a[(i, j)].abs() <= 1e-10 * a.amax());
            assert!(d[(i, j)].abs() <= 1e-10 * d.amax());
            // B16 = B26 = −(t²/4)(Q̄16 of the +45 ply) ≠ 0
            assert!(b[(i, j)].abs() > 0.1 * scale);
        }
    }

    /// Q̄ of a ply turned by 90° swaps the 1 and 2 directions; by 45° it
    /// matches Jones eq. 2.85 written out.
    #[test]
    fn turned_ply_stiffness() {
        let m = carbon();
        let q = m.reduced_stiffness();
        let l90 = Layer::new(
            Ply::new(m, 1.0, std::f64::consts::FRAC_PI_2),
            LayerRole::Ply,
            [0.0, 1.0],
        );
        assert_relative_eq!(l90.stiffness[(0, 0)], q[(1, 1)], max_relative = 1e-12);
        assert_relative_eq!(l90.stiffness[(1, 1)], q[(0, 0)], max_relative = 1e-12);
        assert_relative_eq!(l90.shear_stiffness[(0, 0)], m.g23, max_relative = 1e-12);
        let l45 = Layer::new(
            Ply::new(m, 1.0, std::f64::consts::FRAC_PI_4),
            LayerRole::Ply,
            [0.0, 1.0],
        );
        let (q11, q12, q22, q66) = (q[(0, 0)], q[(0, 1)], q[(1, 1)], q[(2, 2)]);
        // Jones eq. 2.85 at c = s = 1/√2
        let bar11 = (q11 + 2.0 * (q12 + 2.0 * q66) + q22) / 4.0;
        let bar16 = ((q11 - q12 - 2.0 * q66) + (q12 - q22 + 2.0 * q66)) / 4.0;
        let bar66 = (q11 + q22 - 2.0 * q12 - 2.0 * q66) / 4.0 + q66 / 2.0;
        assert_relative_eq!(l45.stiffness[(0, 0)], bar11, max_relative = 1e-12);
        assert_relative_eq!(l45.stiffness[(0, 2)], bar16, max_relative = 1e-12);
        assert_relative_eq!(l45.stiffness[(2, 2)], bar66, max_relative = 1e-12);
        // Q̄45 = (G13 − G23) c s
        assert_relative_eq!(
            l45.shear_stiffness[(0, 1)],
            (m.g13 - m.g23) / 2.0,
            max_relative = 1e-12
        );
    }

    /// A sandwich of two aluminium faces (t_f = 0.3 mm) on a honeycomb
    /// core (t_c = 20 mm, no in-plane stiffness): `D = E_f t_f d²/2(1−ν²)`
    /// (the parallel-axis term of the faces, `d = t_c + t_f` between
    /// their middles) plus their own bending `E_f t_f³/6(1−ν²)` (Zenkert
    /// 1995 eq. 4.3; Allen 1969 eq. 2.4), to round-off; the shear
    /// stiffness `G_c d²/t_c` (Zenkert eq. 4.9) within the faces'
    /// contributions, which L4 keeps and the textbook formula leaves out
    /// (their own bending `t_f²/3d²` and shear compliance
    /// `~t_f G_c/t_c G_f`: 0.7e-4 and 1.1e-4 measured, the test allows
    /// 5e-4); the mass per area and the rotary inertia of the faces and
    /// the core.
    #[test]
    fn sandwich_against_the_textbook() {
        let (e, nu, rho_f) = (70e9, 0.33, 2800.0);
        let (tf, tc, gc_l, gc_w, rho_c) = (0.3e-3, 20e-3, 190e6, 90e6, 32.0);
        let face = Ply::new(PlyMaterial::isotropic(e, nu, rho_f).unwrap(), tf, 0.0);
        let core = Core {
            density: rho_c,
            ..Core::new(tc, gc_l, gc_w)
        };
        let lam = Laminate::sandwich(&[face], &core, &[face]).unwrap();
        let d = tc + tf;
        let ef = e / (1.0 - nu * nu);
        let d11 = ef * tf * d * d / 2.0 + ef * tf.powi(3) / 6.0;
        assert_relative_eq!(lam.d()[(0, 0)], d11, max_relative = 1e-12);
        assert_relative_eq!(lam.d()[(1, 1)], d11, max_relative = 1e-12);
        assert_relative_eq!(lam.d()[(0, 1)], nu * d11, max_relative = 1e-12);
        assert!(lam.b().amax() <= 1e-12 * lam.a().amax() * lam.thickness());
        // the core carries the shear
        for (i, gc) in [gc_l, gc_w].into_iter().enumerate() {
            let allen = gc * d * d / tc;
            let s = lam.shear()[(i, i)];
            println!(
                "sandwich shear {i}: {s:.6e} against G_c d²/t_c = {allen:.6e}, ratio {:.6}",
                s / allen
            );
            assert_relative_eq!(s, allen, max_relative = 5e-4);
        }
        assert_relative_eq!(
            lam.mass_per_area(),
            2.0 * rho_f * tf + rho_c * tc,
            max_relative = 1e-14
        );
        let i_faces = 2.0 * rho_f * ((tc / 2.0 + tf).powi(3) - (tc / 2.0).powi(3)) / 3.0;
        let i_core = rho_c * tc.powi(3) / 12.0;
        assert_relative_eq!(lam.rotary_inertia(), i_faces + i_core, max_relative = 1e-13);
        let roles: Vec<LayerRole> = lam.layers().iter().map(|l| l.role).collect();
        assert_eq!(
            roles,
            [LayerRole::BottomFace, LayerRole::Core, LayerRole::TopFace]
        );
    }

    /// Faces are listed from the core outward: an unsymmetric face
    /// `[0, 90]` on both sides gives a symmetric sandwich (`B = 0`), with
    /// the 90° plies outside.
    #[test]
    fn faces_are_listed_from_the_core_outward() {
        let m = carbon();
        let face = [
            Ply::new(m, 0.1e-3, 0.0),
            Ply::new(m, 0.1e-3, std::f64::consts::FRAC_PI_2),
        ];
        let lam = Laminate::sandwich(&face, &Core::new(10e-3, 100e6, 50e6), &face).unwrap();
        assert!(lam.b().amax() <= 1e-12 * lam.a().amax() * lam.thickness());
        let angles: Vec<f64> = lam.layers().iter().map(|l| l.ply.angle).collect();
        let half = std::f64::consts::FRAC_PI_2;
        assert_eq!(angles, [half, 0.0, 0.0, 0.0, half]);
    }

    /// Bad plies are refused with the quantity and the value: a negative
    /// thickness, `ν₁₂² ≥ E₁/E₂`, a zero modulus, a core without shear
    /// stiffness, an empty stack.
    #[test]
    fn bad_plies_are_refused() {
        let m = carbon();
        let e = Laminate::stack(&[Ply::new(m, 1e-3, 0.0), Ply::new(m, -1e-3, 0.0)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "ply 2: thickness must be positive and finite, got -0.001"
        );
        // E1/E2 = 0.1: ν12 = 0.4 gives ν12² = 0.16 ≥ 0.1
        let e = PlyMaterial::orthotropic(1e9, 10e9, 0.4, 1e9, 1e9, 1e9, 0.0).unwrap_err();
        assert!(matches!(e, LaminateError::Poisson { .. }), "{e}");
        assert!(
            e.to_string().contains("must be below E1/E2 = 0.100000"),
            "{e}"
        );
        // just below the limit is accepted
        assert!(PlyMaterial::orthotropic(1e9, 10e9, 0.316, 1e9, 1e9, 1e9, 0.0).is_ok());
        let e = PlyMaterial::orthotropic(0.0, 10e9, 0.3, 1e9, 1e9, 1e9, 0.0).unwrap_err();
        assert_eq!(e.to_string(), "E1 must be positive and finite, got 0");
        let e = PlyMaterial::isotropic(70e9, 1.0, 0.0).unwrap_err();
        assert!(matches!(e, LaminateError::Poisson { .. }));
        let face = [Ply::new(m, 1e-4, 0.0)];
        let e = Laminate::sandwich(&face, &Core::new(1e-2, 0.0, 1e6), &face).unwrap_err();
        assert_eq!(
            e.to_string(),
            "core: G13 must be positive and finite, got 0"
        );
        assert_eq!(Laminate::stack(&[]).unwrap_err(), LaminateError::Empty);
    }

    /// The layer stresses: a membrane strain alone gives `Q̄ ε` in every
    /// ply; a curvature alone, stresses linear in `z` with opposite signs
    /// on both sides of a symmetric stack; principal stresses and von
    /// Mises of a pure shear `τ` are `±τ` at 45° and `√3 τ`; the shear
    /// stress at the middle of a homogeneous plate is `3Q/2h`.
    #[test]
    fn layer_stresses() {
        let lam = Laminate::isotropic(70e9, 0.3, 2e-3, 0.0).unwrap();
        let mut out = Vec::new();
        let eps = Vector3::new(1e-4, -2e-4, 3e-4);
        lam.layer_stresses(&eps, &Vector3::zeros(), &Vector2::zeros(), &mut out);
        let s = lam.layers()[0].stiffness * eps;
        assert_eq!(out.len(), 1);
        assert_relative_eq!(Vector3::from(out[0].top.sigma), s, max_relative = 1e-14);
        assert_relative_eq!(Vector3::from(out[0].bottom.sigma), s, max_relative = 1e-14);
        let kappa = Vector3::new(0.1, 0.0, 0.0);
        lam.layer_stresses(
            &Vector3::zeros(),
            &kappa,
            &Vector2::new(10.0, 0.0),
            &mut out,
        );
        assert_relative_eq!(
            out[0].top.sigma[0],
            -out[0].bottom.sigma[0],
            max_relative = 1e-14
        );
        assert!(out[0].top.sigma[0] > 0.0);
        assert_relative_eq!(
            out[0].transverse_shear[0],
            1.5 * 10.0 / 2e-3,
            max_relative = 1e-12
        );
        assert_eq!(out[0].transverse_shear[1], 0.0);

        let shear = InPlaneStress::new(Vector3::new(0.0, 0.0, 5.0));
        assert_relative_eq!(shear.principal[0], 5.0, max_relative = 1e-15);
        assert_relative_eq!(shear.principal[1], -5.0, max_relative = 1e-15);
        assert_relative_eq!(
            shear.principal_angle,
            std::f64::consts::FRAC_PI_4,
            max_relative = 1e-15
        );
        assert_relative_eq!(shear.von_mises, 5.0 * 3f64.sqrt(), max_relative = 1e-15);
        // in the principal axes: (σ₁, σ₂, 0)
        let p = shear.in_axes(shear.principal_angle);
        assert_relative_eq!(p[0], 5.0, max_relative = 1e-14);
        assert_relative_eq!(p[1], -5.0, max_relative = 1e-14);
        assert!(p[2].abs() < 1e-14);
    }
}
