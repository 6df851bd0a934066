//! Bodies that end inside one another: a check of a run's final
//! configuration against its first, for the wrong models that run to
//! "completed" (a hinge axis along the panel instead of the hinge line
//! folds a panel into the spacecraft; a joint on the wrong node swings a
//! body through its neighbour).
//!
//! Each rigid body or point mass is drawn with a shape
//! ([`crate::elements::shape::BodyShape`]: its own, or the box of its
//! inertia). The shapes play no part in the mechanics, so nothing stops
//! one body from passing through another; this check looks at where they
//! end. For a pair of bodies on different nodes, not both fixed, the
//! points spread over each ([`BodyShape::samples`]) are placed in the other
//! ([`BodyShape::side`]):
//! - **inside**: the fraction of one body's points inside the other's
//!   volume (a box, a thick plate, a cylinder);
//! - **through**: for a plate, the points of the other body within its
//!   outline on both of its sides, the smaller count as the fraction.
//!
//! A pair whose larger fraction reaches [`OVERLAP_FRACTION`] at the end is
//! reported, unless it did at the start too and the two bodies hardly
//! moved relative to each other (by less than [`RELATIVE_MOTION`] rad and
//! of their reach): panels stowed on one another modelled as coincident
//! are an idealisation, not an error, until one turns through the other.
//! Points sampled at the centres of a grid's cells keep bodies that touch
//! (hinged edge to edge, a panel against the spacecraft's wall) apart.

use std::collections::HashMap;

use super::{Id, Model};
use crate::elements::shape::{BodyShape, Side};
use crate::elements::ElementKind;
use crate::so3::{self, Mat3, Vec3};
use crate::state::State;

/// The fraction of a body's sample points inside (or through) another at
/// which the pair is reported: a tenth of a body inside another is no
/// contact of two faces, nor the round-off of shapes drawn from inertias.
pub const OVERLAP_FRACTION: f64 = 0.1;

/// A pair of bodies overlapping at the start and at the end is reported
/// only if they moved relative to each other by more than this: a
/// rotation of this many radians, or a translation of this fraction of
/// the larger reach.
pub const RELATIVE_MOTION: f64 = 0.1;

/// How two bodies end, one in the other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OverlapKind {
    /// A part of `body` lies inside `other`'s volume.
    Inside,
    /// `body` crosses the plate `other`.
    Through,
}

/// A pair of bodies found inside one another at the end of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Overlap {
    /// The body of which a part lies inside (or across) the other: its
    /// kind and id.
    pub body: (ElementKind, Id),
    /// The other body.
    pub other: (ElementKind, Id),
    /// Whether `other` is held fixed (all six components of its node).
    pub other_fixed: bool,
    /// How.
    pub kind: OverlapKind,
    /// The fraction of `body`'s sample points inside (or, for `Through`,
    /// on the smaller side of) `other`.
    pub fraction: f64,
    /// Whether the two overlapped at the start already.
    pub at_start: bool,
}

/// A body's shape placed at a state: its sample points and its frame.
struct Placed {
    kind: ElementKind,
    id: Id,
    node: usize,
    fixed: bool,
    shape: BodyShape,
    x: Vec3,
    r: Mat3,
    reach: f64,
}

impl Placed {
    fn all(model: &Model, state: &State) -> Vec<Self> {
        model
            .elements
            .iter()
            .filter_map(|e| {
                let shape = *e.body_shape()?;
                let &node = e.nodes().first()?;
                Some(Self {
                    kind: e.kind(),
                    id: e.id(),
                    node,
                    fixed: model.fixed[node].iter().all(|&f| f),
                    shape,
                    x: state.x[node],
                    r: so3::matrix(&state.q[node]),
                    reach: shape.reach(),
                })
            })
            .collect()
    }

    /// The fraction of the points of `self` inside `other`, and of those
    /// on the smaller side of the plate `other`.
    fn fractions(&self, other: &Placed, samples: &[Vec3]) -> (f64, f64) {
        let (mut inside, mut above, mut below) = (0usize, 0usize, 0usize);
        for p in samples {
            // global, then in the other's node frame
            let g = self.x + self.r * p;
            match other.shape.side(&(other.r.transpose() * (g - other.x))) {
                Side::Inside => inside += 1,
                Side::Above => above += 1,
                Side::Below => below += 1,
                Side::Outside => {}
            }
        }
        let n = samples.len().max(1) as f64;
        (inside as f64 / n, above.min(below) as f64 / n)
    }
}

