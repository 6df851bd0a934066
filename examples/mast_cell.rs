//! The folding of a triangular mast cell (Cardona, section 6.1): a
//! kinetostatic analysis, displacement controlled, of an articulated cell
//! of three longerons and three diagonals hinged at their mid-points,
//! between two triangles of battens.
//!
//! ```text
//! cargo run --release --example mast_cell -- [output directory] [increments] [--drive-top]
//! ```
//!
//! The program builds the model with the `unfold` API, writes it as a model
//! file, runs it, and writes, besides the usual result files, the moments
//! in the longerons along the fold (`longeron_moments.csv`, and their plot
//! `longeron_moments.svg` and `.png`). `examples/mast_cell.md` describes the model,
//! its dimensions and the choice of the hinge axes.
//!
//! In short:
//! - six corner bodies (rigid bodies); the battens are rigidly joined to
//!   them, the longerons and the diagonals by revolute joints; each
//!   diagonal has a revolute joint (knee) at its mid-point: 51 beams,
//!   6 rigid bodies and 15 revolute joints, as in the paper;
//! - every hinge axis is chosen so that the deployed configuration and a
//!   computed folded configuration are both compatible (stress-free):
//!   the axis of the rotation that takes one body to the other between the
//!   two configurations. In between the bars must bend and twist;
//! - the diagonals are pretensioned by a shortening (initial strain);
//! - stage (a), `0 ≤ t ≤ 1`: the knees are pushed inward, normal to the
//!   side faces, which unlocks the cell; stage (b), `1 ≤ t ≤ 2`: the knees
//!   go on inward along the path that straight bars would follow, and the
//!   top triangle comes down and turns until the cell is folded. With
//!   `--drive-top` the vertical displacement of the top corners is imposed
//!   too (the paper's control), which over-controls the cell (see
//!   `examples/mast_cell.md`).

use std::error::Error;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use unfold::analysis::{IncrementInfo, NoObserver, Observer, StaticAnalysis, StaticOutcome};
use unfold::elements::ElementKind;
use unfold::io::plot::{Axis, Chart, Series};
use unfold::io::run::{
    signal_name, stop_on_signals, Interrupted, Recorder, SignalEvent, Silent, StopRequest,
};
use unfold::model::builder::*;
use unfold::model::input::ModelInput;
use unfold::so3::{self, Rotation, Vec3};
use unfold::state::State;

/// A thin-walled circular tube.
#[derive(Clone, Copy, Debug)]
pub struct Tube {
    /// Young's modulus (Pa).
    pub e: f64,
    /// Shear modulus (Pa).
    pub g: f64,
    /// Outer diameter (m).
    pub diameter: f64,
    /// Wall thickness (m).
    pub wall: f64,
}

impl Tube {
    /// Cross-section area (m²).
    pub fn area(&self) -> f64 {
        let (ro, ri) = self.radii();
        PI * (ro * ro - ri * ri)
    }

    /// Second moment of area (m⁴).
    pub fn inertia(&self) -> f64 {
        let (ro, ri) = self.radii();
        PI / 4.0 * (ro.powi(4) - ri.powi(4))
    }

    fn radii(&self) -> (f64, f64) {
        let ro = self.diameter / 2.0;
        (ro, ro - self.wall)
    }

    /// The section: `EA`, `GA2 = GA3` with the shear factor 0.5 of a thin
    /// circular tube, `GJ = G·2I`, `EI2 = EI3`.
    pub fn section(&self) -> Section {
        let (a, i) = (self.area(), self.inertia());
        let ga = 0.5 * self.g * a;
        Section::diagonal(self.e * a, ga, ga, self.g * 2.0 * i, self.e * i, self.e * i)
    }
}

/// The design parameters of the cell.
#[derive(Clone, Debug)]
pub struct Design {
    /// Circumradius of the batten triangles (m).
    pub radius: f64,
    /// Height of the deployed cell = length of a longeron (m).
    pub height: f64,
    /// Height of the folded cell (m).
    pub folded_height: f64,
    /// Inward displacement of the knees that unlocks the cell, stage (a) (m).
    pub unlock: f64,
    /// Axial initial strain of the diagonals (negative: shortened).
    pub pretension_strain: f64,
    /// Longerons and diagonals.
    pub bar: Tube,
    /// Battens.
    pub batten: Tube,
    /// Mass (kg) and principal inertia (kg·m²) of a corner body.
    pub corner_mass: (f64, f64),
    /// Elements per longeron, per diagonal half, per batten.
    pub elements: (usize, usize, usize),
    /// Whether the vertical displacement of the top corners is imposed in
    /// stage (b) as well as the knees' (three more drivers).
    pub drive_top: bool,
    /// Whether the knee drivers are released at the end of stage (a), so
    /// that stage (b) is driven by the top alone (with `drive_top`): its
    /// three corners lowered and one corner turned about the axis (the
    /// paper's seven constraints in all).
    pub release_knees: bool,
}

