//! The evolving state of a model: node positions and orientations, the
//! generalised coordinates and multipliers of elements, internal variables,
//! and the rates of all of them, at one value of the time (load parameter).
//!
//! ## The update rule `q ⊕ Δq`
//! A node's unknowns are the translation increment `Δx` (global frame) and
//! the incremental *material* rotation `ΔΘ` (docs/theory.md §2):
//!
//! ```text
//! x ← x + Δx,    R ← R exp(ΔΘ~)
//! ```
//!
//! coordinates and multipliers are updated additively. [`State::displace_node`]
//! is the one place where this is written: Newton's corrections
//! ([`State::update`]), the finite-difference checks of every tangent
//! ([`State::displace_local`]) and the examples go through it, so that a
//! tangent is always the derivative along the update that Newton applies.

use serde::{Deserialize, Serialize};

use crate::dofs::DofMap;
use crate::so3::{self, Rotation, Vec3};

/// Configuration and motion of the model at time (load parameter) `time`.
///
/// Per-node vectors (`x`, `q`, `velocity`, `acceleration`,
/// `pseudo_acceleration`) are as long as the model has nodes, and the
/// vectors of coordinates as long as it has coordinates, whatever the
/// analysis: statics leaves the rates at zero, so that an element never
/// has to ask whether they are there.
///
/// It serialises (serde) field by field under the names below, positions
/// as `[x, y, z]` and orientations as unit quaternions `[w, x, y, z]`
/// (the restart files of [`crate::io::restart`]); every number is kept
/// to the last bit.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct State {
    /// Time, or load parameter in statics.
    pub time: f64,
    /// Node positions, global frame.
    #[serde(with = "serde_positions")]
    pub x: Vec<Vec3>,
    /// Node orientations (material frame to global frame).
    #[serde(with = "serde_orientations")]
    pub q: Vec<Rotation>,
    /// Generalised coordinates of elements (a slider's curve parameter,
    /// modal amplitudes).
    pub coordinates: Vec<f64>,
    /// Lagrange multipliers of constraints (`k λ` is the constraint force).
    pub multipliers: Vec<f64>,
    /// Internal variables of elements (unwrapped angles, the coordinate
    /// where a driver takes over, hysteresis or latch states).
    pub internal: Vec<f64>,
    /// Node velocities `(ẋ, Ω)`: translation (global) and angular velocity
    /// (material, `RᵀṘ = Ω~`).
    pub velocity: Vec<[f64; 6]>,
    /// Node accelerations `(ẍ, Ω̇)`, in the frames of `velocity`.
    pub acceleration: Vec<[f64; 6]>,
    /// Rates of the coordinates.
    pub coordinate_rates: Vec<f64>,
    /// Second rates of the coordinates.
    pub coordinate_accelerations: Vec<f64>,
    /// Pseudo-accelerations `a` of the nodes (generalised-α).
    pub pseudo_acceleration: Vec<[f64; 6]>,
    /// Pseudo-accelerations of the coordinates (generalised-α).
    pub coordinate_pseudo_accelerations: Vec<f64>,
}

impl State {
    /// A state at rest at `time`: nodes at `x`, `q`, every rate zero, no
    /// coordinates, multipliers or internal variables.
    pub fn at_rest(time: f64, x: Vec<Vec3>, q: Vec<Rotation>) -> Self {
        let n = x.len();
        assert_eq!(n, q.len(), "as many positions as orientations");
        Self {
            time,
            x,
            q,
            velocity: vec![[0.0; 6]; n],
            acceleration: vec![[0.0; 6]; n],
            pseudo_acceleration: vec![[0.0; 6]; n],
            ..Self::default()
        }
    }

