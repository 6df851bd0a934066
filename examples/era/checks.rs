//! Kinematic and static checks of the design, and the counts.
//!
//! - [`rank`]: the rank of the constraints of the rigid-link model
//!   (docs/joints.md §5): the motions the joints leave free with the
//!   mid-hinges locked (none: a structure) or free (one: the deployment,
//!   the count of `examples/era.md`);
//! - [`zero_modes`]: the zero eigenvalues of the stiffness of the
//!   flexible model on its constraints (`K x + Bᵀμ = λ W x`, `B x = 0`,
//!   `W` a unit metric): the mechanisms of the model with its beams;
//! - [`counts`]: unknowns and the mean bandwidth of the tangent.

use std::error::Error;

use unfold::analysis::preflight;
use unfold::analysis::statics::StaticError;
use unfold::assembly::Assembler;
use unfold::dofs::{DofKind, DofMap};
use unfold::eigen::{self, EigenSettings, Method, ModalSolution, Pencil};
use unfold::elements::Need;
use unfold::linalg::SparseMatrix;
use unfold::model::builder::Analysis;
use unfold::model::Model;

use super::geometry::Geometry;
use super::hinge::Hinges;
use super::model::{build, Built, Members, Options};

/// The rank analysis of the rigid-link model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rank {
    /// Unknowns (node components of the links, multipliers).
    pub unknowns: usize,
    /// Motions the joints, locks and the support leave free.
    pub free_motions: usize,
    /// Constraint equations repeating others (`None` when the model is a
    /// mechanism: the analysis stops before it counts them).
    pub redundant: Option<usize>,
}

/// The rigid-link model at scale `scale` with the mid-hinges as
/// `hinges` and a clamped longeron, prepared for a kinematic analysis.
pub fn rigid_links(geometry: &Geometry, scale: f64, hinges: Hinges) -> Built {
    let options = Options {
        scale,
        members: Members::Rigid,
        hinges,
        support: true,
        gravity: None,
        analysis: Analysis::kinematic().into_input(),
    };
    build(geometry, &options, "rank of the rigid-link model")
}

/// The rank of the constraints of the rigid-link model (every member a
/// rigid link, one longeron clamped) at `scale` with the mid-hinges as
/// `hinges`: what a kinematic analysis checks before it starts.
pub fn rank(geometry: &Geometry, scale: f64, hinges: Hinges) -> Result<Rank, Box<dyn Error>> {
    let built = rigid_links(geometry, scale, hinges);
    let model = Model::from_input(&built.input)?;
    let unknowns = DofMap::new(&model).n_equations();
    let settings = Analysis::kinematic().settings()?;
    match preflight::check(&model, &settings) {
        Ok(p) => Ok(Rank {
            unknowns,
            free_motions: p.free_motions,
            redundant: Some(p.redundant_constraints),
        }),
        Err(StaticError::Indeterminate { free, .. }) => Ok(Rank {
            unknowns,
            free_motions: free,
            redundant: None,
        }),
        Err(e) => Err(e.into()),
    }
}

/// The tangent of `model` at `t = 0` in the reference configuration, its
/// equation numbering and which equations are multipliers.
fn tangent(model: &Model) -> (DofMap, SparseMatrix, Vec<bool>) {
    let dofs = DofMap::new(model);
    let mut assembler = Assembler::new(model, &dofs);
    let mut state = model.initial_state();
    model.apply_prescribed(&mut state, 0.0);
    assembler.assemble(model, &model.context(0.0, Need::STIFFNESS), &state);
    let multiplier = (0..dofs.n_equations())
        .map(|eq| matches!(dofs.equation_kind(eq), DofKind::Multiplier(_)))
        .collect();
    (dofs, assembler.matrix, multiplier)
}

/// The `modes` lowest eigenvalues of the stiffness of `model` on its
/// constraints, `K x + Bᵀμ = λ W x`, with the unit metric `W` (1 on
/// translations, `ℓ²` on rotations, `ℓ` the model's length scale): the
/// zero ones are its rigid-body motions and mechanisms; the lowest
/// non-zero one is the stiffness (N/m) of its softest deformation, per
/// unit of `|u|² + ℓ²|θ|²`.
pub fn zero_modes(model: &Model, modes: usize) -> Result<ModalSolution, Box<dyn Error>> {
    let (dofs, k, multiplier) = tangent(model);
    let n = dofs.n_equations();
    let l2 = model.length_scale * model.length_scale;
    let mut w = SparseMatrix::from_pattern(n, (0..n).map(|i| (i, i)).collect());
    for eq in 0..n {
        let p = w.position(eq, eq).expect("diagonal");
        w.values_mut()[p] = match dofs.equation_kind(eq) {
            DofKind::Translation => 1.0,
            DofKind::Rotation => l2,
            DofKind::Coordinate { length } => length * length,
            DofKind::Multiplier(_) => 0.0,
        };
    }
    let pencil = Pencil {
        stiffness: &k,
        mass: &w,
        multiplier: &multiplier,
    };
    let settings = EigenSettings {
        method: Method::Auto,
        ..EigenSettings::lowest(modes)
    };
    Ok(eigen::solve(&pencil, &settings)?)
}

