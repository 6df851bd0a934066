//! The evolving state of a model: node positions and orientations, extra
//! unknowns and internal variables, at one value of the load parameter.

use crate::so3::{Rotation, Vec3};

/// Configuration of the model at time (load parameter) `time`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct State {
    /// Load parameter (pseudo-time in statics).
    pub time: f64,
    /// Node positions, global frame.
    pub x: Vec<Vec3>,
    /// Node orientations (material frame to global frame).
    pub q: Vec<Rotation>,
    /// Extra unknowns owned by elements (multipliers, modal amplitudes).
    pub extra: Vec<f64>,
    /// Internal variables of elements.
    pub internal: Vec<f64>,
    /// Node velocities `(ẋ, Ω)` (translation, material angular velocity);
    /// empty when the model is at rest (quasi-static analyses).
    pub velocity: Vec<[f64; 6]>,
}