impl Default for Design {
    fn default() -> Self {
        // carbon/epoxy tubes with axial and ±45° plies (assumed properties)
        let (e, g) = (100.0e9, 10.0e9);
        Self {
            radius: 0.5,
            height: 0.45,
            folded_height: 0.15,
            unlock: 0.02,
            pretension_strain: -1.0e-3,
            bar: Tube {
                e,
                g,
                diameter: 0.012,
                wall: 0.001,
            },
            batten: Tube {
                e,
                g,
                diameter: 0.020,
                wall: 0.0015,
            },
            corner_mass: (0.15, 1.5e-4),
            elements: (7, 3, 2),
            drive_top: false,
            release_knees: false,
        }
    }
}

/// The deployed and folded configurations and the hinge axes derived
/// from them. Index `k` = 0, 1, 2 runs over corners, longerons and side
/// faces; diagonal `k` runs from bottom corner `k` to top corner `k + 1`
/// in side face `k`.
#[derive(Clone, Debug)]
pub struct Geometry {
    /// Bottom corners.
    pub bottom: [Vec3; 3],
    /// Top corners, deployed.
    pub top: [Vec3; 3],
    /// Top corners, folded.
    pub top_folded: [Vec3; 3],
    /// Rotation of the top triangle about the vertical axis in the folded
    /// configuration (rad, negative: clockwise seen from above).
    pub twist: f64,
    /// Knees (mid-points of the diagonals), deployed.
    pub knee: [Vec3; 3],
    /// Knees, folded.
    pub knee_folded: [Vec3; 3],
    /// Inward normals of the side faces (horizontal unit vectors).
    pub inward: [Vec3; 3],
    /// Length of a diagonal.
    pub diagonal: f64,
    /// Hinge axes: longeron at its bottom and top ends, diagonal at its
    /// bottom end, knee and top end.
    pub axes: Axes,
}

/// Hinge axes (unit vectors, reference configuration) of each joint.
#[derive(Clone, Debug)]
pub struct Axes {
    /// Longeron k, bottom.
    pub longeron_bottom: [Vec3; 3],
    /// Longeron k, top.
    pub longeron_top: [Vec3; 3],
    /// Diagonal k, bottom.
    pub diagonal_bottom: [Vec3; 3],
    /// Diagonal k, knee.
    pub knee: [Vec3; 3],
    /// Diagonal k, top.
    pub diagonal_top: [Vec3; 3],
}

/// Angle of corner `k` about the vertical axis.
fn corner_angle(k: usize) -> f64 {
    2.0 * PI * k as f64 / 3.0
}

/// The axis of a revolute joint between bodies A and B that turn by `r_a`
/// and `r_b` from one configuration to the other: it keeps `R_A e = R_B e`,
/// so `e` is the axis of `R_Aᵀ R_B` (sign immaterial for a hinge).
fn hinge_axis(r_a: &Rotation, r_b: &Rotation) -> Vec3 {
    so3::log(&(r_a.inverse() * r_b)).normalize()
}

impl Design {
    /// Folded height reached when the top triangle has turned by `twist`
    /// with straight longerons: `h² + (2 r sin(ψ/2))² = L²`.
    pub fn height_at(&self, twist: f64) -> f64 {
        let chord = 2.0 * self.radius * (0.5 * twist).sin();
        (self.height * self.height - chord * chord).max(0.0).sqrt()
    }

    /// Twist of the folded configuration: negative, so that the diagonals
    /// (bottom corner k to top corner k + 1) shorten.
    pub fn folded_twist(&self) -> f64 {
        let (l, h) = (self.height, self.folded_height);
        let chord = (l * l - h * h).sqrt();
        -2.0 * (chord / (2.0 * self.radius)).asin()
    }

    /// Stress-free length of a diagonal half (shortened by the pretension
    /// strain).
    pub fn half_diagonal(&self) -> f64 {
        let r = self.radius;
        0.5 * (self.height * self.height + 3.0 * r * r).sqrt() * (1.0 + self.pretension_strain)
    }

