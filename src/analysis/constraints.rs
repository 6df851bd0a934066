//! Rank of the constraint equations: redundant constraints and
//! indeterminate mechanisms (docs/joints.md §5).
//!
//! The rows of the assembled tangent that belong to multipliers are
//! `−k B` (eq. 18): the constraint gradients over the free unknowns. They
//! are orthogonalised in order (modified Gram–Schmidt, twice, within each
//! group of constraints that share unknowns); a row left with less than
//! [`REDUNDANT`] of its norm is a combination of the rows before it, i.e.
//! a redundant constraint (an over-constrained closed loop: a Bricard
//! linkage, two hinges on one axis). Its multiplier is removed from the
//! system and stays zero; the other multipliers carry the loads.
//!
//! The same basis tells how many motions the constraints leave free: a
//! kinematic analysis requires none.
//!
//! [`ConstraintRows`] evaluates the multiplier rows of the residual,
//! `−kΦ`, from the elements that own multipliers alone.

use crate::dofs::{DofMap, NO_EQUATION};
use crate::elements::{ElementOutput, EvalContext};
use crate::linalg::SparseMatrix;
use crate::model::Model;
use crate::state::State;

/// A row keeping less than this fraction of its norm after
/// orthogonalisation is redundant. Constraint gradients of a sound
/// mechanism are independent to O(1); round-off leaves ~1e-15.
pub const REDUNDANT: f64 = 1e-8;

/// Result of the rank analysis.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConstraintRank {
    /// Redundant multipliers, as indices into
    /// [`crate::state::State::multipliers`].
    pub redundant: Vec<usize>,
    /// Number of free unknowns that are not multipliers.
    pub n_unknowns: usize,
    /// Number of independent constraint equations.
    pub rank: usize,
    /// Free unknowns (dofs) ordered from the least constrained, with the
    /// part of their unit vector the constraints leave free (1: entirely).
    pub freedom: Vec<(usize, f64)>,
}

impl ConstraintRank {
    /// Motions left free by the constraints (0 for a determinate
    /// mechanism).
    pub fn degrees_of_freedom(&self) -> usize {
        self.n_unknowns.saturating_sub(self.rank)
    }
}

fn find(p: &mut [usize], mut i: usize) -> usize {
    while p[i] != i {
        p[i] = p[p[i]];
        i = p[i];
    }
    i
}

