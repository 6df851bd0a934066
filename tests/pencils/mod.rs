//! Pencils for the tests and the benchmark of the eigen-solvers
//! (`tests/eigen.rs`, `benches/eigen.rs`): spring–mass chains and a
//! beam-like finite-element pencil with constraints, in the saddle-point
//! form of the assembler.

use unfold::linalg::SparseMatrix;

/// A sparse matrix from `(row, col, value)` triplets (summed).
pub fn sparse(n: usize, t: &[(usize, usize, f64)]) -> SparseMatrix {
    let mut a = SparseMatrix::from_pattern(n, t.iter().map(|&(i, j, _)| (i, j)).collect());
    for &(i, j, v) in t {
        let p = a.position(i, j).unwrap();
        a.values_mut()[p] += v;
    }
    a
}

/// A spring `k` between equations `a` and `b` (`None`: the ground).
pub fn spring(t: &mut Vec<(usize, usize, f64)>, a: Option<usize>, b: Option<usize>, k: f64) {
    for (i, si) in [(a, 1.0), (b, -1.0)] {
        for (j, sj) in [(a, 1.0), (b, -1.0)] {
            if let (Some(i), Some(j)) = (i, j) {
                t.push((i, j, si * sj * k));
            }
        }
    }
}

/// A chain of `n` masses `m` and springs `k`, fixed or free at both ends.
pub fn chain(n: usize, k: f64, m: f64, fixed: bool) -> (SparseMatrix, SparseMatrix, Vec<bool>) {
    let mut kt = Vec::new();
    for i in 0..n.saturating_sub(1) {
        spring(&mut kt, Some(i), Some(i + 1), k);
    }
    if fixed {
        spring(&mut kt, None, Some(0), k);
        spring(&mut kt, Some(n - 1), None, k);
    }
    let mt: Vec<_> = (0..n).map(|i| (i, i, m)).collect();
    (sparse(n, &kt), sparse(n, &mt), vec![false; n])
}

/// A seeded pseudo-random number in [0, 1) (splitmix64).
pub struct Random(pub u64);

impl Random {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A term `(node, component, coefficient)` of a constraint row.
type Term = (usize, usize, f64);

/// A planar Euler–Bernoulli beam of `elements` elements along x (unknowns
/// u, w, θ per node), with random section properties per element (±50 %),
/// lumped translational masses, rotational inertia on every other node
/// only (a singular M), and constraint rows (multipliers numbered after
/// the unknowns of the node they act on): a rigid link tying the axial
/// displacements of two nodes, a pin `u = w = 0` at the first node if
/// `pinned`, `w = 0` at the last if `supported`.
pub fn beam(
    elements: usize,
    pinned: bool,
    supported: bool,
    seed: u64,
) -> (SparseMatrix, SparseMatrix, Vec<bool>) {
    let mut rng = Random(seed);
    let nodes = elements + 1;
    let h = 0.1;
    // constraints: (node, [(node, component, coefficient)])
    let mut constraints: Vec<(usize, Vec<Term>)> = Vec::new();
    if pinned {
        constraints.push((0, vec![(0, 0, 1.0)]));
        constraints.push((0, vec![(0, 1, 1.0)]));
    }
    let (la, lb) = (nodes / 3, 2 * nodes / 3);
    constraints.push((lb, vec![(la, 0, 1.0), (lb, 0, -1.0)]));
    if supported {
        constraints.push((nodes - 1, vec![(nodes - 1, 1, 1.0)]));
    }
    // numbering: each node's 3 unknowns, then the multipliers attached to it
    let mut first = vec![0; nodes];
    let mut lam = vec![0; constraints.len()];
    let mut next = 0;
    for (node, first) in first.iter_mut().enumerate() {
        *first = next;
        next += 3;
        for (c, (at, _)) in constraints.iter().enumerate() {
            if *at == node {
                lam[c] = next;
                next += 1;
            }
        }
    }
    let n = next;
    let mut mult = vec![false; n];
    lam.iter().for_each(|&l| mult[l] = true);
    let mut kt = Vec::new();
    let mut mt = Vec::new();
    for e in 0..elements {
        let ea = 1e6 * (0.5 + rng.next());
        let ei = 1e2 * (0.5 + rng.next());
        let rho_a = 2.0 * (0.5 + rng.next());
        let dofs: Vec<usize> = [e, e + 1]
            .iter()
            .flat_map(|&nd| {
                let f = first[nd];
                (0..3).map(move |c| f + c)
            })
            .collect();
        // axial bar and Euler–Bernoulli bending (u1 w1 θ1 u2 w2 θ2)
        let a = ea / h;
        let (b1, b2, b3, b4) = (
            12.0 * ei / h.powi(3),
            6.0 * ei / h.powi(2),
            4.0 * ei / h,
            2.0 * ei / h,
        );
        let ke = [
            [a, 0.0, 0.0, -a, 0.0, 0.0],
            [0.0, b1, b2, 0.0, -b1, b2],
            [0.0, b2, b3, 0.0, -b2, b4],
            [-a, 0.0, 0.0, a, 0.0, 0.0],
            [0.0, -b1, -b2, 0.0, b1, -b2],
            [0.0, b2, b4, 0.0, -b2, b3],
        ];
        for i in 0..6 {
            for j in 0..6 {
                if ke[i][j] != 0.0 {
                    kt.push((dofs[i], dofs[j], ke[i][j]));
                }
            }
        }
        let half = 0.5 * rho_a * h;
        for nd in [e, e + 1] {
            mt.push((first[nd], first[nd], half));
            mt.push((first[nd] + 1, first[nd] + 1, half));
            if nd % 2 == 0 {
                mt.push((first[nd] + 2, first[nd] + 2, half * h * h / 12.0));
            }
        }
    }
    for (c, (_, row)) in constraints.iter().enumerate() {
        for &(nd, comp, coef) in row {
            kt.push((lam[c], first[nd] + comp, coef));
            kt.push((first[nd] + comp, lam[c], coef));
        }
    }
    (sparse(n, &kt), sparse(n, &mt), mult)
}