    /// Knee positions when the top has turned by `twist` with straight
    /// longerons and straight stress-free diagonal halves: on the circle of
    /// points at a half length from both ends, towards the mast axis (at
    /// the chord's mid-point when the halves cannot reach).
    pub fn knees_at(&self, twist: f64) -> [Vec3; 3] {
        let h = self.height_at(twist);
        let half = self.half_diagonal();
        std::array::from_fn(|k| {
            let (a, b) = (corner_angle(k), corner_angle(k + 1) + twist);
            let p = Vec3::new(self.radius * a.cos(), self.radius * a.sin(), 0.0);
            let q = Vec3::new(self.radius * b.cos(), self.radius * b.sin(), h);
            let chord = q - p;
            let mid = 0.5 * (p + q);
            let u = chord.normalize();
            let towards_axis = Vec3::new(-mid.x, -mid.y, 0.0);
            let w = (towards_axis - u * u.dot(&towards_axis)).normalize();
            let rho = (half * half - 0.25 * chord.norm_squared()).max(0.0).sqrt();
            mid + w * rho
        })
    }

    /// Both configurations and the hinge axes.
    pub fn geometry(&self) -> Geometry {
        let (r, l) = (self.radius, self.height);
        let twist = self.folded_twist();
        let at = |angle: f64, z: f64| Vec3::new(r * angle.cos(), r * angle.sin(), z);
        let bottom: [Vec3; 3] = std::array::from_fn(|k| at(corner_angle(k), 0.0));
        let top: [Vec3; 3] = std::array::from_fn(|k| at(corner_angle(k), l));
        let top_folded: [Vec3; 3] =
            std::array::from_fn(|k| at(corner_angle(k) + twist, self.folded_height));
        let knee: [Vec3; 3] = std::array::from_fn(|k| 0.5 * (bottom[k] + top[(k + 1) % 3]));
        let diagonal = (top[1] - bottom[0]).norm();
        let knee_folded = self.knees_at(twist);
        let inward: [Vec3; 3] = std::array::from_fn(|k| {
            let a = corner_angle(k) + PI / 3.0;
            -Vec3::new(a.cos(), a.sin(), 0.0)
        });

        // rotation of every body from the deployed to the folded
        // configuration: the corner bodies stay, the top ones turn about
        // the vertical, the bars turn by the smallest rotation that aligns
        // them (no spin about their own axis)
        let (fixed, r_top) = (Rotation::identity(), so3::exp(&(Vec3::z() * twist)));
        let mut axes = Axes {
            longeron_bottom: [Vec3::zeros(); 3],
            longeron_top: [Vec3::zeros(); 3],
            diagonal_bottom: [Vec3::zeros(); 3],
            knee: [Vec3::zeros(); 3],
            diagonal_top: [Vec3::zeros(); 3],
        };
        for k in 0..3 {
            let k1 = (k + 1) % 3;
            let r_longeron =
                so3::rotation_between(&(top[k] - bottom[k]), &(top_folded[k] - bottom[k]));
            let r_lower =
                so3::rotation_between(&(knee[k] - bottom[k]), &(knee_folded[k] - bottom[k]));
            let r_upper =
                so3::rotation_between(&(top[k1] - knee[k]), &(top_folded[k1] - knee_folded[k]));
            axes.longeron_bottom[k] = hinge_axis(&fixed, &r_longeron);
            axes.longeron_top[k] = hinge_axis(&r_top, &r_longeron);
            axes.diagonal_bottom[k] = hinge_axis(&fixed, &r_lower);
            axes.knee[k] = hinge_axis(&r_lower, &r_upper);
            axes.diagonal_top[k] = hinge_axis(&r_top, &r_upper);
        }
        Geometry {
            bottom,
            top,
            top_folded,
            twist,
            knee,
            knee_folded,
            inward,
            diagonal,
            axes,
        }
    }
}

// ---------- the model ----------

/// The parts of the cell that drivers and results refer to.
#[derive(Clone, Debug)]
pub struct Parts {
    /// Corner nodes of the bottom triangle, each carrying a corner body.
    pub bottom: [NodeHandle; 3],
    /// Corner nodes of the top triangle, each carrying a corner body.
    pub top: [NodeHandle; 3],
    /// The knee of each diagonal: the end node of its lower half.
    pub knees: [NodeHandle; 3],
    /// Elements of each longeron, from the bottom up.
    pub longerons: [Vec<BeamHandle>; 3],
    /// Elements of each diagonal: its lower half from the bottom, then its
    /// upper half from the knee.
    pub diagonals: [Vec<BeamHandle>; 3],
    /// The drivers pushing the knees inward (none in the cell alone).
    pub knee_drivers: Vec<DriverHandle>,
}

/// A model of the cell: its definition, and the parts it is read by.
#[derive(Clone, Debug)]
pub struct Cell {
    /// The model definition (written as `mast_cell.toml`).
    pub input: ModelInput,
    /// Its parts.
    pub parts: Parts,
}

/// Points of the piecewise-linear stage (b) curves.
const CURVE_POINTS: usize = 80;

