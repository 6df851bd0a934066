//! The mid-hinges: what acts on their angle. This is the one place where
//! the hinge law becomes model entities; the torsion springs' nonlinear
//! moment/angle law with hysteresis and the latches that lock the hinges
//! at the end of their travel (paper §6.2) replace the stand-ins here.
//!
//! Angles. A mid-hinge is a revolute joint from the first half of its
//! horizontal (body A, which carries the fitting) to the second (body B),
//! about the vertical oriented so that opening is a positive rotation
//! ([`super::geometry::Geometry::opening_sense`]). Its coordinate is
//! `θ = γ − γ_ref`, `γ` the opening angle (between the halves, `π`
//! deployed) and `γ_ref` its value in the configuration the model is
//! built in.

use std::f64::consts::PI;

use unfold::model::builder::*;

use super::design::HingeLaw;

/// What holds or moves the mid-hinges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hinges {
    /// Free: the torsion spring alone.
    Free,
    /// Locked where the model is built (a driver holding `θ = 0`): the
    /// stand-in for the latch of a deployed hinge.
    Locked,
    /// Driven from the opening of the reference configuration to
    /// `opening` (rad) along `curve` (a driver on `θ`), spring included.
    Driven {
        /// Opening angle at `curve = 1` (rad).
        opening: f64,
    },
}

/// The entities acting on one mid-hinge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HingeParts {
    /// The revolute joint.
    pub joint: JointHandle,
    /// Its torsion spring.
    pub spring: Option<JointSpringHandle>,
    /// The driver or lock, if any.
    pub driver: Option<DriverHandle>,
    /// Opening angle in the reference configuration (rad).
    pub reference_opening: f64,
}

/// The torsion spring of `law` on `joint`, opened by `reference_opening`
/// in the reference configuration.
///
/// Stand-in: a linear joint spring. The spring's generalised force on the
/// coordinate is `f_s = k (θ − θ₀)` (docs/joints.md §4: positive resists
/// an increase of `θ`), so the opening moment is `−f_s = k (θ₀ − θ)`;
/// equal to `M(γ) = M_d + k (π − γ)` with `θ = γ − γ_ref` when
/// `θ₀ = M_d / k + π − γ_ref`.
pub fn spring(law: &HingeLaw, joint: JointHandle, reference_opening: f64) -> JointSpring {
    let free = law.deployed_moment / law.stiffness + PI - reference_opening;
    JointSpring::on(joint)
        .stiffness(law.stiffness)
        .free_value(free)
}

/// Adds the spring and the driver or lock of `hinges` to `joint`.
pub fn add(
    m: &mut ModelBuilder,
    law: &HingeLaw,
    joint: JointHandle,
    reference_opening: f64,
    hinges: Hinges,
    curve: Option<CurveHandle>,
) -> HingeParts {
    let spring = Some(m.add(spring(law, joint, reference_opening)));
    let driver = match hinges {
        Hinges::Free => None,
        Hinges::Locked => Some(m.add(Driver::on(joint).value(0.0))),
        Hinges::Driven { opening } => {
            let mut d = Driver::on(joint).value(opening - reference_opening);
            if let Some(c) = curve {
                d = d.curve(c);
            }
            Some(m.add(d))
        }
    };
    HingeParts {
        joint,
        spring,
        driver,
        reference_opening,
    }
}
