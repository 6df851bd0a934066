//! # unfold
//!
//! Finite-element simulation of flexible mechanisms: geometrically exact
//! beams, rigid bodies, springs and (later) kinematic joints, for the
//! deployment analysis of space structures.
//!
//! The crate follows the formulation of Cardona & Géradin (the reference
//! paper, `docs/theory.md`): nodes carry positions and orientations,
//! rotations are updated on the group with incremental material rotation
//! vectors, and every component of the mechanism is an element contributing
//! a residual and a consistent tangent to a Newton–Raphson solution.
//!
//! Layout:
//! - [`so3`]: finite rotations (exponential, logarithm, tangent operators);
//! - [`model`]: the model definition (file schema, and the builders of
//!   [`model::builder`] in Rust) and its validated form;
//! - [`state`]: positions, orientations, coordinates, multipliers and their
//!   rates, and the one update rule `q ⊕ Δq`;
//! - [`elements`]: beams, rigid bodies, springs, nodal loads (residual,
//!   stiffness and inertia matrix from one evaluation);
//! - [`dofs`], [`assembly`], [`linalg`]: numbering, sparse assembly, sparse
//!   direct solver;
//! - [`analysis`]: Newton–Raphson, the step controller, the nonlinear
//!   static analysis and its settings;
//! - [`reduction`]: Craig–Bampton reduction of flexible bodies (imported
//!   matrices or the project's own elements) into superelements;
//! - [`eigen`]: eigen-solvers of modal analysis (dense null-space and
//!   shift-invert Lanczos);
//! - [`io`]: model files in, results (CSV, JSON, VTK) out.
//!
//! ```
//! use std::sync::Arc;
//! use unfold::analysis::{NoObserver, StaticAnalysis};
//! use unfold::model::builder::*;
//!
//! // a 2 m cantilever of 8 elements (EI = 1e5 N·m²) with a 1 N tip load
//! let mut m = ModelBuilder::new("cantilever");
//! let (root, tip) = (m.node([0.0, 0.0, 0.0]), m.node([2.0, 0.0, 0.0]));
//! let s = m.section(Section::diagonal(1e8, 4e7, 4e7, 1e5, 1e5, 1e5));
//! m.add(BeamLine::between(root, tip, 8, s).orientation([0.0, 0.0, 1.0]));
//! m.fix(root, Dofs::ALL);
//! m.add(Load::force(tip, [0.0, 0.0, -1.0]));
//! let model = Arc::new(m.build().unwrap());
//! // the analysis settings live beside the model: statics from t = 0 to 1
//! let settings = Analysis::statics().settings().unwrap();
//! let outcome = StaticAnalysis::new(model.clone(), settings).run(model.initial_state(), &mut NoObserver);
//! assert!(outcome.error.is_none());
//! // tip deflection ≈ P L³/3EI = 8/3e5, within 1 % with 8 elements
//! let tip = outcome.state.x[model.node(tip)].z;
//! assert!((tip + 8.0 / 3e5).abs() < 1e-2 * 8.0 / 3e5);
//! ```
//!
//! The same model can be read from a model file
//! ([`io::model_file::read_model`], docs/model-format.md, which gives the
//! model and its analyses), or written as the file schema
//! [`model::input::ModelInput`] directly.

#![warn(missing_docs)]
#![allow(non_snake_case)]
// index loops read better than iterator chains in the numerical kernels
#![allow(clippy::needless_range_loop)]

pub mod analysis;
pub mod assembly;
pub mod curves;
pub mod dofs;
pub mod eigen;
pub mod elements;
pub mod io;
pub mod joints;
pub mod linalg;
pub mod model;
pub mod reduction;
pub mod so3;
pub mod state;

/// The Rust example of README.md, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeExample;