/// The cell without drivers: bars, corner bodies, hinges, supports and
/// the pretension of the diagonals.
pub fn cell(d: &Design) -> (ModelBuilder, Parts) {
    let g = d.geometry();
    let mut m = ModelBuilder::new(format!(
        "Folding of a triangular mast cell: r = {} m, L = {} m, folded to {} m",
        d.radius, d.height, d.folded_height
    ));
    m.analysis(Analysis::kinetostatic());
    let bar = m.section(d.bar.section().named("bar"));
    let batten = m.section(d.batten.section().named("batten"));

    // corners
    let corners: [[NodeHandle; 2]; 3] =
        std::array::from_fn(|k| [m.node(g.bottom[k]), m.node(g.top[k])]);
    let (bottom, top) = (corners.map(|c| c[0]), corners.map(|c| c[1]));

    // every bar has end nodes of its own, at the corners and at the knees,
    // hinged there
    let mut longeron = Vec::new();
    let mut diagonal = Vec::new();
    for k in 0..3 {
        longeron.push([m.node(g.bottom[k]), m.node(g.top[k])]);
        diagonal.push([
            m.node(g.bottom[k]),
            m.node(g.knee[k]),
            m.node(g.knee[k]),
            m.node(g.top[(k + 1) % 3]),
        ]);
    }

    // bars: longerons, diagonals in two halves shortened for the
    // pretension; the battens join the corners rigidly
    let (nl, nd, nb) = d.elements;
    let longerons = std::array::from_fn(|k| m.beam_line(longeron[k][0], longeron[k][1], nl, bar));
    let diagonals = std::array::from_fn(|k| {
        let [lower_end, knee_lower, knee_upper, upper_end] = diagonal[k];
        [[lower_end, knee_lower], [knee_upper, upper_end]]
            .into_iter()
            .flat_map(|[a, b]| {
                m.add(BeamLine::between(a, b, nd, bar).axial_strain(d.pretension_strain))
                    .elements
            })
            .collect()
    });
    for level in [bottom, top] {
        for k in 0..3 {
            m.beam_line(level[k], level[(k + 1) % 3], nb, batten);
        }
    }

    // corner bodies; the bottom ones are clamped
    let (mass, inertia) = d.corner_mass;
    for node in bottom.into_iter().chain(top) {
        m.add(RigidBody::at(node, mass).inertia([inertia; 3]));
    }
    for node in bottom {
        m.fix(node, Dofs::ALL);
    }

    // revolute joints: 2 per longeron, 3 per diagonal, at the node of their
    // first body
    let axes = &g.axes;
    for k in 0..3 {
        let [lower_end, upper_end] = longeron[k];
        m.add(Joint::revolute(bottom[k], lower_end).axis(axes.longeron_bottom[k]));
        m.add(Joint::revolute(top[k], upper_end).axis(axes.longeron_top[k]));
    }
    for k in 0..3 {
        let [lower_end, knee_lower, knee_upper, upper_end] = diagonal[k];
        m.add(Joint::revolute(bottom[k], lower_end).axis(axes.diagonal_bottom[k]));
        m.add(Joint::revolute(knee_lower, knee_upper).axis(axes.knee[k]));
        m.add(Joint::revolute(top[(k + 1) % 3], upper_end).axis(axes.diagonal_top[k]));
    }
    let parts = Parts {
        bottom,
        top,
        knees: std::array::from_fn(|k| diagonal[k][1]),
        longerons: longerons.map(|l: BeamLineHandle| l.elements),
        diagonals,
        knee_drivers: Vec::new(),
    };
    (m, parts)
}

/// The pretensioned configuration after assembly, before any driver acts
/// (the paper's fig. 3-a): the shortened diagonals pull the top triangle
/// down and turn it slightly.
#[derive(Clone, Debug, PartialEq)]
pub struct Assembly {
    /// Vertical displacement of the top corners (m).
    pub top_drop: f64,
    /// Inward displacement of the knees (m).
    pub knee_inward: f64,
}

/// Solves the equilibrium of the [`cell`] without drivers.
pub fn assemble(d: &Design) -> Result<Assembly, Box<dyn Error>> {
    let g = d.geometry();
    let (mut m, parts) = cell(d);
    // nothing depends on t: the equilibrium at t = 0 and one trivial increment
    m.analysis(Analysis::kinetostatic().initial_increment(1.0));
    let model = Arc::new(m.build()?);
    let settings = m.analyses()?.remove(0);
    let settings = settings.as_static().ok_or("a static analysis")?.clone();
    let outcome =
        StaticAnalysis::new(model.clone(), settings).run(model.initial_state(), &mut NoObserver);
    if let Some(e) = outcome.error {
        return Err(format!("assembly of the pretensioned cell: {e}").into());
    }
    let displacement = |node: NodeHandle| {
        let i = model.node(node);
        outcome.state.x[i] - model.reference_x[i]
    };
    Ok(Assembly {
        top_drop: displacement(parts.top[0]).z,
        knee_inward: displacement(parts.knees[0]).dot(&g.inward[0]),
    })
}

