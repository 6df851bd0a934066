//! The linear model of a flexible body before reduction.
//!
//! Its unknowns ("dofs") are components of its mesh nodes: translations
//! `u` and small rotations `θ`, both in the model's global axes at the
//! reference configuration (the convention of a linear finite-element
//! code, whose rotational dofs are infinitesimal rotations about the
//! global axes). A node may carry fewer than six dofs (the translations
//! alone of a solid mesh); the boundary nodes of a reduction carry all
//! six.

use crate::assembly::Assembler;
use crate::dofs::DofMap;
use crate::elements::{CellShape, Need};
use crate::linalg::SparseMatrix;
use crate::model::{Id, Model};
use crate::so3::{self, Mat3, Rotation, Vec3};

/// A cell of the original mesh, drawn in the VTK files.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MeshCell {
    /// Its mesh nodes (indices into [`FlexibleBody::node_ids`]): 1 for a
    /// vertex, 2 for a line, 3 for a triangle, 4 for a quadrilateral (in
    /// order around it).
    pub nodes: Vec<usize>,
    /// The original element it draws (index into the elements of
    /// [`FlexibleBody::elements`]), if the body has them.
    pub element: Option<usize>,
}

/// The linear model of a flexible body: mesh, stiffness and mass.
pub struct FlexibleBody {
    /// Ids of the mesh nodes (in the body's own numbering).
    pub node_ids: Vec<Id>,
    /// Reference positions of the mesh nodes, model global frame.
    pub positions: Vec<Vec3>,
    /// Reference orientations of the mesh nodes (material to global;
    /// the identity for imported matrices), to recover their rotations
    /// and the results of the original elements.
    pub orientations: Vec<Rotation>,
    /// The node and component (0–2 translations, 3–5 rotations) of each
    /// row of the matrices.
    pub dofs: Vec<(usize, usize)>,
    /// Stiffness `K`, symmetric.
    pub stiffness: SparseMatrix,
    /// Mass `M`, symmetric positive semi-definite.
    pub mass: SparseMatrix,
    /// Cells to draw the mesh with.
    pub cells: Vec<MeshCell>,
    /// The original elements, when the body is a model of the project's
    /// own elements: their results at a recovered state are the stresses
    /// of the body ([`super::ReducedBody::element_results`]).
    pub elements: Option<Model>,
    /// Where the body was placed in the model ([`FlexibleBody::placed`]):
    /// `(p, Q)` with `X = p + Q X_own`. The original elements stay in
    /// their own coordinates `X_own`: a recovered state is taken back
    /// there for their results.
    pub placement: (Vec3, Rotation),
}

impl std::fmt::Debug for FlexibleBody {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FlexibleBody")
            .field("nodes", &self.node_ids.len())
            .field("dofs", &self.dofs.len())
            .field("cells", &self.cells.len())
            .finish()
    }
}

/// A square sparse matrix from `(row, column, value)` triplets, duplicates
/// summed.
pub fn from_triplets(n: usize, triplets: &[(usize, usize, f64)]) -> SparseMatrix {
    let mut a = SparseMatrix::from_pattern(n, triplets.iter().map(|t| (t.0, t.1)).collect());
    for &(i, j, v) in triplets {
        let p = a.position(i, j).expect("an entry of the pattern");
        a.values_mut()[p] += v;
    }
    a
}

impl FlexibleBody {
    /// The body made of the elements of `model` (beams, rigid bodies,
    /// point masses; later shells) at its reference state: `K = ∂r/∂q` and
    /// `M = ∂r/∂v̇` of every element assembled once on the model's own
    /// numbering, as the modal analysis does
    /// ([`crate::analysis::ModalAnalysis`]), without gravity, then carried
    /// from the material rotation increments `ΔΘ` of the node unknowns to
    /// the global small rotations `θ = R₀ ΔΘ` (`K ← T K Tᵀ`, `T` the block
    /// diagonal of `I` and the reference orientations `R₀`). The model's
    /// supports are ignored: a body is reduced free. Every node carries six
    /// dofs.
    pub fn from_model(model: Model) -> Self {
        let n_nodes = model.n_nodes();
        let dofs = DofMap::new(&model);
        let mut assembler = Assembler::new(&model, &dofs);
        let (mut k, mut m) = (assembler.matrix.clone(), assembler.matrix.clone());
        let mut state = model.initial_state();
        model.apply_prescribed(&mut state, 0.0);
        let ctx = crate::elements::EvalContext {
            gravity: Vec3::zeros(),
            ..model.context(0.0, Need::with_inertia(0.0, 1.0))
        };
        assembler.assemble_split(&model, &ctx, &state, &mut k, &mut m);
        let rotations: Vec<Mat3> = model.reference_q.iter().map(so3::matrix).collect();
        let global = |a: &SparseMatrix| -> SparseMatrix {
            let mut triplets = Vec::with_capacity(3 * a.nnz());
            for (r, c, v) in a.entries() {
                if v == 0.0 {
                    continue;
                }
                let (dr, dc) = (dofs.dof(r), dofs.dof(c));
                if dr >= 6 * n_nodes || dc >= 6 * n_nodes {
                    // coordinates and multipliers of joints: not part of
                    // a linear body
                    continue;
                }
                let (ni, ci) = (dr / 6, dr % 6);
                let (nj, cj) = (dc / 6, dc % 6);
                // T K Tᵀ: a rotation row spreads over the three global
                // components by Rᵢ, a rotation column by Rⱼᵀ
                let spread = |n: usize, c: usize| -> [(usize, f64); 3] {
                    if c < 3 {
                        [(6 * n + c, 1.0), (usize::MAX, 0.0), (usize::MAX, 0.0)]
                    } else {
                        let r = &rotations[n];
                        [
                            (6 * n + 3, r[(0, c - 3)]),
                            (6 * n + 4, r[(1, c - 3)]),
                            (6 * n + 5, r[(2, c - 3)]),
                        ]
                    }
                };
                for (gi, wi) in spread(ni, ci) {
                    for (gj, wj) in spread(nj, cj) {
                        if gi != usize::MAX && gj != usize::MAX && wi * wj != 0.0 {
                            triplets.push((gi, gj, wi * v * wj));
                        }
                    }
                }
            }
            symmetric_part(&from_triplets(6 * n_nodes, &triplets))
        };
        let (stiffness, mass) = (global(&k), global(&m));
        let cells = model
            .elements
            .iter()
            .enumerate()
            .filter_map(|(e, el)| {
                let shape = el.cell_shape();
                (shape != CellShape::None).then(|| MeshCell {
                    nodes: el.nodes()[..shape.nodes()].to_vec(),
                    element: Some(e),
                })
            })
            .collect();
        Self {
            node_ids: model.node_ids.clone(),
            positions: model.reference_x.clone(),
            orientations: model.reference_q.clone(),
            dofs: (0..6 * n_nodes).map(|d| (d / 6, d % 6)).collect(),
            stiffness,
            mass,
            cells,
            elements: Some(model),
            placement: (Vec3::zeros(), Rotation::identity()),
        }
    }