/// Where a body of a pair lies relative to the other.
struct Relative {
    /// The rotation and position of the second in the frame of the
    /// first's node.
    rotation: Mat3,
    position: Vec3,
    /// The larger reach of the two.
    reach: f64,
}

impl Relative {
    fn of(a: &Placed, b: &Placed) -> Self {
        Self {
            rotation: a.r.transpose() * b.r,
            position: a.r.transpose() * (b.x - a.x),
            reach: a.reach.max(b.reach),
        }
    }
}

/// The pairs of bodies overlapping in `state` (the larger fraction of
/// each pair reaching [`OVERLAP_FRACTION`]), keyed by their indices in
/// [`Placed::all`]'s order, with what each is, the placement of the
/// second in the frame of the first and the larger reach of the two.
fn overlapping(model: &Model, state: &State) -> HashMap<(usize, usize), (Overlap, Relative)> {
    let placed = Placed::all(model, state);
    let samples: Vec<Vec<Vec3>> = placed.iter().map(|p| p.shape.samples()).collect();
    let mut found = HashMap::new();
    for i in 0..placed.len() {
        for j in i + 1..placed.len() {
            let (a, b) = (&placed[i], &placed[j]);
            let centre = |p: &Placed| p.x + p.r * p.shape.center;
            // bodies on one node are one body; fixed ones do not move
            if a.node == b.node
                || (a.fixed && b.fixed)
                || (centre(a) - centre(b)).norm() > a.reach + b.reach
            {
                continue;
            }
            let (a_in_b, a_through_b) = a.fractions(b, &samples[i]);
            let (b_in_a, b_through_a) = b.fractions(a, &samples[j]);
            let candidates = [
                (a_in_b, OverlapKind::Inside, a, b),
                (b_in_a, OverlapKind::Inside, b, a),
                (a_through_b, OverlapKind::Through, a, b),
                (b_through_a, OverlapKind::Through, b, a),
            ];
            let Some(&(fraction, kind, body, other)) =
                candidates.iter().max_by(|x, y| x.0.total_cmp(&y.0))
            else {
                continue;
            };
            if fraction >= OVERLAP_FRACTION {
                let overlap = Overlap {
                    body: (body.kind, body.id),
                    other: (other.kind, other.id),
                    other_fixed: other.fixed,
                    kind,
                    fraction,
                    at_start: false,
                };
                found.insert((i, j), (overlap, Relative::of(a, b)));
            }
        }
    }
    found
}

/// The bodies that overlap at `end`, but for those that overlapped at
/// `start` and hardly moved relative to each other since (module
/// documentation), in the order of the model's elements.
pub fn new_overlaps(model: &Model, start: &State, end: &State) -> Vec<Overlap> {
    let before = overlapping(model, start);
    let mut after: Vec<((usize, usize), Overlap)> = overlapping(model, end)
        .into_iter()
        .filter_map(|(pair, (mut overlap, now))| {
            if let Some((_, then)) = before.get(&pair) {
                // the angle of the relative rotation, from its trace
                let turned = (0.5 * ((now.rotation * then.rotation.transpose()).trace() - 1.0))
                    .clamp(-1.0, 1.0)
                    .acos();
                let moved = (now.position - then.position).norm() / now.reach;
                if turned <= RELATIVE_MOTION && moved <= RELATIVE_MOTION {
                    return None;
                }
                overlap.at_start = true;
            }
            Some((pair, overlap))
        })
        .collect();
    after.sort_by_key(|(pair, _)| *pair);
    after.into_iter().map(|(_, o)| o).collect()
}

/// The warnings of [`new_overlaps`] between `start` and `end`, for a user.
pub fn overlap_warnings(model: &Model, start: &State, end: &State) -> Vec<String> {
    let time = crate::io::run::format_time(end.time);
    new_overlaps(model, start, end)
        .iter()
        .map(|o| o.message(&time))
        .collect()
}