/// Builds the model with the default design, with the analysis divided
/// into `increments` equal increments (the solver cuts them back if
/// needed), half for each stage.
pub fn build(increments: usize) -> Cell {
    build_design(&Design::default(), increments).expect("the default design assembles")
}

/// Builds the model of `design`: the [`cell`], its drivers and the
/// analysis settings. The drivers start from the [`assemble`]d
/// configuration, so that at `t = 0` they carry no load and the pretension
/// is balanced inside the cell.
pub fn build_design(d: &Design, increments: usize) -> Result<Cell, Box<dyn Error>> {
    let g = d.geometry();
    let a = assemble(d)?;
    let (mut m, mut parts) = cell(d);
    let step = 2.0 / increments.max(1) as f64;
    m.analysis(
        Analysis::kinetostatic()
            .end_time(2.0)
            .initial_increment(step)
            .max_increment(step)
            .min_increment(step * 1e-4),
    );

    // Knees: stage (a) pushes them inward by `unlock` from where the
    // assembly put them; stage (b) moves them as straight bars would when
    // the top turns by ψ = ψ_f s² at t = 1 + s, i.e. ψ grows about linearly
    // with t (the knee moves as √|ψ| at first, hence the points crowded at
    // the start).
    let knee_final = (g.knee_folded[0] - g.knee[0]).dot(&g.inward[0]);
    let knee_unlocked = a.knee_inward + d.unlock;
    let mut push = vec![
        [0.0, a.knee_inward / knee_final],
        [1.0, knee_unlocked / knee_final],
    ];
    // Top corners (`drive_top` only): the height of straight longerons
    // when the top has turned by ψ_f s at t = 1 + s.
    let drop = d.folded_height - d.height;
    let mut lower = vec![[0.0, a.top_drop / drop], [1.0, a.top_drop / drop]];
    for i in 1..=CURVE_POINTS {
        let s = i as f64 / CURVE_POINTS as f64;
        let knee = d.knees_at(g.twist * s * s)[0];
        let inward = (knee - g.knee[0]).dot(&g.inward[0]).max(knee_unlocked);
        push.push([1.0 + s * s, inward / knee_final]);
        let u = d.height_at(g.twist * s) - d.height + a.top_drop * (1.0 - s);
        lower.push([1.0 + s, u / drop]);
    }
    let push = m.curve(LoadCurve::points(push).named("push_knees"));
    for k in 0..3 {
        let mut driver = Driver::translation(parts.knees[k], g.inward[k])
            .value(knee_final)
            .curve(push);
        if d.release_knees {
            driver = driver.active(0.0, 1.0);
        }
        parts.knee_drivers.push(m.add(driver));
    }
    if d.drive_top {
        let lower = m.curve(LoadCurve::points(lower).named("lower_top"));
        for k in 0..3 {
            let mut driver = Driver::translation(parts.top[k], [0.0, 0.0, 1.0])
                .value(drop)
                .curve(lower);
            if d.release_knees {
                driver = driver.active(1.0, f64::INFINITY);
            }
            m.add(driver);
        }
        if d.release_knees {
            // the seventh constraint: the top's rotation about the axis,
            // as the straight longerons would turn it
            let turn = m.curve(LoadCurve::points([[1.0, 0.0], [2.0, 1.0]]).named("turn_top"));
            m.add(
                Driver::rotation(parts.top[0], [0.0, 0.0, 1.0])
                    .value(g.twist)
                    .curve(turn)
                    .active(1.0, 1.9),
            );
        }
    }
    Ok(Cell {
        input: m.into_input(),
        parts,
    })
}

// ---------- results along the fold ----------

/// Section forces of a member at one converged increment.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MemberForces {
    /// Axial force of each element (N).
    pub axial: Vec<f64>,
    /// Bending moment `√(M2² + M3²)` of each element (N·m).
    pub bending: Vec<f64>,
    /// Torsion `T` of each element (N·m).
    pub torsion: Vec<f64>,
}