/// Sizes of a model's system of equations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Counts {
    /// Nodes.
    pub nodes: usize,
    /// Unknowns: free node components and multipliers.
    pub unknowns: usize,
    /// Of which multipliers.
    pub multipliers: usize,
    /// Mean bandwidth of the tangent numbered by reverse Cuthill–McKee
    /// ([`mean_bandwidth`]).
    pub mean_bandwidth: f64,
    /// The same in the order the model numbers its unknowns (nodes in the
    /// order they were built, then the multipliers).
    pub mean_bandwidth_as_built: f64,
}

/// The counts of `model`.
pub fn counts(model: &Model) -> Counts {
    let (dofs, k, multiplier) = tangent(model);
    let identity: Vec<usize> = (0..k.dim()).collect();
    Counts {
        nodes: model.n_nodes(),
        unknowns: dofs.n_equations(),
        multipliers: multiplier.iter().filter(|&&m| m).count(),
        mean_bandwidth: mean_bandwidth(&k),
        mean_bandwidth_as_built: skyline(&adjacency(&k), &identity),
    }
}

/// The symmetric adjacency of the pattern of `a`, diagonal left out.
fn adjacency(a: &SparseMatrix) -> Vec<Vec<usize>> {
    let mut adjacency: Vec<Vec<usize>> = vec![Vec::new(); a.dim()];
    for (i, j, _) in a.entries() {
        if i != j {
            adjacency[i].push(j);
            adjacency[j].push(i);
        }
    }
    for list in &mut adjacency {
        list.sort_unstable();
        list.dedup();
    }
    adjacency
}

/// The mean skyline height `(1/n) Σᵢ (i − fᵢ + 1)` of the graph
/// `adjacency` numbered by `position` (`fᵢ` the lowest number among row
/// `i` and its neighbours).
fn skyline(adjacency: &[Vec<usize>], position: &[usize]) -> f64 {
    let mut profile = 0usize;
    for (v, list) in adjacency.iter().enumerate() {
        let i = position[v];
        let first = list.iter().map(|&u| position[u]).fold(i, usize::min);
        profile += i - first + 1;
    }
    profile as f64 / adjacency.len().max(1) as f64
}

/// The mean bandwidth of the symmetric pattern of `a` numbered by the
/// reverse Cuthill–McKee ordering: the mean height of the skyline,
/// `(1/n) Σᵢ (i − fᵢ + 1)`, `fᵢ` the first column of row `i` (diagonal
/// included), which is what a profile (skyline) solver of the time
/// stored and what the paper's "mean bandwidth" measures.
///
/// Reverse Cuthill–McKee (George & Liu, *Computer Solution of Large
/// Sparse Positive Definite Systems*, 1981, §4.3): from a
/// pseudo-peripheral vertex, number by breadth-first levels, neighbours
/// by increasing degree, then reverse.
pub fn mean_bandwidth(a: &SparseMatrix) -> f64 {
    let n = a.dim();
    if n == 0 {
        return 0.0;
    }
    let adjacency = adjacency(a);
    let degree: Vec<usize> = adjacency.iter().map(Vec::len).collect();

    // breadth-first levels from `root` within the unnumbered vertices
    let levels = |root: usize, numbered: &[bool]| -> Vec<Vec<usize>> {
        let mut seen = numbered.to_vec();
        seen[root] = true;
        let mut levels = vec![vec![root]];
        loop {
            let mut next = Vec::new();
            for &v in levels.last().expect("a level") {
                for &u in &adjacency[v] {
                    if !seen[u] {
                        seen[u] = true;
                        next.push(u);
                    }
                }
            }
            if next.is_empty() {
                return levels;
            }
            levels.push(next);
        }
    };

    let mut order = Vec::with_capacity(n);
    let mut numbered = vec![false; n];
    while order.len() < n {
        // pseudo-peripheral root of the next component: from its vertex of
        // least degree, move to a least-degree vertex of the last level
        // while the eccentricity grows
        let start = (0..n)
            .filter(|&v| !numbered[v])
            .min_by_key(|&v| degree[v])
            .expect("an unnumbered vertex");
        let mut root = start;
        let mut depth = levels(root, &numbered).len();
        loop {
            let last = levels(root, &numbered).pop().expect("a level");
            let candidate = *last.iter().min_by_key(|&&v| degree[v]).expect("a vertex");
            let d = levels(candidate, &numbered).len();
            if d > depth {
                root = candidate;
                depth = d;
            } else {
                break;
            }
        }
        // Cuthill–McKee from the root
        let first = order.len();
        order.push(root);
        numbered[root] = true;
        let mut head = first;
        while head < order.len() {
            let v = order[head];
            head += 1;
            let mut next: Vec<usize> = adjacency[v]
                .iter()
                .copied()
                .filter(|&u| !numbered[u])
                .collect();
            next.sort_by_key(|&u| degree[u]);
            for u in next {
                numbered[u] = true;
                order.push(u);
            }
        }
    }
    order.reverse();
    let mut position = vec![0; n];
    for (p, &v) in order.iter().enumerate() {
        position[v] = p;
    }
    skyline(&adjacency, &position)
}
