//! Substructuring of flexible bodies (reference paper §5, eq. 20–29;
//! docs/theory.md §18): a linear finite-element model of a body is
//! reduced by the Craig–Bampton method to its boundary nodes and a few
//! fixed-interface modes, and moves in the mechanism as a superelement on
//! a floating frame ([`crate::elements::superelement`]).
//!
//! - [`FlexibleBody`]: the linear model of the body, its stiffness `K`
//!   and mass `M` on the dofs of its mesh nodes (translations and small
//!   rotations in the model's global axes), its node coordinates and the
//!   cells to draw it with. It comes from the project's own elements at
//!   their reference state ([`FlexibleBody::from_model`], assembled as the
//!   modal analysis assembles them) or from imported matrices
//!   ([`import`]: Matrix Market with a dof map, Nastran DMIG punch).
//! - [`craig_bampton::reduce`]: the reduction (boundary nodes keep their 6
//!   dofs; static constraint modes; fixed-interface modes by count or
//!   cut-off frequency from the shift-invert Lanczos of
//!   [`crate::eigen`]), its checks (orthogonality, frequencies of the
//!   reduced body free-free and clamped against the full model's), and
//!   the inertia invariants of the floating-frame formulation
//!   ([`ReducedBody`]).
//! - Recovery: the displacements of every node of the original mesh from
//!   the boundary motion and the modal amplitudes
//!   ([`ReducedBody::recover`]), and the results of the original elements
//!   from them ([`ReducedBody::element_results`]), for the VTK files and
//!   the peak stresses of `summary.json`.

pub mod body;
pub mod craig_bampton;
pub mod import;

pub use body::{FlexibleBody, MeshCell};
pub use craig_bampton::{
    reduce, FrequencyPair, InertiaModel, ModeSelection, ReducedBody, ReductionError,
    ReductionReport, ReductionSettings,
};
