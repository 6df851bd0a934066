//! Input and output: model files in, results out.
//!
//! - [`model_file`]: reads a TOML model file into a validated model, with
//!   errors that name the file, the entity and the problem;
//! - [`results`]: writes per-step CSV histories, `summary.json`, and VTK
//!   files through an [`crate::analysis::Observer`];
//! - [`vtk`]: the VTK unstructured-grid (`.vtu`) and collection (`.pvd`)
//!   writers;
//! - [`plot`]: line charts as SVG files (result histories).

pub mod model_file;
pub mod plot;
pub mod results;
pub mod vtk;
