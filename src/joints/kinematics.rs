//! Local configurations of joint elements and their exact differentiation.
//!
//! A joint formula is a function `f(q)` of the configurations of a few
//! nodes (position `x`, orientation `R`) and of coordinate unknowns (the
//! curve parameter of a slider). Its derivatives are taken along the update
//! of the unknowns (docs/theory.md §2): `x ← x + Δx`, `R ← R exp(ΔΘ~)`,
//! coordinates additively. With hyper-dual numbers:
//! - gradient `gᵣ = ∂f/∂qᵣ`: seed unknown `r` with ε₁;
//! - second derivative `Hᵣ꜀ = ∂gᵣ/∂q꜀` (the tangent of a residual
//!   `μ·g`): evaluate at `(q ⊕ ε₂e꜀) ⊕ ε₁eᵣ`, i.e. with
//!   `R (I + ε₂ẽ꜀)(I + ε₁ẽᵣ)`, and read the ε₁ε₂ part. On the rotation
//!   group `H` is not symmetric; this is the matrix the residual's
//!   finite differences see.

use super::hyperdual::{HyperDual, M3, V3};
use crate::so3::{self, Mat3, Vec3};
use crate::state::State;

/// Configuration of an element's nodes and coordinates, in [`HyperDual`]s.
#[derive(Clone, Debug, Default)]
pub struct Conf {
    /// Node positions.
    pub x: Vec<V3<HyperDual>>,
    /// Node orientations (material to global).
    pub r: Vec<M3<HyperDual>>,
    /// Coordinate unknowns.
    pub coords: Vec<HyperDual>,
}

/// The real configuration an element is differentiated at.
#[derive(Clone, Debug, Default)]
pub struct Local {
    /// Node positions.
    pub x: Vec<Vec3>,
    /// Node orientation matrices.
    pub r: Vec<Mat3>,
    /// Coordinate unknowns.
    pub coords: Vec<f64>,
    /// Hyper-dual work configuration.
    conf: Conf,
}

fn hd(v: f64, d1: f64, d2: f64, d12: f64) -> HyperDual {
    HyperDual {
        re: v,
        e1: d1,
        e2: d2,
        e12: d12,
    }
}

impl Local {
    /// Gathers the configuration of `nodes` and of the coordinates
    /// `state.coordinates[coords]`.
    pub fn gather(&mut self, state: &State, nodes: &[usize], coords: std::ops::Range<usize>) {
        self.x.clear();
        self.r.clear();
        self.coords.clear();
        for &n in nodes {
            self.x.push(state.x[n]);
            self.r.push(so3::matrix(&state.q[n]));
        }
        self.coords.extend_from_slice(&state.coordinates[coords]);
    }

    /// Number of local unknowns: 6 per node plus the coordinates.
    pub fn n(&self) -> usize {
        6 * self.x.len() + self.coords.len()
    }

    /// Sets the hyper-dual configuration with unknown `i` seeded with ε₁
    /// and unknown `j` by ε₂ (composition `(q ⊕ ε₂eⱼ) ⊕ ε₁eᵢ`).
    fn set(&mut self, i: Option<usize>, j: Option<usize>) -> &Conf {
        let nn = self.x.len();
        let c = &mut self.conf;
        c.x.resize(nn, V3([HyperDual::default(); 3]));
        c.r.resize(nn, M3([V3([HyperDual::default(); 3]); 3]));
        c.coords.resize(self.coords.len(), HyperDual::default());
        // which component of which node each seed touches
        let split = |k: Option<usize>| match k {
            Some(k) if k < 6 * nn => (Some(k / 6), k % 6, None),
            Some(k) => (None, 0, Some(k - 6 * nn)),
            None => (None, 0, None),
        };
        let (ni, ci, ki) = split(i);
        let (nj, cj, kj) = split(j);
        for n in 0..nn {
            let x = &self.x[n];
            let r = &self.r[n];
            let ti = (ni == Some(n) && ci < 3).then_some(ci);
            let tj = (nj == Some(n) && cj < 3).then_some(cj);
            for a in 0..3 {
                c.x[n].0[a] = hd(
                    x[a],
                    f64::from(ti == Some(a)),
                    f64::from(tj == Some(a)),
                    0.0,
                );
            }
            // R (I + ε₂ẽⱼ)(I + ε₁ẽᵢ) = R + ε₁Rẽᵢ + ε₂Rẽⱼ + ε₁ε₂Rẽⱼẽᵢ
            let ri = (ni == Some(n) && ci >= 3).then(|| so3::skew(&Vec3::ith(ci - 3, 1.0)));
            let rj = (nj == Some(n) && cj >= 3).then(|| so3::skew(&Vec3::ith(cj - 3, 1.0)));
            let d1 = ri.map(|s| r * s);
            let d2 = rj.map(|s| r * s);
            let d12 = match (ri, rj) {
                (Some(si), Some(sj)) => Some(r * sj * si),
                _ => None,
            };
            for col in 0..3 {
                for row in 0..3 {
                    let g = |m: &Option<Mat3>| m.map_or(0.0, |m| m[(row, col)]);
                    c.r[n].0[col].0[row] = hd(r[(row, col)], g(&d1), g(&d2), g(&d12));
                }
            }
        }
        for (k, v) in self.coords.iter().enumerate() {
            c.coords[k] = hd(*v, f64::from(ki == Some(k)), f64::from(kj == Some(k)), 0.0);
        }
        &self.conf
    }

