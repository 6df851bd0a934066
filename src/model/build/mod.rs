//! Validation of a [`ModelInput`] and construction of the [`Model`].
//!
//! The input is checked in the order of the file's tables; every problem
//! is collected (none stops the others from being found) and each is
//! reported once, at the entity where it is written: an invalid curve,
//! node, section or joint is not reported again by the entities referring
//! to it. Sizes are checked before anything is allocated (the limits of
//! docs/model-format.md, "Limits").

use crate::io::number::plain as num;
use std::collections::{HashMap, HashSet};

mod beams;
mod checks;
mod contacts;
mod curves;
mod drivers;
mod hinge_laws;
mod initial;
mod joint_springs;
mod joints;
mod latches;
mod loads;
mod masses;
mod nodes;
mod output;
mod rolling;
mod sections;
mod settings;
mod shells;
mod springs;
mod stops;
mod superelements;
mod supports;

use super::input::*;
use super::{Model, ModelError, ModelErrorKind, ModelErrors, ModelWarning, Prescribed};
use crate::curves::CurveIndex;
use crate::elements::beam::BeamSection;
use crate::elements::{Element, ElementKind};
use crate::so3::{Rotation, Vec3};
use beams::BeamSpec;
use curves::{CurveTable, CONSTANT, RAMP};

/// Most elements one `beam_lines` entry may generate.
pub const MAX_LINE_ELEMENTS: usize = 100_000;

/// Most nodes and elements of a model, together (given and generated). A
/// model of this size needs about 2 GB to check (measured: 1.5 GB and 9 s
/// for 200 000 beams); the largest structures of the field (a deployable
/// truss of thousands of cells) are far below.
pub const MAX_MODEL_SIZE: usize = 500_000;

/// Most increments an analysis may need, `end_time / max_increment`.
pub const MAX_INCREMENTS: f64 = 1e6;

/// Most Newton iterations per increment (`max_iterations`) and
/// arc-length increments (`max_increments`, as [`MAX_INCREMENTS`]).
pub const MAX_ITERATIONS: usize = 1000;

/// Smallest `min_increment`, relative to `end_time`: below it an increment
/// is lost in the round-off of `t`, and cut-backs could go on ~1000 times.
pub const MIN_RELATIVE_INCREMENT: f64 = 1e-12;

/// Largest force or stiffness an element may give in the reference
/// configuration: the analysis measures residuals by sums of squares,
/// which overflow beyond 1.3e154.
pub const LARGEST_ELEMENT_VALUE: f64 = 1e150;

/// Relative margin above half or a whole turn before an angle without a
/// unit is warned about, so that π and 2π written to a few digits
/// (3.1416, 6.2832) pass.
const ANGLE_SLACK: f64 = 1e-3;

/// How large an angle written without a unit may be before it looks like
/// degrees: a rotation vector is at most half a turn long; a driven
/// angle, a spring's free angle or a table's angle rarely pass a full
/// turn.
#[derive(Clone, Copy)]
enum AngleLimit {
    HalfTurn,
    FullTurn,
}

/// Collects problems and warnings while the model is built.
#[derive(Default)]
struct Checker {
    errors: Vec<ModelError>,
    warnings: Vec<ModelWarning>,
    notes: Vec<ModelWarning>,
}

impl Checker {
    fn push(
        &mut self,
        kind: ModelErrorKind,
        entity: impl Into<String>,
        message: impl Into<String>,
    ) {
        self.errors.push(ModelError {
            kind,
            entity: entity.into(),
            message: message.into(),
        });
    }

    fn warn(&mut self, entity: impl Into<String>, message: impl Into<String>) {
        self.warnings.push(ModelWarning {
            entity: entity.into(),
            message: message.into(),
        });
    }

    fn note(&mut self, entity: impl Into<String>, message: impl Into<String>) {
        self.notes.push(ModelWarning {
            entity: entity.into(),
            message: message.into(),
        });
    }

    /// Notes how a coefficient given per degree (`unit = "deg"`) is read:
    /// `what` (`stiffness`), `value` per degree, `per` the rest of its
    /// unit (`N·m`, `N·m·s`), `unit` the radians in the model's angle
    /// unit (1 for radians: no note).
    fn per_degree(&mut self, entity: &str, what: &str, value: f64, per: &str, unit: f64) {
        if unit == 1.0 || value == 0.0 {
            return;
        }
        self.note(
            entity,
            format!(
                "{what} = {value} with unit = \"deg\" is {value} {per}/deg = {:.6e} {per}/rad (the angle in the {what} is in degrees too; {value} {per}/rad would be {what} = {:.6e})",
                value / unit,
                value * unit
            ),
        );
    }