    /// Gives the state `n` coordinates with the values `values` (zero
    /// rates), and `m` multipliers and `k` internal variables at zero.
    pub fn with_unknowns(mut self, coordinates: Vec<f64>, m: usize, k: usize) -> Self {
        let n = coordinates.len();
        self.coordinates = coordinates;
        self.coordinate_rates = vec![0.0; n];
        self.coordinate_accelerations = vec![0.0; n];
        self.coordinate_pseudo_accelerations = vec![0.0; n];
        self.multipliers = vec![0.0; m];
        self.internal = vec![0.0; k];
        self
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.x.len()
    }

    /// Moves node `node` by the translation `dx` (global) and the material
    /// rotation `dtheta`: `x ← x + Δx`, `R ← R exp(ΔΘ~)`, renormalised
    /// (docs/theory.md §2). The orientation is left untouched (bit for bit)
    /// when `dtheta` is zero.
    #[inline]
    pub fn displace_node(&mut self, node: usize, dx: &Vec3, dtheta: &Vec3) {
        self.x[node] += dx;
        if *dtheta != Vec3::zeros() {
            let q = &mut self.q[node];
            *q *= so3::exp(dtheta);
            q.renormalize_fast();
        }
    }

    /// Applies a correction `delta`, by equation of `dofs`, to every free
    /// unknown: nodes through [`State::displace_node`], coordinates and
    /// multipliers additively. Unknowns without an equation are left as
    /// they are.
    pub fn update(&mut self, dofs: &DofMap, delta: &[f64]) {
        for node in 0..self.x.len() {
            let mut d = [0.0; 6];
            let mut any = false;
            for (c, dc) in d.iter_mut().enumerate() {
                let eq = dofs.equation(6 * node + c);
                if eq != crate::dofs::NO_EQUATION {
                    *dc = delta[eq];
                    any = true;
                }
            }
            if any {
                let (dx, dth) = (Vec3::new(d[0], d[1], d[2]), Vec3::new(d[3], d[4], d[5]));
                self.displace_node(node, &dx, &dth);
            }
        }
        let first = dofs.first_coordinate();
        for (k, v) in self.coordinates.iter_mut().enumerate() {
            let eq = dofs.equation(first + k);
            if eq != crate::dofs::NO_EQUATION {
                *v += delta[eq];
            }
        }
        let first = dofs.first_multiplier();
        for (k, v) in self.multipliers.iter_mut().enumerate() {
            let eq = dofs.equation(first + k);
            if eq != crate::dofs::NO_EQUATION {
                *v += delta[eq];
            }
        }
    }

    /// Moves local unknown `k` of an element by `h` along the update rule.
    /// The element's local unknowns are `[6 per node of nodes, its
    /// n_coordinates coordinates (from offsets.coordinates), its
    /// multipliers (from offsets.multipliers)]`, as in its residual.
    pub fn displace_local(
        &mut self,
        nodes: &[usize],
        n_coordinates: usize,
        offsets: &crate::elements::Offsets,
        k: usize,
        h: f64,
    ) {
        let nq = 6 * nodes.len();
        if k < nq {
            let (node, c) = (nodes[k / 6], k % 6);
            let mut d = Vec3::zeros();
            d[c % 3] = h;
            if c < 3 {
                self.displace_node(node, &d, &Vec3::zeros());
            } else {
                self.displace_node(node, &Vec3::zeros(), &d);
            }
        } else if k < nq + n_coordinates {
            self.coordinates[offsets.coordinates + k - nq] += h;
        } else {
            self.multipliers[offsets.multipliers + k - nq - n_coordinates] += h;
        }
    }

    /// Changes the rate of local unknown `k` of an element by `h`: the
    /// velocity of a node component, or the rate of a coordinate
    /// (multipliers have no rates). See [`State::displace_local`].
    pub fn change_local_rate(
        &mut self,
        nodes: &[usize],
        n_coordinates: usize,
        offsets: &crate::elements::Offsets,
        k: usize,
        h: f64,
    ) {
        let (nodal, coordinates) = (&mut self.velocity, &mut self.coordinate_rates);
        change_local(nodal, coordinates, nodes, n_coordinates, offsets, k, h);
    }