    /// Values of `f` (length `m`) at the real configuration.
    pub fn value<F>(&mut self, m: usize, f: &F, value: &mut [f64])
    where
        F: Fn(&Conf, &mut [HyperDual]),
    {
        let mut out = [HyperDual::default(); MAX_OUT];
        let out = &mut out[..m];
        f(self.set(None, None), out);
        for (v, o) in value.iter_mut().zip(out.iter()) {
            *v = o.re;
        }
    }

    /// Values of `f` and its gradient: `grad[i·n + c] = ∂fᵢ/∂q꜀` over the
    /// `active` unknowns (the others are left untouched).
    pub fn gradient<F>(
        &mut self,
        m: usize,
        active: &[usize],
        f: &F,
        value: &mut [f64],
        grad: &mut [f64],
    ) where
        F: Fn(&Conf, &mut [HyperDual]),
    {
        let n = self.n();
        let mut out = [HyperDual::default(); MAX_OUT];
        let out = &mut out[..m];
        if active.is_empty() {
            return self.value(m, f, value);
        }
        for &c in active {
            f(self.set(Some(c), None), out);
            for i in 0..m {
                value[i] = out[i].re;
                grad[i * n + c] = out[i].e1;
            }
        }
    }

    /// Adds `Σᵢ wᵢ ∂gᵢᵣ/∂q꜀` to `tangent[c·ld + r]` for the active
    /// unknowns `r, c` (column-major with leading dimension `ld`), given
    /// the gradients `grad` (`m × n`, from [`Local::gradient`]).
    ///
    /// Perturbations of different unknowns commute, except two rotations
    /// of the same node: `R(I + ε₂ẽ꜀)(I + ε₁ẽᵣ)` and `R(I + ε₁ẽᵣ)(I + ε₂ẽ꜀)`
    /// differ by `ε₁ε₂ R (e꜀ × eᵣ)~`, so `H꜀ᵣ = Hᵣ꜀ + g_Θ·(eᵣ × e꜀)`. Only
    /// `r ≤ c` is evaluated and the other half follows. When the formula is
    /// affine in the nodes' translations (`affine`), pairs of two
    /// translations are zero and skipped.
    #[allow(clippy::too_many_arguments)]
    pub fn add_weighted_hessian<F>(
        &mut self,
        m: usize,
        active: &[usize],
        f: &F,
        w: &[f64],
        grad: &[f64],
        affine: bool,
        tangent: &mut [f64],
        ld: usize,
    ) where
        F: Fn(&Conf, &mut [HyperDual]),
    {
        if w.iter().all(|&w| w == 0.0) {
            return;
        }
        let n = self.n();
        let node_dofs = 6 * self.x.len();
        let translation = |k: usize| k < node_dofs && k % 6 < 3;
        let rotation = |k: usize| k < node_dofs && k % 6 >= 3;
        let mut out = [HyperDual::default(); MAX_OUT];
        let out = &mut out[..m];
        for (ic, &c) in active.iter().enumerate() {
            for &r in &active[..=ic] {
                if affine && translation(r) && translation(c) {
                    continue;
                }
                f(self.set(Some(r), Some(c)), out);
                let h_rc: f64 = (0..m).map(|i| w[i] * out[i].e12).sum();
                tangent[c * ld + r] += h_rc;
                if r == c {
                    continue;
                }
                let mut h_cr = h_rc;
                if rotation(r) && rotation(c) && r / 6 == c / 6 {
                    // eᵣ × e꜀ = ε_{abk} e_k
                    let (a, b) = (r % 6 - 3, c % 6 - 3);
                    let k = 3 - a - b;
                    let sign = if (a + 1) % 3 == b { 1.0 } else { -1.0 };
                    let gk = 6 * (r / 6) + 3 + k;
                    h_cr += sign * (0..m).map(|i| w[i] * grad[i * n + gk]).sum::<f64>();
                }
                tangent[r * ld + c] += h_cr;
            }
        }
    }
}