    /// Checks that every value is finite.
    fn finite(&mut self, entity: &str, what: &str, values: &[f64]) -> bool {
        if values.iter().all(|v| v.is_finite()) {
            true
        } else {
            self.push(
                ModelErrorKind::Invalid,
                entity,
                format!("{what} must be finite, got {values:?}"),
            );
            false
        }
    }

    /// Warns that an angle written without a `unit` (read in radians) is
    /// beyond `limit` (half or a whole turn), as an angle in degrees
    /// would be: `what` says which angle (`"rotation has the length"`).
    fn unitless_angle(&mut self, entity: &str, what: &str, angle: f64, limit: AngleLimit) {
        let (bound, beyond) = match limit {
            AngleLimit::HalfTurn => (std::f64::consts::PI, "half a turn"),
            AngleLimit::FullTurn => (std::f64::consts::TAU, "a full turn"),
        };
        if angle.abs() > bound * (1.0 + ANGLE_SLACK) {
            self.warn(
                entity,
                format!(
                    "{what} {:.4} rad ({:.1}°), more than {beyond}, and gives no unit: angles are read in radians. If it is in degrees, write unit = \"deg\" (unit = \"rad\" confirms radians)",
                    angle.abs(),
                    angle.abs().to_degrees()
                ),
            );
        }
    }

    /// Checks that a value is finite and zero or positive.
    fn non_negative(&mut self, entity: &str, what: &str, value: f64) -> bool {
        if value.is_finite() && value >= 0.0 {
            true
        } else {
            self.push(
                ModelErrorKind::NonPositive,
                entity,
                format!(
                    "{what} must be zero or positive and finite, got {}",
                    num(value)
                ),
            );
            false
        }
    }

    /// Checks that a value is finite and strictly positive.
    fn positive(&mut self, entity: &str, what: &str, value: f64) -> bool {
        if value.is_finite() && value > 0.0 {
            true
        } else {
            self.push(
                ModelErrorKind::NonPositive,
                entity,
                format!("{what} must be positive, got {}", num(value)),
            );
            false
        }
    }
}

/// The model's size ([`Model::length_scale`]): the diagonal of the box
/// around the nodes at `x`; for a model of one point, the largest length
/// the model gives otherwise ([`own_length`]); 1 only for a model without
/// any length.
fn length_scale<'a>(input: &ModelInput, x: impl Iterator<Item = &'a Vec3>) -> f64 {
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    let mut first = None;
    for x in x {
        lo = lo.inf(x);
        hi = hi.sup(x);
        first.get_or_insert(*x);
    }
    let d = (hi - lo).norm();
    if d > 0.0 && d.is_finite() {
        return d;
    }
    let l = own_length(input, first.unwrap_or_else(Vec3::zeros));
    if l > 0.0 && l.is_finite() {
        l
    } else {
        1.0
    }
}

/// The largest length of a model whose nodes are all at one point `x0`,
/// in its own units: where its joints and contact planes are, the radii
/// of its spheres and the radii of gyration and centres of mass of its
/// rigid bodies, the pitch of its screws, and the limits of stops and the
/// lock values of latches on joint coordinates that are lengths (a ball
/// on a prismatic stop). Values that are not finite are left out (their
/// entity's own check reports them).
fn own_length(input: &ModelInput, x0: Vec3) -> f64 {
    let mut l = 0.0f64;
    let mut add = |v: f64| {
        if v.is_finite() {
            l = l.max(v.abs());
        }
    };
    let from = |p: [f64; 3]| (Vec3::from(p) - x0).norm();
    for j in &input.joints {
        if let Some(p) = j.position {
            add(from(p));
        }
        if let Some(o) = j.offset {
            add(Vec3::from(o).norm());
        }
        j.pitch.map(&mut add);
    }
    for b in &input.rigid_bodies {
        if let Some(c) = b.center_of_mass {
            add(Vec3::from(c).norm());
        }
        let largest = match &b.inertia {
            Some(InertiaInput::Diagonal(d)) => d.iter().fold(0.0f64, |a, v| a.max(v.abs())),
            Some(InertiaInput::Full(f)) => (0..3).fold(0.0f64, |a, i| a.max(f[i][i].abs())),
            None => 0.0,
        };
        if b.mass > 0.0 {
            add((largest / b.mass).sqrt());
        }
    }
    for c in &input.contacts {
        if let Some(p) = c.point {
            add(from(p));
        }
        c.radius.map(&mut add);
        c.radii.iter().flatten().for_each(|&r| add(r));
    }
    // the coordinate a stop or latch acts on, when it is a length
    let is_length = |joint: Id, name: &Option<String>| {
        input
            .joints
            .iter()
            .find(|j| j.id == joint)
            .is_some_and(|j| {
                let cs = j.kind.coordinates();
                let c = match name {
                    Some(n) => cs.iter().find(|c| c.name() == n.as_str()),
                    None => cs.first(),
                };
                c.is_some_and(|c| !c.is_angle())
            })
    };
    for s in &input.stops {
        if is_length(s.joint, &s.coordinate) {
            s.lower.map(&mut add);
            s.upper.map(&mut add);
        }
    }
    for t in &input.latches {
        if is_length(t.joint, &t.coordinate) {
            add(t.value);
        }
    }
    l
}

