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

use crate::dofs::DofMap;
use crate::linalg::SparseMatrix;

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