/// Analyses the constraint rows of `matrix` (equation numbering of
/// `dofs`); `multiplier[eq]` tells which equations are multipliers.
pub fn analyse(dofs: &DofMap, matrix: &SparseMatrix, multiplier: &[bool]) -> ConstraintRank {
    let n = matrix.dim();
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    for (r, c, v) in matrix.entries() {
        if multiplier[r] && !multiplier[c] && v != 0.0 {
            rows[r].push((c, v));
        }
    }
    // groups of rows sharing unknowns
    let mut parent: Vec<usize> = (0..n).collect();
    for row in &rows {
        for w in row.windows(2) {
            let (a, b) = (find(&mut parent, w[0].0), find(&mut parent, w[1].0));
            parent[a] = b;
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    let mut redundant_eq = Vec::new();
    for (eq, row) in rows.iter().enumerate() {
        if !multiplier[eq] {
            continue;
        }
        match row.first() {
            Some(&(c, _)) => groups.entry(find(&mut parent, c)).or_default().push(eq),
            // a released driver (`k λ = 0`: a diagonal entry, no gradient)
            // is not a constraint now, nor a redundant one
            None if matrix
                .position(eq, eq)
                .is_some_and(|p| matrix.values()[p] != 0.0) => {}
            None => redundant_eq.push(eq),
        }
    }
    let mut rank = 0;
    let mut constrained = vec![0.0f64; n]; // Σ b_j² over the basis
    for eqs in groups.values() {
        // local numbering of the group's columns
        let mut cols: Vec<usize> = eqs
            .iter()
            .flat_map(|&e| rows[e].iter().map(|p| p.0))
            .collect();
        cols.sort_unstable();
        cols.dedup();
        let local = |c: usize| cols.binary_search(&c).expect("column of the group");
        let mut basis: Vec<Vec<f64>> = Vec::new();
        for &eq in eqs {
            let mut v = vec![0.0; cols.len()];
            for &(c, val) in &rows[eq] {
                v[local(c)] += val;
            }
            let norm0 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            for _ in 0..2 {
                for b in &basis {
                    let d: f64 = v.iter().zip(b).map(|(x, y)| x * y).sum();
                    v.iter_mut().zip(b).for_each(|(x, y)| *x -= d * y);
                }
            }
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm <= REDUNDANT * norm0 {
                redundant_eq.push(eq);
            } else {
                v.iter_mut().for_each(|x| *x /= norm);
                basis.push(v);
            }
        }
        rank += basis.len();
        for b in &basis {
            for (k, &c) in cols.iter().enumerate() {
                constrained[c] += b[k] * b[k];
            }
        }
    }
    let mut redundant: Vec<usize> = redundant_eq
        .iter()
        .filter_map(|&eq| dofs.multiplier_index(dofs.dof(eq)))
        .collect();
    redundant.sort_unstable();
    let mut freedom: Vec<(usize, f64)> = (0..n)
        .filter(|&eq| !multiplier[eq])
        .map(|eq| (dofs.dof(eq), (1.0 - constrained[eq]).max(0.0)))
        .collect();
    freedom.sort_by(|a, b| b.1.total_cmp(&a.1));
    ConstraintRank {
        redundant,
        n_unknowns: freedom.len(),
        rank,
        freedom,
    }
}

/// The multiplier rows of the residual, `−kΦ` (eq. 18), and of the
/// matrices, evaluated from the elements that own multipliers (joints,
/// drivers, latches, stops, rolling discs) without the others: a
/// multiplier's row, and its column, are written by its own element alone,
/// so these rows are those of a whole assembly, to the bit, at the cost of
/// the constraints only (the beams and bodies of the model are not
/// evaluated).
#[derive(Clone, Debug, Default)]
pub struct ConstraintRows {
    /// Per element with multipliers: its index, the local index of its
    /// first multiplier and the start of its local dofs in `dofs`.
    owners: Vec<(usize, usize, usize)>,
    /// The dofs of the owners' local unknowns, one after the other (the
    /// nodes' six, the element's coordinates, then its multipliers).
    dofs: Vec<usize>,
    /// Local residual, stiffness and inertia matrix of one element.
    residual: Vec<f64>,
    stiffness: Vec<f64>,
    inertia: Vec<f64>,
    /// The equation of every dof when `scatter` was built.
    numbering: Vec<usize>,
    /// Per owner, the local entries in a multiplier row or column and
    /// their positions in the matrix: `(owner, j n + i, position)`.
    scatter: Vec<(usize, usize, usize)>,
}

impl ConstraintRows {
    /// The elements of `model` that own multipliers, numbered by `dofs`.
    pub fn new(model: &Model, dofs: &DofMap) -> Self {
        let mut rows = Self::default();
        let mut longest = 0;
        for (i, e) in model.elements.iter().enumerate() {
            if e.n_multipliers() == 0 {
                continue;
            }
            let first = e.n_local() - e.n_multipliers();
            rows.owners.push((i, first, rows.dofs.len()));
            rows.dofs.extend(dofs.element_dofs(model, i));
            longest = longest.max(e.n_local());
        }
        rows.residual = vec![0.0; longest];
        rows.stiffness = vec![0.0; longest * longest];
        rows.inertia = vec![0.0; longest * longest];
        rows
    }

    /// Writes the multiplier rows of the residual at `state` (`ctx.need`
    /// the residual alone) into `rows`, by dof; the other entries of `rows`
    /// are left as they are.
    pub fn evaluate(&mut self, model: &Model, ctx: &EvalContext, state: &State, rows: &mut [f64]) {
        for &(i, first, start) in &self.owners {
            let e = &model.elements[i];
            let n = e.n_local();
            let local = &mut self.residual[..n];
            local.fill(0.0);
            e.evaluate(ctx, state, &mut ElementOutput::residual(local));
            for (&d, &r) in self.dofs[start + first..start + n]
                .iter()
                .zip(&local[first..])
            {
                rows[d] = r;
            }
        }
    }

    /// Sets `stiffness` (on the pattern of the assembled matrix, in the
    /// equation numbering of `dofs`) to the stiffness of the elements with
    /// multipliers at `state` (`ctx.need` with the stiffness; the inertia
    /// matrix, if asked, is computed and dropped): exact in every
    /// multiplier row and column, zero elsewhere.
    pub fn stiffness(
        &mut self,
        model: &Model,
        dofs: &DofMap,
        ctx: &EvalContext,
        state: &State,
        stiffness: &mut SparseMatrix,
    ) {
        let renumbered = self.numbering.len() != dofs.n_dofs()
            || (0..dofs.n_dofs()).any(|d| self.numbering[d] != dofs.equation(d));
        if renumbered {
            self.place(dofs, stiffness);
        }
        let values = stiffness.values_mut();
        values.fill(0.0);
        let mut entries = self.scatter.iter().peekable();
        for (o, &(i, _, _)) in self.owners.iter().enumerate() {
            let e = &model.elements[i];
            let n = e.n_local();
            let (residual, k) = (&mut self.residual[..n], &mut self.stiffness[..n * n]);
            residual.fill(0.0);
            k.fill(0.0);
            let inertia = ctx.need.inertia.map(|_| {
                let d = &mut self.inertia[..n * n];
                d.fill(0.0);
                d
            });
            let mut out = ElementOutput {
                residual,
                stiffness: Some(k),
                inertia,
            };
            e.evaluate(ctx, state, &mut out);
            let k = &self.stiffness[..n * n];
            while let Some(&&(_, local, position)) = entries.peek().filter(|s| s.0 == o) {
                values[position] += k[local];
                entries.next();
            }
        }
    }

    /// Builds `scatter` for the numbering of `dofs` and the pattern of
    /// `matrix`.
    fn place(&mut self, dofs: &DofMap, matrix: &SparseMatrix) {
        self.numbering.clear();
        self.numbering
            .extend((0..dofs.n_dofs()).map(|d| dofs.equation(d)));
        self.scatter.clear();
        for (o, &(_, first, start)) in self.owners.iter().enumerate() {
            let end = self
                .owners
                .get(o + 1)
                .map_or(self.dofs.len(), |next| next.2);
            let local = &self.dofs[start..end];
            let n = local.len();
            for (j, &cj) in local.iter().enumerate() {
                for (i, &ri) in local.iter().enumerate() {
                    let (row, col) = (dofs.equation(ri), dofs.equation(cj));
                    if (i < first && j < first) || row == NO_EQUATION || col == NO_EQUATION {
                        continue;
                    }
                    if let Some(p) = matrix.position(row, col) {
                        self.scatter.push((o, j * n + i, p));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Assembler;
    use crate::dofs::DofKind;
    use crate::elements::Need;
    use crate::io::model_file::parse_model;
    use crate::so3::Vec3;
    use std::path::Path;

    /// Models with joints of every kind, drivers, a hinge law, latches,
    /// sliders' coordinates, beams and bodies.
    const MODELS: [(&str, &str); 5] = [
        (
            "slider_crank",
            include_str!("../../examples/slider_crank.toml"),
        ),
        ("four_bar", include_str!("../../examples/four_bar.toml")),
        (
            "hinge_lock_cycle",
            include_str!("../../examples/hinge_lock_cycle.toml"),
        ),
        (
            "every_table",
            include_str!("../../tests/data/every_table.toml"),
        ),
        (
            "latched_panels",
            include_str!("../../tests/data/latched_panels.toml"),
        ),
    ];

    /// The rows and the stiffness of the elements with multipliers, at a
    /// state moved off the initial one with velocities and multipliers,
    /// equal those of the whole assembly to the bit in every multiplier row
    /// and column (a multiplier's row and column are written by its own
    /// element alone), and the stiffness is zero elsewhere.
    #[test]
    fn constraint_rows_are_those_of_the_whole_assembly() {
        for (name, text) in MODELS {
            let input = parse_model(text, Path::new(name)).expect("the model parses");
            let model = Model::from_input(&input).expect("the model is valid");
            let dofs = DofMap::new(&model);
            let mut assembler = Assembler::new(&model, &dofs);
            let mut state = model.initial_state();
            for node in 0..state.n_nodes() {
                let k = node as f64 + 1.0;
                state.displace_node(
                    node,
                    &Vec3::new(0.01 * k, -0.02, 0.015 * k),
                    &Vec3::new(0.03, 0.02 * k, -0.01),
                );
                state.velocity[node] = [0.1 * k, -0.2, 0.3, 0.4, -0.1 * k, 0.2];
            }
            for (i, m) in state.multipliers.iter_mut().enumerate() {
                *m = 0.5 + i as f64;
            }
            state.time = 0.3;
            let mut rows = ConstraintRows::new(&model, &dofs);
            assert!(
                !rows.owners.is_empty(),
                "{name}: no element with multipliers"
            );

            let ctx = model.context(state.time, Need::RESIDUAL);
            assembler.assemble(&model, &ctx, &state);
            let mut residual = vec![f64::NAN; dofs.n_dofs()];
            rows.evaluate(&model, &ctx, &state, &mut residual);
            for d in dofs.first_multiplier()..dofs.n_dofs() {
                assert_eq!(residual[d], assembler.residual[d], "{name}: dof {d}");
            }

            let ctx = EvalContext {
                dynamics: true,
                ..model.context(state.time, Need::with_inertia(0.0, 1.0))
            };
            let (mut k, mut m) = (assembler.matrix.clone(), assembler.matrix.clone());
            assembler.assemble_split(&model, &ctx, &state, &mut k, &mut m);
            let mut own = assembler.matrix.clone();
            own.values_mut().fill(f64::NAN);
            rows.stiffness(&model, &dofs, &ctx, &state, &mut own);
            let multiplier = |eq: usize| matches!(dofs.equation_kind(eq), DofKind::Multiplier(_));
            let mut compared = 0;
            for ((row, col, whole), (_, _, part)) in k.entries().zip(own.entries()) {
                if multiplier(row) || multiplier(col) {
                    assert_eq!(part, whole, "{name}: entry ({row}, {col})");
                    compared += usize::from(whole != 0.0);
                } else {
                    assert_eq!(part, 0.0, "{name}: entry ({row}, {col})");
                }
            }
            assert!(compared > 0, "{name}: no constraint gradient compared");
        }
    }
}
