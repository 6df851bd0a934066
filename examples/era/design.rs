//! The design parameters of the ERA cell: dimensions, tubes, fittings,
//! mesh and the mid-hinge springs. Every value is an assumption for a
//! cell of about 1 m (the paper gives none); `examples/era.md` says how
//! each was chosen.

use std::f64::consts::PI;

use unfold::model::builder::Section;

/// A thin-walled circular tube of carbon-fibre reinforced plastic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tube {
    /// Axial Young's modulus (Pa).
    pub e: f64,
    /// Shear modulus (Pa).
    pub g: f64,
    /// Density (kg/m³).
    pub density: f64,
    /// Outer diameter (m).
    pub diameter: f64,
    /// Wall thickness (m).
    pub wall: f64,
}

impl Tube {
    /// A tube of the laminate of [`Design::default`] (`E = 110 GPa`,
    /// `G = 12 GPa`, `ρ = 1,600 kg/m³`).
    pub fn carbon(diameter: f64, wall: f64) -> Self {
        Self {
            e: 110.0e9,
            g: 12.0e9,
            density: 1600.0,
            diameter,
            wall,
        }
    }

    fn radii(&self) -> (f64, f64) {
        let ro = 0.5 * self.diameter;
        (ro, ro - self.wall)
    }

    /// Cross-section area `A = π (r_o² − r_i²)` (m²).
    pub fn area(&self) -> f64 {
        let (ro, ri) = self.radii();
        PI * (ro * ro - ri * ri)
    }

    /// Second moment of area `I = π (r_o⁴ − r_i⁴) / 4` (m⁴); the polar
    /// moment is `2I`.
    pub fn inertia(&self) -> f64 {
        let (ro, ri) = self.radii();
        0.25 * PI * (ro.powi(4) - ri.powi(4))
    }

    /// Mass per length `ρA` (kg/m).
    pub fn mass_per_length(&self) -> f64 {
        self.density * self.area()
    }

    /// The section: `EA`; `GA₂ = GA₃ = ½ G A` (shear factor 1/2 of a
    /// thin circular tube); `GJ = G·2I`; `EI₂ = EI₃ = E I`; mass `ρA` and
    /// rotational inertia per length `(ρ·2I, ρI, ρI)`.
    pub fn section(&self) -> Section {
        let (a, i) = (self.area(), self.inertia());
        let ga = 0.5 * self.g * a;
        let rho = self.density;
        Section::diagonal(self.e * a, ga, ga, self.g * 2.0 * i, self.e * i, self.e * i)
            .mass_per_length(rho * a)
            .inertia_per_length([rho * 2.0 * i, rho * i, rho * i])
    }

    /// Mass of a member of length `length` (kg).
    pub fn mass(&self, length: f64) -> f64 {
        self.mass_per_length() * length
    }
}

/// An aluminium fitting modelled as a rigid body: a solid cylinder about
/// the vertical (the mass and inertia of a machined part of that size).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fitting {
    /// Mass (kg).
    pub mass: f64,
    /// Radius of the equivalent cylinder (m).
    pub radius: f64,
    /// Height of the equivalent cylinder (m).
    pub height: f64,
}

impl Fitting {
    /// Principal moments of inertia about the centre, axes x, y, z
    /// (kg·m²): `m(3R² + H²)/12` about the horizontal axes, `mR²/2` about
    /// the vertical.
    pub fn inertia(&self) -> [f64; 3] {
        let (m, r, h) = (self.mass, self.radius, self.height);
        let horizontal = m * (3.0 * r * r + h * h) / 12.0;
        [horizontal, horizontal, 0.5 * m * r * r]
    }
}

/// The mid-hinge torsion springs: tape-spring hinges, whose moment
/// against the hinge's opening angle follows the tape-spring shape of
/// docs/joints.md §4.1 (deployment moment over the travel, a stiff locked
/// branch from the locking angle on, a locking peak that must be overcome
/// to fold the locked hinge again, hysteresis between them), and a latch
/// that locks the hinge rigidly at the end of its travel (docs/joints.md
/// §6.2), the halves in line (`γ = π`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HingeLaw {
    /// `M_d`: moment that opens the hinge over its travel (N·m).
    pub deployment_moment: f64,
    /// `M_L`: moment that folds the locked hinge again (N·m).
    pub locking_peak: f64,
    /// `K`: slope of the locked branch (N·m/rad).
    pub locked_stiffness: f64,
    /// `w`: width over which the moment falls from `M_L` back to `M_d`
    /// when the hinge is folded past its peak (rad).
    pub snap_width: f64,
    /// `k_e`: slope of the moment between the bounds of the hysteresis
    /// (N·m/rad), steeper than `K` and `(M_L − M_d)/w`.
    pub elastic_slope: f64,
}

