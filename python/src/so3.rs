//! Finite rotations for building models from Python (`unfold.so3`): the
//! library's exponential and logarithm maps and the smallest rotation
//! between two directions (src/so3.rs), on unit quaternions given as
//! `(w, x, y, z)` and rotation vectors `(x, y, z)` in radians, so that a
//! Python model computes its hinge axes with the same arithmetic as a
//! Rust one.

use pyo3::prelude::*;

use unfold::so3::{self, Rotation, Vec3};

type Quaternion = (f64, f64, f64, f64);

fn rotation(q: Quaternion) -> Rotation {
    Rotation::new_unchecked(nalgebra::Quaternion::new(q.0, q.1, q.2, q.3))
}

fn quaternion(r: &Rotation) -> Quaternion {
    (r.w, r.i, r.j, r.k)
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

/// The rotation `exp(ψ~)` of the rotation vector `psi`.
#[pyfunction]
fn exp(psi: [f64; 3]) -> Quaternion {
    quaternion(&so3::exp(&vec3(psi)))
}

/// The rotation vector of the rotation `q` (angle in `[0, π]`).
#[pyfunction]
fn log(q: Quaternion) -> [f64; 3] {
    let v = so3::log(&rotation(q));
    [v.x, v.y, v.z]
}

/// The smallest rotation that turns the direction of `a` into that of `b`.
#[pyfunction]
fn rotation_between(a: [f64; 3], b: [f64; 3]) -> Quaternion {
    quaternion(&so3::rotation_between(&vec3(a), &vec3(b)))
}

/// The product `q₁ q₂` (first `q₂`, then `q₁`).
#[pyfunction]
fn compose(q1: Quaternion, q2: Quaternion) -> Quaternion {
    quaternion(&(rotation(q1) * rotation(q2)))
}

/// The inverse rotation.
#[pyfunction]
fn inverse(q: Quaternion) -> Quaternion {
    quaternion(&rotation(q).inverse())
}

/// `q` applied to the vector `v`.
#[pyfunction]
fn rotate(q: Quaternion, v: [f64; 3]) -> [f64; 3] {
    let w = rotation(q) * vec3(v);
    [w.x, w.y, w.z]
}

/// Adds the submodule `so3`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let s = PyModule::new(m.py(), "so3")?;
    s.add_function(wrap_pyfunction!(exp, &s)?)?;
    s.add_function(wrap_pyfunction!(log, &s)?)?;
    s.add_function(wrap_pyfunction!(rotation_between, &s)?)?;
    s.add_function(wrap_pyfunction!(compose, &s)?)?;
    s.add_function(wrap_pyfunction!(inverse, &s)?)?;
    s.add_function(wrap_pyfunction!(rotate, &s)?)?;
    m.add_submodule(&s)?;
    Ok(())
}