/// Work buffers of joint elements, one set per thread, so that no
/// evaluation allocates once the buffers have grown to size.
#[derive(Default)]
pub struct Scratch {
    /// The local configuration.
    pub local: Local,
    /// Gradients, `m × n`.
    pub grad: Vec<f64>,
    /// A second-derivative matrix, `n × n`.
    pub hess: Vec<f64>,
    /// Local velocities.
    pub vel: Vec<f64>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Runs `f` with this thread's work buffers (fresh ones if they are
/// already in use further up the stack).
pub fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with(|s| match s.try_borrow_mut() {
        Ok(mut s) => f(&mut s),
        Err(_) => f(&mut Scratch::default()),
    })
}

/// Largest number of outputs of one joint formula.
pub const MAX_OUT: usize = 8;

/// Where a joint sits on its two bodies A and B. Each body carries a point
/// (offset in the body's material frame) and a triad of joint axes
/// `e₁, e₂, e₃` (columns, material frame); in the reference configuration
/// both triads coincide, and so do both points. Coordinates measure B
/// relative to A.
///
/// Between two nodes, A is the element's first node and B its second. For
/// a joint to the ground, A is the ground (a fixed frame) and B the node
/// (the element's only node), so coordinates measure the node's motion.
#[derive(Clone, Debug, PartialEq)]
pub struct Pair {
    /// Offset of the joint point on A, A's material frame.
    pub a: Vec3,
    /// Joint axes carried by A, A's material frame.
    pub ea: Mat3,
    /// Offset of the joint point on B, B's material frame.
    pub b: Vec3,
    /// Joint axes carried by B, B's material frame.
    pub eb: Mat3,
    /// When A is the ground: its joint point and axes (global).
    pub ground: Option<(Vec3, Mat3)>,
}

/// The joint points and triads in the global frame.
#[derive(Clone, Copy, Debug)]
pub struct Frames {
    /// Joint point of A.
    pub pa: V3<HyperDual>,
    /// Axes of A (columns).
    pub ea: M3<HyperDual>,
    /// Joint point of B.
    pub pb: V3<HyperDual>,
    /// Axes of B (columns).
    pub eb: M3<HyperDual>,
}

impl Pair {
    /// Builds a pair from the reference configuration: the joint point `p`
    /// and the global joint triad `e` (columns `e₁, e₂, e₃`), for the
    /// element's first node at `(x1, r1)` and its second at `(x2, r2)`;
    /// without a second node, the first is B and the ground is A.
    pub fn from_reference(
        p: &Vec3,
        e: &Mat3,
        (x1, r1): (&Vec3, &Mat3),
        second: Option<(&Vec3, &Mat3)>,
    ) -> Self {
        match second {
            Some((x2, r2)) => Self {
                a: r1.transpose() * (p - x1),
                ea: r1.transpose() * e,
                b: r2.transpose() * (p - x2),
                eb: r2.transpose() * e,
                ground: None,
            },
            None => Self {
                a: Vec3::zeros(),
                ea: Mat3::identity(),
                b: r1.transpose() * (p - x1),
                eb: r1.transpose() * e,
                ground: Some((*p, *e)),
            },
        }
    }

    /// A node against a fixed frame with axes `e` (columns), both at the
    /// node's reference position `x` and orientation `r`.
    pub fn node_to_ground(x: &Vec3, r: &Mat3, e: &Mat3) -> Self {
        Self::from_reference(x, e, (x, r), None)
    }

    /// Local node of body B.
    pub fn node_b(&self) -> usize {
        if self.ground.is_some() {
            0
        } else {
            1
        }
    }

    /// Joint points and triads of configuration `c`.
    pub fn frames(&self, c: &Conf) -> Frames {
        let (pa, ea) = match &self.ground {
            Some((p, e)) => (V3::cst(p), M3::cst(e)),
            None => (c.x[0].add(&c.r[0].apply(&self.a)), c.r[0].mul_cst(&self.ea)),
        };
        let nb = self.node_b();
        Frames {
            pa,
            ea,
            pb: c.x[nb].add(&c.r[nb].apply(&self.b)),
            eb: c.r[nb].mul_cst(&self.eb),
        }
    }
}

/// `θ_ref + wrap(θ − θ_ref)`: the branch of an angle nearest to a
/// reference (the value at the last converged state), so that angles are
/// continuous across turns. Only the real part moves.
pub fn unwrap(theta: HyperDual, reference: f64) -> HyperDual {
    use std::f64::consts::TAU;
    let turns = ((reference - theta.re) / TAU).round();
    theta + turns * TAU
}