impl Overlap {
    /// The warning for a user, at time `time`.
    pub fn message(&self, time: &str) -> String {
        let (body, other) = (
            format!("{} {}", self.body.0.name(), self.body.1),
            format!(
                "{} {}{}",
                self.other.0.name(),
                self.other.1,
                if self.other_fixed { " (fixed)" } else { "" }
            ),
        );
        let percent = (100.0 * self.fraction).round();
        let how = match self.kind {
            OverlapKind::Inside => format!("{percent}% of {body} lies inside {other}"),
            OverlapKind::Through => {
                format!(
                    "{body} passes through the plate {other} ({percent}% of it on the far side)"
                )
            }
        };
        let start = if self.at_start {
            "as at its start, though they moved relative to each other"
        } else {
            "and not at its start"
        };
        format!(
            "{how} at the end of the run (t = {time}), {start}: bodies pass through each other freely (their shapes play no part in the mechanics), so a joint's axis, position or nodes may be wrong; look at the last configuration (`unfold view`)"
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::shape::Solid;

    fn placed(shape: BodyShape, x: Vec3, r: Mat3) -> Placed {
        Placed {
            kind: ElementKind::RigidBody,
            id: 1,
            node: 0,
            fixed: false,
            reach: shape.reach(),
            shape,
            x,
            r,
        }
    }

    /// Two unit boxes: apart, face to face, overlapping by a quarter of
    /// their length; a small box turned inside a large one.
    #[test]
    fn the_fraction_inside_is_the_overlapping_volume() {
        let cube = BodyShape::new(
            Solid::Box { size: [1.0; 3] },
            Vec3::zeros(),
            Mat3::identity(),
        );
        let a = placed(cube, Vec3::zeros(), Mat3::identity());
        let at = |x: f64| placed(cube, Vec3::new(x, 0.0, 0.0), Mat3::identity());
        let samples = cube.samples();
        assert_eq!(samples.len(), 512);
        // apart, and touching face to face: nothing inside
        assert_eq!(a.fractions(&at(2.0), &samples), (0.0, 0.0));
        assert_eq!(a.fractions(&at(1.0), &samples), (0.0, 0.0));
        // overlapping by 0.25: the two layers of cells out of eight
        assert_eq!(a.fractions(&at(0.75), &samples).0, 0.25);
        // a cube of half the size, turned, lies wholly inside (its
        // half-diagonal in the plane, 0.35, within 0.5), and the unit
        // cube turned by 0.7 rad about z keeps its corners out
        let small = BodyShape::new(
            Solid::Box { size: [0.5; 3] },
            Vec3::zeros(),
            Mat3::identity(),
        );
        let turn = so3::exp_matrix(&Vec3::new(0.0, 0.0, 0.7));
        let inner = placed(small, Vec3::zeros(), turn);
        assert_eq!(inner.fractions(&a, &small.samples()).0, 1.0);
        let turned = placed(cube, Vec3::zeros(), turn);
        let f = a.fractions(&turned, &samples).0;
        assert!(0.5 < f && f < 1.0, "{f}");
    }

    /// A plate hinged to another along an edge, at 90° and flat: no
    /// overlap; swung through it: half of it on each side.
    #[test]
    fn a_plate_through_a_plate_is_found_and_one_hinged_to_it_is_not() {
        let plate = BodyShape::new(
            Solid::Plate {
                size: [1.0, 0.5],
                thickness: 0.0,
            },
            Vec3::zeros(),
            Mat3::identity(),
        );
        let b = placed(plate, Vec3::zeros(), Mat3::identity());
        let samples = plate.samples();
        // flat beside it along x, and standing on its edge x = 0.5
        let flat = placed(plate, Vec3::new(1.0, 0.0, 0.0), Mat3::identity());
        assert_eq!(flat.fractions(&b, &samples), (0.0, 0.0));
        let up = so3::exp_matrix(&Vec3::new(0.0, -std::f64::consts::FRAC_PI_2, 0.0));
        let standing = placed(plate, Vec3::new(0.5, 0.0, 0.5), up);
        assert_eq!(standing.fractions(&b, &samples), (0.0, 0.0));
        // crossing it at its middle: half above, half below
        let crossing = placed(plate, Vec3::zeros(), up);
        assert_eq!(crossing.fractions(&b, &samples), (0.0, 0.5));
    }
}