impl MemberForces {
    fn max_abs(v: &[f64]) -> f64 {
        v.iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    /// Largest bending moment along the member.
    pub fn max_bending(&self) -> f64 {
        Self::max_abs(&self.bending)
    }

    /// Largest torsion (absolute value) along the member.
    pub fn max_torsion(&self) -> f64 {
        Self::max_abs(&self.torsion)
    }
}

/// What is recorded at each converged increment.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Increment (0: the pretensioned equilibrium at `t = 0`).
    pub increment: usize,
    /// Load parameter: stage (a) for `t ≤ 1`, stage (b) after.
    pub time: f64,
    /// Newton iterations of the increment.
    pub iterations: usize,
    /// Vertical displacement of each top corner (m).
    pub top_drop: [f64; 3],
    /// Rotation of the top triangle about the vertical (rad).
    pub twist: f64,
    /// Inward displacement of each knee (m).
    pub knee_inward: [f64; 3],
    /// Force each knee driver applies along the inward normal (N).
    pub knee_load: [f64; 3],
    /// Longerons (elements from the bottom up).
    pub longerons: [MemberForces; 3],
    /// Diagonals (lower half from the bottom, then upper half from the
    /// knee).
    pub diagonals: [MemberForces; 3],
}

/// Wraps the run's recorder and records the forces in the bars.
struct FoldObserver {
    recorder: Option<Recorder>,
    design: Design,
    parts: Parts,
    records: Vec<Record>,
    log: bool,
}

fn member(model: &Model, state: &State, beams: &[BeamHandle]) -> MemberForces {
    let mut f = MemberForces::default();
    for &beam in beams {
        let s = model.section_forces(beam, state);
        f.axial.push(s.force.x);
        f.torsion.push(s.moment.x);
        f.bending.push(s.moment.y.hypot(s.moment.z));
    }
    f
}

impl Observer for FoldObserver {
    fn iteration(&mut self, info: &unfold::analysis::IterationInfo) {
        if let Some(r) = self.recorder.as_mut() {
            r.iteration(info);
        }
    }

    fn cutback(&mut self, info: &unfold::analysis::CutbackInfo) {
        if let Some(r) = self.recorder.as_mut() {
            r.cutback(info);
        }
    }

    fn note(&mut self, text: &str) {
        if let Some(r) = self.recorder.as_mut() {
            r.note(text);
        }
    }

    fn increment(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        residual: &[f64],
    ) -> std::io::Result<()> {
        let (g, p) = (self.design.geometry(), &self.parts);
        let displacement = |node: NodeHandle| {
            let i = model.node(node);
            state.x[i] - model.reference_x[i]
        };
        let r = so3::matrix(&state.q[model.node(p.top[0])]);
        let record = Record {
            increment: info.increment,
            time: info.time,
            iterations: info.iterations,
            top_drop: std::array::from_fn(|k| displacement(p.top[k]).z),
            twist: r[(1, 0)].atan2(r[(0, 0)]),
            knee_inward: std::array::from_fn(|k| displacement(p.knees[k]).dot(&g.inward[k])),
            knee_load: std::array::from_fn(|k| {
                let load = model.results(p.knee_drivers[k], state).get("load");
                load.expect("a driver's load")
            }),
            longerons: std::array::from_fn(|k| member(model, state, &p.longerons[k])),
            diagonals: std::array::from_fn(|k| member(model, state, &p.diagonals[k])),
        };
        if self.log {
            println!(
                "increment {:3}  t = {:.4}  iterations {:2}  top {:8.4} m  twist {:7.2}°  knee {:7.4} m  longeron: bending {:6.2} N·m, torsion {:5.2} N·m",
                info.increment,
                info.time,
                info.iterations,
                record.top_drop[0],
                record.twist.to_degrees(),
                record.knee_inward[0],
                record.longerons[0].max_bending(),
                record.longerons[0].max_torsion(),
            );
        }
        self.records.push(record);
        match self.recorder.as_mut() {
            Some(r) => r.increment(info, model, state, residual),
            None => Ok(()),
        }
    }
}

/// Counts of the model and of the run.
#[derive(Clone, Debug)]
pub struct Figures {
    /// Beam elements.
    pub beams: usize,
    /// Rigid bodies.
    pub rigid_bodies: usize,
    /// Joints.
    pub joints: usize,
    /// Drivers.
    pub drivers: usize,
    /// Nodes.
    pub nodes: usize,
    /// Free unknowns (including multipliers).
    pub unknowns: usize,
    /// Constraint equations found redundant and left out.
    pub redundant_constraints: usize,
    /// Converged increments (initial equilibrium excluded).
    pub increments: usize,
    /// Newton iterations per increment (initial equilibrium excluded).
    pub iterations_per_increment: f64,
    /// Newton iterations per increment of stage (b).
    pub iterations_per_fold_increment: f64,
    /// Cut-backs.
    pub cutbacks: usize,
    /// Wall time of the analysis (s).
    pub wall_time: f64,
}

/// The outcome of a run.
pub struct Run {
    /// Every converged increment.
    pub records: Vec<Record>,
    /// Counts and timings.
    pub figures: Figures,
    /// The analysis outcome (final state, error if it stopped early).
    pub outcome: StaticOutcome,
}