/// A node being built: reference position and orientation.
struct NodeData {
    x: Vec3,
    q: Rotation,
}

/// The model being built: everything resolved so far.
struct Builder<'i> {
    input: &'i ModelInput,
    ck: Checker,
    /// What the checks and defaults take from the analyses.
    plan: settings::Plan,
    curves: CurveTable,
    node_ids: Vec<Id>,
    nodes: Vec<NodeData>,
    node_index: HashMap<Id, usize>,
    /// Ids of nodes defined with errors (already reported).
    invalid_nodes: HashSet<Id>,
    sections: HashMap<String, BeamSection>,
    /// Names of sections defined with errors (already reported).
    invalid_sections: HashSet<String>,
    /// The element ids claimed so far, with the entity that holds each.
    element_ids: HashMap<Id, String>,
    elements: Vec<Box<dyn Element>>,
    beam_specs: Vec<BeamSpec>,
    /// Ply materials, laminates and the pressures of shells.
    shell_tables: shells::ShellTables,
    fixed: Vec<[bool; 6]>,
    prescribed: Vec<Prescribed>,
    /// Nodes taken out of the model inside a superelement, with its
    /// entity.
    absorbed_nodes: HashMap<Id, String>,
    /// Rigid bodies and point masses reduced into a superelement.
    absorbed_elements: HashSet<Id>,
}

impl Builder<'_> {
    /// Index of node `id`; an error naming `entity` if it does not exist
    /// (unless its own definition was invalid and reported).
    fn node(&mut self, entity: &str, id: Id) -> Option<usize> {
        let found = self.node_index.get(&id).copied();
        if found.is_none() && !self.invalid_nodes.contains(&id) {
            let message = match self.absorbed_nodes.get(&id) {
                Some(holder) => format!("node {id} is inside {holder}, reduced away with its interior: make it one of its boundary nodes to attach to it"),
                None => format!("node {id} does not exist"),
            };
            self.ck.push(ModelErrorKind::UnknownNode, entity, message);
        }
        found
    }

    /// Claims an element id: false (and an error) if it is taken or too
    /// large.
    fn claim_id(&mut self, entity: &str, id: Id) -> bool {
        if id > MAX_ID {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("id {id} is larger than {MAX_ID}, the largest a model file can hold"),
            );
            false
        } else if let Some(holder) = self.element_ids.get(&id) {
            let message = format!("duplicate element id: {holder} has id {id} already");
            self.ck.push(ModelErrorKind::DuplicateId, entity, message);
            false
        } else {
            self.element_ids.insert(id, entity.to_string());
            true
        }
    }

    /// The curve followed by `entity`.
    fn curve(
        &mut self,
        entity: &str,
        name: &Option<String>,
        default: CurveIndex,
    ) -> Option<CurveIndex> {
        self.curves.resolve(&mut self.ck, entity, name, default)
    }

    /// Default curve of loads and gravity: the ramp in statics (the load
    /// factor), the constant in a kinematic analysis, whose motion the
    /// drivers set and whose loads are those of the real, fully loaded
    /// mechanism at every instant, and in a first dynamic analysis, whose
    /// loads act from the start (a ramp in time is a loading history of
    /// its own, to be given as such).
    fn load_default(&self) -> CurveIndex {
        if self.plan.kinematic || self.plan.first_dynamic {
            CONSTANT
        } else {
            RAMP
        }
    }
}

