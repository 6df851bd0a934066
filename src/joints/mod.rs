//! Kinematic pairs, the springs, dampers and drivers acting on their
//! relative coordinates, and the treatment of redundant constraints
//! (docs/joints.md).
//!
//! Every joint is a finite element whose extra unknowns are the Lagrange
//! multipliers of its constraint equations `Φ(q) = 0`, enforced by the
//! augmented Lagrangian of the reference paper (eqs. 17–18). Constraint
//! formulas are written once over hyper-dual numbers ([`hyperdual`]), which
//! gives the constraint gradient `B` and the second-derivative term
//! `∂(Bᵀλ)/∂q` exactly ([`kinematics`]); those made of dot products (every
//! joint type but the helical joint and the slider, and the coordinates)
//! are differentiated in closed form ([`products`]).

pub mod coordinate;
pub mod driver;
pub mod hinge;
pub mod hyperdual;
pub mod joint;
pub mod kinematics;
pub mod latch;
pub mod products;
pub mod rolling;
pub mod spring;
pub mod stop;
pub mod types;

pub use coordinate::PairCoordinate;
pub use driver::Driver;
pub use hinge::{Branch, HingeLaw, Hysteresis, Response, TapeSpring};
pub use joint::Joint;
pub use kinematics::Pair;
pub use latch::Latch;
pub use rolling::RollingDisc;
pub use spring::{JointSpring, Law};
pub use stop::Stop;
pub use types::{Coordinate, JointType};

#[cfg(test)]
mod tests;
