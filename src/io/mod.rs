//! Input and output: model files in, results out.
//!
//! - [`modes`]: the result files of modal analyses (`modes.csv`,
//!   `mode_shapes.csv`, a grid per mode and `modes.pvd`);
//! - [`model_file`]: reads a TOML model file into a validated model, with
//!   errors that name the file, the entity and the problem;
//! - [`results`]: writes per-step CSV histories, `summary.json`, and VTK
//!   files through an [`crate::analysis::Observer`];
//! - [`run`]: the record of a whole run (results, `log.txt`, summary,
//!   stopping on a signal), shared by the command-line tool and the
//!   programs that use the library;
//! - [`restart`]: restart files, the state of a run from which a later
//!   run continues;
//! - [`vtk`]: the VTK unstructured-grid (`.vtu`) and collection (`.pvd`)
//!   writers;
//! - [`peaks`]: the largest loads of latches, stops and contacts over a
//!   run, for `summary.json`;
//! - [`number`]: numbers in scientific notation for `log.txt`;
//! - [`line`]: a line of `log.txt` built as bytes, numbers written
//!   straight into it;
//! - [`residual`]: the relative residual as `log.txt` reports it, with
//!   groups at round-off told apart;
//! - [`plot`]: line charts of result histories, as SVG and PNG files;
//! - [`histories`]: the charts of a run for a report (joint coordinates,
//!   hinge moments, energies), drawn from its result files;
//! - [`view`]: the page that animates a run in a web browser
//!   (`unfold view`), made from its result files.

pub mod histories;
pub mod line;
pub mod model_file;
pub mod modes;
pub mod number;
pub mod peaks;
pub mod plot;
pub mod residual;
pub mod restart;
pub mod results;
pub mod run;
pub mod view;
pub mod vtk;