/// The size of the model the input describes, nodes and elements given and
/// generated (by the lines within [`MAX_LINE_ELEMENTS`]: the others are
/// reported and not generated).
fn model_size(input: &ModelInput) -> usize {
    let generated: usize = input
        .beam_lines
        .iter()
        .filter(|l| l.elements <= MAX_LINE_ELEMENTS)
        .map(|l| 2 * l.elements)
        .sum();
    [
        input.nodes.len(),
        input.beams.len(),
        input.shells.len(),
        shells::panels_size(&input.panels),
        input.rigid_bodies.len(),
        input.point_masses.len(),
        input.springs.len(),
        input.loads.len(),
        input.joints.len(),
        input.joint_springs.len(),
        input.hinge_laws.len(),
        input.drivers.len(),
        input.latches.len(),
        input.stops.len(),
        input.contacts.len(),
        input.rolling_discs.len(),
        input.superelements.len(),
        generated,
    ]
    .into_iter()
    .fold(0usize, usize::saturating_add)
}

impl Model {
    /// Validates `input` and builds the model. On failure returns every
    /// problem found.
    pub fn from_input(input: &ModelInput) -> Result<Model, ModelErrors> {
        let mut ck = Checker::default();
        let plan = settings::Plan::of(&settings::analyses(&mut ck, &input.analysis));
        let curves = CurveTable::build(&mut ck, &input.curves, plan.end_time);
        output::check(&mut ck, input.output.as_ref(), plan.end_time);
        let mut b = Builder {
            input,
            ck,
            plan,
            curves,
            node_ids: Vec::new(),
            nodes: Vec::new(),
            node_index: HashMap::new(),
            invalid_nodes: HashSet::new(),
            sections: HashMap::new(),
            invalid_sections: HashSet::new(),
            element_ids: HashMap::new(),
            elements: Vec::new(),
            beam_specs: Vec::new(),
            shell_tables: Default::default(),
            fixed: Vec::new(),
            prescribed: Vec::new(),
            absorbed_nodes: HashMap::new(),
            absorbed_elements: HashSet::new(),
        };
        let size = model_size(input);
        let mesh = size <= MAX_MODEL_SIZE;
        if !mesh {
            b.ck.push(
                ModelErrorKind::Invalid,
                "model",
                format!(
                    "has {size} nodes and elements (given and generated by beam_lines and panels), more than the limit of {MAX_MODEL_SIZE}"
                ),
            );
        }
        b.nodes();
        b.sections();
        b.beams();
        b.beam_lines(mesh);
        b.superelements();
        b.build_beams();
        b.ply_materials();
        b.laminates();
        // panels first: single shells may join their nodes
        b.panels(mesh);
        b.shells();
        b.pressure_loads();
        b.masses();
        b.springs();
        b.loads();
        joints::build(&mut b);
        b.contacts();
        b.rolling_discs();
        let gravity = b.gravity();
        b.supports();
        b.prescribed();
        let initial_velocity = b.initial_velocities();

        // ---------- global checks ----------
        let Builder {
            mut ck,
            plan,
            curves,
            node_ids,
            nodes,
            node_index,
            elements,
            fixed,
            prescribed,
            ..
        } = b;
        if ck.errors.is_empty() {
            if elements.iter().all(|e| e.kind() == ElementKind::NodalLoad) {
                ck.push(ModelErrorKind::Missing, "model", "has no elements");
            } else if !plan.no_statics {
                // a free part has no static equilibrium; in dynamics its
                // inertia holds it, a modal analysis gives its rigid-body
                // modes
                checks::check_restraint(&mut ck, &node_ids, &elements, &fixed);
            }
        }
        if !ck.errors.is_empty() {
            return Err(ModelErrors(ck.errors));
        }

        let length_scale = length_scale(input, nodes.iter().map(|n| &n.x));
        let mut model = Model {
            title: input.title.clone().unwrap_or_default(),
            node_ids,
            node_lookup: node_index,
            element_lookup: elements
                .iter()
                .enumerate()
                .map(|(i, e)| ((e.kind(), e.id()), i))
                .collect(),
            reference_x: nodes.iter().map(|n| n.x).collect(),
            reference_q: nodes.iter().map(|n| n.q).collect(),
            elements,
            fixed,
            prescribed,
            curves: curves.curves,
            curve_uses: curves.uses,
            warnings: ck.warnings,
            notes: ck.notes,
            gravity,
            length_scale,
            scaling: Default::default(),
            initial_velocity,
            offsets: Vec::new(),
            sizes: Default::default(),
        };
        model.place_elements();
        let mut model = model.with_default_scaling(
            input.analysis.constraint_scale,
            input.analysis.constraint_penalty,
        );
        let errors = checks::non_finite_elements(&model, plan.end_time);
        if !errors.is_empty() {
            return Err(ModelErrors(errors));
        }
        for (entity, message) in checks::suspect_model(&model, input) {
            model.warnings.push(ModelWarning { entity, message });
        }
        Ok(model)
    }
}