/// Runs the `cell` built from `design`; with `out`, writes the result
/// files there (VTK, CSV, `log.txt`, `summary.json`, the longeron moments
/// and their plot). With `log`, prints a line per increment.
pub fn run(
    design: &Design,
    cell: &Cell,
    out: Option<&Path>,
    log: bool,
) -> Result<Run, Box<dyn Error>> {
    run_until(design, cell, out, log, &StopRequest::new())
}

/// [`run`], stopping after the increment during which `stop` is
/// requested.
pub fn run_until(
    design: &Design,
    cell: &Cell,
    out: Option<&Path>,
    log: bool,
    stop: &StopRequest,
) -> Result<Run, Box<dyn Error>> {
    let model = Arc::new(Model::from_input(&cell.input)?);
    let settings = cell.input.analyses()?.remove(0);
    let settings = settings.as_static().ok_or("a static analysis")?.clone();
    let mut analysis = StaticAnalysis::new(model.clone(), settings);
    let recorder = match out {
        Some(dir) => {
            let file = dir.join("mast_cell.toml").display().to_string();
            Some(Recorder::create(dir, &file, &analysis, Silent)?.with_stop(stop))
        }
        None => None,
    };
    let mut observer = FoldObserver {
        recorder,
        design: design.clone(),
        parts: cell.parts.clone(),
        records: Vec::new(),
        log,
    };
    let outcome = analysis.run(model.initial_state(), &mut observer);
    let records = observer.records;
    let count = |k: ElementKind| model.elements.iter().filter(|e| e.kind() == k).count();
    let average = |r: &mut dyn Iterator<Item = &Record>| {
        let (n, sum) = r.fold((0, 0), |(n, s), r| (n + 1, s + r.iterations));
        if n > 0 {
            sum as f64 / n as f64
        } else {
            0.0
        }
    };
    let figures = Figures {
        beams: count(ElementKind::Beam),
        rigid_bodies: count(ElementKind::RigidBody),
        joints: count(ElementKind::Joint),
        drivers: count(ElementKind::Driver),
        nodes: model.n_nodes(),
        unknowns: analysis.n_equations(),
        redundant_constraints: outcome.redundant_constraints,
        increments: outcome.increments,
        iterations_per_increment: average(&mut records.iter().skip(1)),
        iterations_per_fold_increment: average(&mut records.iter().filter(|r| r.time > 1.0)),
        cutbacks: outcome.cutbacks,
        wall_time: outcome.wall_time,
    };
    if let (Some(recorder), Some(dir)) = (observer.recorder, out) {
        let report = recorder.finish(&outcome);
        if let Some(e) = report.output_errors.into_iter().next() {
            return Err(e.into());
        }
        write_moments(dir, &records)?;
    }
    Ok(Run {
        records,
        figures,
        outcome,
    })
}

