//! The mid-hinges: what acts on their angle. This is the one place where
//! the hinge law becomes model entities: the torsion spring's nonlinear
//! moment/angle law with its hysteresis (a tape-spring hinge law,
//! docs/joints.md §4.1) and the latch that locks the hinge at the end of
//! its travel (docs/joints.md §6.2), as the paper's §6.2 describes them.
//!
//! Angles. A mid-hinge is a revolute joint from the first half of its
//! horizontal (body A, which carries the fitting) to the second (body B),
//! about its axis (vertical at the top, normal to the face at the bottom)
//! oriented so that opening is a positive rotation
//! ([`super::geometry::Geometry::opening_sense`]). Its coordinate is
//! `θ = γ − γ_ref`, `γ` the opening angle (between the halves, `π`
//! deployed) and `γ_ref` its value in the configuration the model is
//! built in; the hinge locks at `θ_L = π − γ_ref`.

use std::f64::consts::PI;

use unfold::model::builder::*;
use unfold::model::input::TapeSpringInput;

use super::design::HingeLaw as Law;

/// What holds the mid-hinges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hinges {
    /// The tape spring and the latch: the hinge deploys and locks.
    Free,
    /// Locked where the model is built (a driver holding `θ = 0`): the
    /// deployed structure, for the checks.
    Locked,
}

/// The entities acting on one mid-hinge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HingeParts {
    /// The revolute joint.
    pub joint: JointHandle,
    /// Its tape spring.
    pub law: Option<HingeLawHandle>,
    /// Its latch.
    pub latch: Option<LatchHandle>,
    /// The lock of [`Hinges::Locked`].
    pub driver: Option<DriverHandle>,
    /// Opening angle in the reference configuration (rad).
    pub reference_opening: f64,
}

impl HingeParts {
    /// The coordinate `θ_L` at which the hinge locks (rad).
    pub fn locking_angle(&self) -> f64 {
        PI - self.reference_opening
    }
}

/// The tape spring of `law` on `joint`: the shape of docs/joints.md §4.1
/// with the locking angle `c_L = π − γ_ref`, so that the moment opens the
/// hinge by `M_d` (the law's moment is negative: it pushes `θ` up) until
/// the locked branch takes over just before the halves are in line.
pub fn tape_spring(law: &Law, joint: JointHandle, reference_opening: f64) -> HingeLaw {
    HingeLaw::on(joint, law.elastic_slope).tape_spring(TapeSpringInput {
        deployment_moment: law.deployment_moment,
        locking_angle: PI - reference_opening,
        locking_peak: law.locking_peak,
        locked_stiffness: law.locked_stiffness,
        snap_width: law.snap_width,
        rounding: None,
    })
}

/// Adds the spring and latch, or the lock, of `hinges` to `joint`.
pub fn add(
    m: &mut ModelBuilder,
    law: &Law,
    joint: JointHandle,
    reference_opening: f64,
    hinges: Hinges,
) -> HingeParts {
    let mut parts = HingeParts {
        joint,
        law: None,
        latch: None,
        driver: None,
        reference_opening,
    };
    match hinges {
        Hinges::Free => {
            parts.law = Some(m.add(tape_spring(law, joint, reference_opening)));
            parts.latch = Some(m.add(Latch::on(joint, PI - reference_opening)));
        }
        Hinges::Locked => parts.driver = Some(m.add(Driver::on(joint).value(0.0))),
    }
    parts
}