impl HingeLaw {
    /// The energy the spring gives the structure as the hinge opens by
    /// `travel` (rad) up to the lock: `M_d` over the travel less the
    /// locked branch's `M_d²/(2K)` (J).
    pub fn deployment_energy(&self, travel: f64) -> f64 {
        self.deployment_moment * travel
            - 0.5 * self.deployment_moment.powi(2) / self.locked_stiffness
    }
}

/// Elements per member.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mesh {
    /// Beam elements per longeron.
    pub longeron: usize,
    /// Beam elements per half of a horizontal.
    pub half_horizontal: usize,
    /// Beam elements per diagonal.
    pub diagonal: usize,
}

/// The design of a cell (and of the platform, whose cells are equal).
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// Distance between the longeron axes of a cell, deployed (m).
    pub side: f64,
    /// Height of a cell: length of a longeron between the centres of its
    /// corner bodies (m).
    pub height: f64,
    /// Distance of the hinge points (clevises) from the longeron axis (m).
    pub clevis_radius: f64,
    /// Height of the diagonals' clevises above the bottom corner body's
    /// centre (m).
    pub diagonal_clevis_height: f64,
    /// Scale of the column layout when folded: the longerons stand at this
    /// fraction of their deployed distances from the centre.
    pub folded_scale: f64,
    /// Longerons.
    pub longeron: Tube,
    /// Horizontals (top and bottom).
    pub horizontal: Tube,
    /// Diagonals.
    pub diagonal: Tube,
    /// Corner body: mass of the body itself (kg) ...
    pub corner_base_mass: f64,
    /// ... plus this mass per clevis it carries (kg).
    pub clevis_mass: f64,
    /// Radius and height of the corner body's equivalent cylinder (m).
    pub corner_size: (f64, f64),
    /// The fitting of a mid-hinge (torsion spring, latch, clevis).
    pub mid_hinge: Fitting,
    /// Extra mass of a top mid-hinge fitting, which also carries the two
    /// diagonals' clevises (kg).
    pub mid_hinge_diagonal_mass: f64,
    /// Elements per member.
    pub mesh: Mesh,
    /// The mid-hinge springs and latches.
    pub hinge: HingeLaw,
    /// Stiffness-proportional Rayleigh damping of the members, `β` (s):
    /// `ζ = β ω / 2` in each mode of the locked structure.
    pub rayleigh_beta: f64,
}

impl Default for Design {
    fn default() -> Self {
        Self {
            side: 1.0,
            height: 1.0,
            clevis_radius: 0.06,
            diagonal_clevis_height: 0.04,
            folded_scale: 0.2,
            longeron: Tube::carbon(0.025, 0.0015),
            horizontal: Tube::carbon(0.020, 0.0010),
            diagonal: Tube::carbon(0.016, 0.0010),
            corner_base_mass: 0.08,
            clevis_mass: 0.02,
            corner_size: (0.07, 0.06),
            mid_hinge: Fitting {
                mass: 0.06,
                radius: 0.02,
                height: 0.04,
            },
            mid_hinge_diagonal_mass: 0.02,
            mesh: Mesh {
                longeron: 4,
                half_horizontal: 2,
                diagonal: 3,
            },
            hinge: HingeLaw {
                deployment_moment: 0.2,
                locking_peak: 10.0,
                locked_stiffness: 200.0,
                snap_width: 5.0f64.to_radians(),
                elastic_slope: 400.0,
            },
            rayleigh_beta: 0.0,
        }
    }
}

impl Design {
    /// The corner body carrying `clevises` clevises.
    pub fn corner_body(&self, clevises: usize) -> Fitting {
        Fitting {
            mass: self.corner_base_mass + self.clevis_mass * clevises as f64,
            radius: self.corner_size.0,
            height: self.corner_size.1,
        }
    }

    /// The fitting of a top mid-hinge (with the diagonals' clevises) or of
    /// a bottom one.
    pub fn mid_hinge_fitting(&self, top: bool) -> Fitting {
        let mut f = self.mid_hinge;
        if top {
            f.mass += self.mid_hinge_diagonal_mass;
        }
        f
    }
}