/// Writes `longeron_moments.csv` and `longeron_moments.svg`: for each
/// converged increment, the bending moment and the torsion in the
/// longerons at the element next to the bottom hinge and the largest along
/// them (largest of the three longerons, which are equal by symmetry).
fn write_moments(dir: &Path, records: &[Record]) -> Result<(), Box<dyn Error>> {
    use std::fmt::Write as _;
    let mut csv = String::from(
        "increment,t,top_displacement_m,twist_deg,knee_inward_m,knee_driver_load_N,\
         bending_bottom_Nm,torsion_bottom_Nm,bending_max_Nm,torsion_max_Nm,\
         longeron_axial_N,diagonal_axial_N\n",
    );
    let largest = |f: &dyn Fn(&MemberForces) -> f64, m: &[MemberForces; 3]| {
        m.iter().map(f).fold(0.0, f64::max)
    };
    let mut series: [Vec<(f64, f64)>; 4] = Default::default();
    for r in records {
        let values = [
            largest(&|m| m.bending[0], &r.longerons),
            largest(&|m| m.torsion[0].abs(), &r.longerons),
            largest(&|m| m.max_bending(), &r.longerons),
            largest(&|m| m.max_torsion(), &r.longerons),
        ];
        writeln!(
            csv,
            "{},{:.6},{:.6e},{:.4},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}",
            r.increment,
            r.time,
            r.top_drop[0],
            r.twist.to_degrees(),
            r.knee_inward[0],
            r.knee_load[0],
            values[0],
            values[1],
            values[2],
            values[3],
            r.longerons[0].axial[0],
            r.diagonals[0].axial[0],
        )?;
        for (s, v) in series.iter_mut().zip(values) {
            s.push((r.time, v));
        }
    }
    std::fs::write(dir.join("longeron_moments.csv"), csv)?;
    let [bottom_m, bottom_t, max_m, max_t] = series;
    let chart = Chart::new(
        "Mast cell: moments in the longerons",
        Axis::dimensionless("load parameter t: (a) unlocking t ≤ 1, (b) folding t ≥ 1"),
        Axis::new("moment", "N·m"),
    )
    .series(Series::new("bending, next to the bottom hinge", bottom_m))
    .series(Series::new("torsion, next to the bottom hinge", bottom_t))
    .series(Series::new("bending, largest along the longeron", max_m))
    .series(Series::new("torsion, largest along the longeron", max_t))
    .event(1.0, "(a) → (b)");
    chart.write_svg(&dir.join("longeron_moments.svg"))?;
    chart.write_png(&dir.join("longeron_moments.png"))?;
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    let mut design = Design::default();
    let mut positional = Vec::new();
    for a in std::env::args().skip(1) {
        if a == "--drive-top" {
            design.drive_top = true;
        } else if a == "--lower-top" {
            design.drive_top = true;
            design.release_knees = true;
        } else {
            positional.push(a);
        }
    }
    let out = PathBuf::from(
        positional
            .first()
            .map_or("results/mast_cell", |s| s.as_str()),
    );
    let increments: usize = match positional.get(1) {
        None => 96,
        Some(a) => match a.parse::<usize>() {
            Ok(n) if n > 0 => n,
            _ => {
                eprintln!("error: INCREMENTS must be a positive whole number, got \"{a}\"\nusage: cargo run --release --example mast_cell -- [OUTPUT_DIRECTORY] [INCREMENTS] [--drive-top | --lower-top]");
                std::process::exit(2);
            }
        },
    };

    let start = Instant::now();
    let cell = build_design(&design, increments)?;
    std::fs::create_dir_all(&out)?;
    let file = out.join("mast_cell.toml");
    std::fs::write(&file, cell.input.to_toml()?)?;
    println!("model written to {}", file.display());

    // SIGINT, SIGTERM: stop after the current increment, results kept
    let stop = StopRequest::new();
    stop_on_signals(&stop, |event| match event {
        SignalEvent::Stopping(s) => eprintln!(
            "{}: stopping after the current increment (again to stop at once)",
            signal_name(s)
        ),
        SignalEvent::Ending(s) => eprintln!("{}: stopping at once", signal_name(s)),
    })?;
    let run = run_until(&design, &cell, Some(&out), true, &stop)?;
    let f = &run.figures;
    println!(
        "{} elements: {} beams, {} rigid bodies, {} revolute joints; {} drivers; {} nodes; {} unknowns ({} redundant constraint equations)",
        f.beams + f.rigid_bodies + f.joints,
        f.beams,
        f.rigid_bodies,
        f.joints,
        f.drivers,
        f.nodes,
        f.unknowns,
        f.redundant_constraints,
    );
    println!(
        "{} increments, {:.2} iterations per increment ({:.2} in stage (b)), {} cut-backs; analysis {:.3} s, total {:.3} s",
        f.increments,
        f.iterations_per_increment,
        f.iterations_per_fold_increment,
        f.cutbacks,
        f.wall_time,
        start.elapsed().as_secs_f64(),
    );
    let peak = |g: &dyn Fn(&Record) -> f64| {
        run.records
            .iter()
            .map(|r| (g(r), r.time))
            .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
    };
    let bending = |r: &Record| {
        r.longerons
            .iter()
            .map(MemberForces::max_bending)
            .fold(0.0, f64::max)
    };
    let torsion = |r: &Record| {
        r.longerons
            .iter()
            .map(MemberForces::max_torsion)
            .fold(0.0, f64::max)
    };
    let (first, last) = (&run.records[0], run.records.last().expect("increment 0"));
    println!(
        "pretension at t = 0: diagonals {:.3} N, longerons {:.3} N",
        first.diagonals[0].axial[0], first.longerons[0].axial[0]
    );
    let (pb, tb) = peak(&bending);
    let (pt, tt) = peak(&torsion);
    println!(
        "longerons: bending {:.2} N·m at t = {:.3} (final {:.2e}), torsion {:.2} N·m at t = {:.3} (final {:.2e}); top displacement {:.4} m, twist {:.2}°",
        pb,
        tb,
        bending(last),
        pt,
        tt,
        torsion(last),
        last.top_drop[0],
        last.twist.to_degrees()
    );
    println!("results in {}", out.display());
    if let Some(e) = run.outcome.error {
        if let Some(i) = Interrupted::of(&e) {
            eprintln!(
                "{i} at t = {}; results up to it are kept",
                unfold::io::run::format_time(run.outcome.time)
            );
            std::process::exit(i.exit_code().into());
        }
        return Err(e.into());
    }
    Ok(())
}