    /// Changes the acceleration of local unknown `k` of an element by `h`
    /// (see [`State::change_local_rate`]).
    pub fn change_local_acceleration(
        &mut self,
        nodes: &[usize],
        n_coordinates: usize,
        offsets: &crate::elements::Offsets,
        k: usize,
        h: f64,
    ) {
        let (nodal, coordinates) = (&mut self.acceleration, &mut self.coordinate_accelerations);
        change_local(nodal, coordinates, nodes, n_coordinates, offsets, k, h);
    }
}

/// Adds `h` to local unknown `k` of an element in a pair of rate vectors
/// (nodal, coordinates): [`State::change_local_rate`] and
/// [`State::change_local_acceleration`].
fn change_local(
    nodal: &mut [[f64; 6]],
    coordinates: &mut [f64],
    nodes: &[usize],
    n_coordinates: usize,
    offsets: &crate::elements::Offsets,
    k: usize,
    h: f64,
) {
    let nq = 6 * nodes.len();
    if k < nq {
        nodal[nodes[k / 6]][k % 6] += h;
    } else if k < nq + n_coordinates {
        coordinates[offsets.coordinates + k - nq] += h;
    }
}

/// Positions as arrays `[x, y, z]`.
mod serde_positions {
    use super::Vec3;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(x: &[Vec3], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(x.iter().map(|v| [v.x, v.y, v.z]))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Vec3>, D::Error> {
        let raw = Vec::<[f64; 3]>::deserialize(d)?;
        Ok(raw.into_iter().map(Vec3::from).collect())
    }
}

/// Orientations as unit quaternions `[w, x, y, z]`; one that is not of
/// unit length (to 1e-10) is refused, not normalised.
mod serde_orientations {
    use super::Rotation;
    use nalgebra::Quaternion;
    use serde::{de::Error, Deserialize, Deserializer, Serializer};

    /// Largest departure of `|q|` from 1 accepted when reading.
    const UNIT_TOLERANCE: f64 = 1e-10;

    pub fn serialize<S: Serializer>(q: &[Rotation], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(q.iter().map(|r| [r.w, r.i, r.j, r.k]))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Rotation>, D::Error> {
        let raw = Vec::<[f64; 4]>::deserialize(d)?;
        raw.into_iter()
            .enumerate()
            .map(|(i, [w, x, y, z])| {
                let q = Quaternion::new(w, x, y, z);
                if (q.norm() - 1.0).abs() > UNIT_TOLERANCE {
                    return Err(D::Error::custom(format!(
                        "orientation {i} [{w}, {x}, {y}, {z}] is not a unit quaternion"
                    )));
                }
                Ok(Rotation::new_unchecked(q))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn displace_node_composes_material_rotations() {
        // R exp(a~) exp(b~) for two increments about different axes
        let r0 = so3::exp(&Vec3::new(0.3, -1.2, 0.5));
        let mut s = State::at_rest(0.0, vec![Vec3::new(1.0, 2.0, 3.0)], vec![r0]);
        let (a, b) = (Vec3::new(0.1, 0.0, 0.2), Vec3::new(0.0, -0.4, 0.0));
        s.displace_node(0, &Vec3::new(0.5, 0.0, -1.0), &a);
        s.displace_node(0, &Vec3::zeros(), &b);
        let expected = r0 * so3::exp(&a) * so3::exp(&b);
        // renormalisation changes the quaternion by round-off only
        assert!((s.q[0].coords - expected.coords).norm() < 1e-15);
        assert_eq!(s.x[0], Vec3::new(1.5, 2.0, 2.0));
        // a zero rotation leaves the orientation unchanged, bit for bit
        let before = s.q[0];
        s.displace_node(0, &Vec3::x(), &Vec3::zeros());
        assert_eq!(s.q[0], before);
    }
}