    /// Number of dofs (rows of the matrices).
    pub fn n_dofs(&self) -> usize {
        self.dofs.len()
    }

    /// Index of the mesh node with id `id`.
    pub fn node_index(&self, id: Id) -> Option<usize> {
        self.node_ids.iter().position(|&n| n == id)
    }

    /// Row of each component of each node (`None` where the node has no
    /// such dof).
    pub fn dof_rows(&self) -> Vec<[Option<usize>; 6]> {
        let mut rows = vec![[None; 6]; self.node_ids.len()];
        for (r, &(n, c)) in self.dofs.iter().enumerate() {
            rows[n][c] = Some(r);
        }
        rows
    }

    /// The body moved rigidly from its own coordinates to the model's:
    /// `X ← p + Q X`, orientations `R ← Q R`, and the matrices carried to
    /// the new axes (`K ← T K Tᵀ`, `T` of 3 × 3 blocks `Q` on the
    /// translations and on the rotations of each node). A node whose
    /// translations or rotations are only partly dofs cannot be turned
    /// (its missing components would mix with the others): `Err` with its
    /// id.
    pub fn placed(mut self, position: Vec3, rotation: &Rotation) -> Result<Self, Id> {
        let q = so3::matrix(rotation);
        if q != Mat3::identity() {
            let rows = self.dof_rows();
            for (n, r) in rows.iter().enumerate() {
                for group in [&r[0..3], &r[3..6]] {
                    let count = group.iter().filter(|x| x.is_some()).count();
                    if count != 0 && count != 3 {
                        return Err(self.node_ids[n]);
                    }
                }
            }
            let turn = |a: &SparseMatrix| -> SparseMatrix {
                let mut triplets = Vec::with_capacity(9 * a.nnz());
                for (r, c, v) in a.entries() {
                    let (nr, cr) = self.dofs[r];
                    let (nc, cc) = self.dofs[c];
                    let (gr, gc) = (cr / 3 * 3, cc / 3 * 3);
                    for i in 0..3 {
                        for j in 0..3 {
                            let w = q[(i, cr - gr)] * q[(j, cc - gc)];
                            if w != 0.0 {
                                let (ri, cj) = (rows[nr][gr + i], rows[nc][gc + j]);
                                if let (Some(ri), Some(cj)) = (ri, cj) {
                                    triplets.push((ri, cj, w * v));
                                }
                            }
                        }
                    }
                }
                from_triplets(a.dim(), &triplets)
            };
            self.stiffness = turn(&self.stiffness);
            self.mass = turn(&self.mass);
        }
        for x in &mut self.positions {
            *x = position + q * *x;
        }
        for r in &mut self.orientations {
            *r = rotation * *r;
        }
        // composed with an earlier placement: X = p + Q (p₀ + Q₀ X_own)
        let (p0, q0) = self.placement;
        self.placement = (position + q * p0, rotation * q0);
        Ok(self)
    }
}

/// `(A + Aᵀ)/2` on the union of both patterns.
pub fn symmetric_part(a: &SparseMatrix) -> SparseMatrix {
    let mut triplets = Vec::with_capacity(2 * a.nnz());
    for (r, c, v) in a.entries() {
        triplets.push((r, c, 0.5 * v));
        triplets.push((c, r, 0.5 * v));
    }
    from_triplets(a.dim(), &triplets)
}
