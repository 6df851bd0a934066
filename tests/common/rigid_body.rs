//! Independent references for the motion of a rigid body: the closed-form
//! torque-free motion of an asymmetric body (the flips of the Dzhanibekov
//! effect) and a high-accuracy integration of a heavy body on a fixed point
//! (the heavy top), both written from the textbooks without any of the
//! library's code.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::elliptic::complete_k;

/// Period of the angular velocity (in the body frame) of a torque-free
/// rigid body with principal moments of inertia `I₁ < I₂ < I₃` about its
/// centre of mass, kinetic energy `E` and angular momentum `|M|`.
///
/// Landau & Lifshitz, *Mechanics*, §37, eq. (37.10)–(37.12): for
/// `M² > 2EI₂`
///
/// ```text
/// Ω₁ = √((2EI₃ − M²) / (I₁(I₃ − I₁))) cn τ,
/// Ω₂ = √((2EI₃ − M²) / (I₂(I₃ − I₂))) sn τ,
/// Ω₃ = √((M² − 2EI₁) / (I₃(I₃ − I₁))) dn τ,
/// τ = ω_p t,  ω_p = √((I₃ − I₂)(M² − 2EI₁) / (I₁I₂I₃)),
/// k² = (I₂ − I₁)(2EI₃ − M²) / ((I₃ − I₂)(M² − 2EI₁)),
/// ```
///
/// and for `M² < 2EI₂` the same with the indices 1 and 3 exchanged. sn and
/// cn have the period `4K(k)` in τ, dn `2K(k)`, so the angular velocity
/// (and the motion relative to the angular momentum) repeats after
///
/// ```text
/// T = 4 K(k²) / ω_p
/// ```
///
/// (L&L eq. 37.13). Near the intermediate axis (`M² ≈ 2EI₂`, `k → 1`)
/// `Ω₂ ∝ sn τ` reverses every half period: the body flips over every
/// `T/2`, and the zeros of `Ω₂` are `T/2` apart.
pub fn torque_free_period(inertia: [f64; 3], energy: f64, momentum_sq: f64) -> f64 {
    let [i1, i2, i3] = inertia;
    assert!(i1 < i2 && i2 < i3, "principal moments in increasing order");
    let (e2, m2) = (2.0 * energy, momentum_sq);
    // exchange the indices 1 and 3 when M² < 2EI₂ (L&L §37)
    let (a, c) = if m2 > e2 * i2 { (i1, i3) } else { (i3, i1) };
    let omega_p = ((c - i2) * (m2 - e2 * a) / (i1 * i2 * i3)).sqrt();
    let k2 = (i2 - a) * (e2 * c - m2) / ((c - i2) * (m2 - e2 * a));
    4.0 * complete_k(k2) / omega_p
}

/// Kinetic energy and squared angular momentum of a body with principal
/// moments `inertia` turning at `omega` (body frame, principal axes).
pub fn energy_and_momentum(inertia: [f64; 3], omega: [f64; 3]) -> (f64, f64) {
    let mut e = 0.0;
    let mut m2 = 0.0;
    for i in 0..3 {
        e += 0.5 * inertia[i] * omega[i] * omega[i];
        m2 += (inertia[i] * omega[i]).powi(2);
    }
    (e, m2)
}

/// A rigid body turning about a fixed point `O` under uniform gravity:
/// the heavy top. `inertia_com` is the inertia tensor about the centre
/// of mass and `center_of_mass` the position of the centre of mass from
/// `O`, both in the body frame; `gravity` in the global frame.
#[derive(Clone, Copy, Debug)]
pub struct HeavyTop {
    pub mass: f64,
    pub inertia_com: Matrix3<f64>,
    pub center_of_mass: Vector3<f64>,
    pub gravity: Vector3<f64>,
}

/// Orientation (body to global) and angular velocity (body frame) of a
/// rigid body at a time.
#[derive(Clone, Copy, Debug)]
pub struct BodyState {
    pub time: f64,
    pub orientation: UnitQuaternion<f64>,
    pub omega: Vector3<f64>,
}

impl HeavyTop {
    /// Inertia tensor about the fixed point, body frame (parallel axes):
    /// `J = J_c + m (|X|² I − X Xᵀ)`.
    pub fn inertia_about_fixed_point(&self) -> Matrix3<f64> {
        let x = self.center_of_mass;
        self.inertia_com + self.mass * (Matrix3::identity() * x.norm_squared() - x * x.transpose())
    }

    /// Centre of mass in the global frame, `R X`.
    pub fn com(&self, s: &BodyState) -> Vector3<f64> {
        s.orientation * self.center_of_mass
    }

    /// Total energy: `½ Ω·JΩ − m g·(R X)`.
    pub fn energy(&self, s: &BodyState) -> f64 {
        let j = self.inertia_about_fixed_point();
        0.5 * s.omega.dot(&(j * s.omega)) - self.mass * self.gravity.dot(&self.com(s))
    }

    /// Angular momentum about the fixed point, global frame: `R J Ω`.
    pub fn momentum(&self, s: &BodyState) -> Vector3<f64> {
        s.orientation * (self.inertia_about_fixed_point() * s.omega)
    }

    /// Integrates from `start` to `end_time` with the classical fourth-order
    /// Runge–Kutta method at `steps` equal steps on the equations
    ///
    /// ```text
    /// J Ω̇ = −Ω × JΩ + X × Rᵀ(m g)       (Euler's equations about O, body frame)
    /// q̇ = ½ q ⊗ (0, Ω)                   (unit quaternion, Ω material)
    /// ```
    ///
    /// (Goldstein, *Classical Mechanics*, §5.5–5.7; Arnold & Brüls 2007,
    /// §5 for this top). The quaternion is normalised after each step,
    /// which changes it by the order of the step's error and keeps the
    /// fourth order.
    pub fn integrate(&self, start: BodyState, end_time: f64, steps: usize) -> BodyState {
        let j = self.inertia_about_fixed_point();
        let j_inv = j.try_inverse().expect("a positive definite inertia");
        let weight = self.mass * self.gravity;
        let x = self.center_of_mass;
        // the state as a plain array: quaternion (w, i, j, k) and Ω
        let rate = |y: &[f64; 7]| -> [f64; 7] {
            let q = Quaternion::new(y[0], y[1], y[2], y[3]);
            let omega = Vector3::new(y[4], y[5], y[6]);
            let r = UnitQuaternion::new_normalize(q);
            let torque = x.cross(&(r.inverse() * weight));
            let domega = j_inv * (torque - omega.cross(&(j * omega)));
            let dq = q * Quaternion::from_imag(omega) * 0.5;
            [dq.w, dq.i, dq.j, dq.k, domega.x, domega.y, domega.z]
        };
        let q0 = start.orientation.quaternion();
        let mut y = [
            q0.w,
            q0.i,
            q0.j,
            q0.k,
            start.omega.x,
            start.omega.y,
            start.omega.z,
        ];
        let h = (end_time - start.time) / steps as f64;
        let add = |y: &[f64; 7], k: &[f64; 7], s: f64| {
            let mut z = *y;
            for i in 0..7 {
                z[i] += s * k[i];
            }
            z
        };
        for _ in 0..steps {
            let k1 = rate(&y);
            let k2 = rate(&add(&y, &k1, 0.5 * h));
            let k3 = rate(&add(&y, &k2, 0.5 * h));
            let k4 = rate(&add(&y, &k3, h));
            for i in 0..7 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            let n = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3]).sqrt();
            for v in &mut y[..4] {
                *v /= n;
            }
        }
        BodyState {
            time: end_time,
            orientation: UnitQuaternion::new_normalize(Quaternion::new(y[0], y[1], y[2], y[3])),
            omega: Vector3::new(y[4], y[5], y[6]),
        }
    }

    /// The states at `times` (increasing, after `start.time`), each
    /// integrated at steps of at most `max_step`.
    pub fn states_at(&self, start: BodyState, times: &[f64], max_step: f64) -> Vec<BodyState> {
        let mut s = start;
        let mut out = Vec::with_capacity(times.len());
        for &t in times {
            let steps = ((t - s.time) / max_step).ceil().max(1.0) as usize;
            s = self.integrate(s, t, steps);
            out.push(s);
        }
        out
    }
}

/// The heavy top of Arnold & Brüls (2007, *Multibody System Dynamics* 18,
/// §5) and Brüls & Cardona (2010, *J. Comput. Nonlinear Dynam.* 5,
/// 031002), as in bench/peer/problems.py: m = 15 kg, centre of mass at
/// (0, 1, 0) m from the fixed point, principal inertia about the centre of
/// mass diag(0.234375, 0.46875, 0.234375) kg·m², gravity −9.81 z, body
/// frame = global frame at t = 0, Ω(0) = (0, 150, −4.61538) rad/s.
pub fn arnold_bruls_top() -> (HeavyTop, BodyState) {
    let top = HeavyTop {
        mass: 15.0,
        inertia_com: Matrix3::from_diagonal(&Vector3::new(0.234375, 0.46875, 0.234375)),
        center_of_mass: Vector3::new(0.0, 1.0, 0.0),
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let start = BodyState {
        time: 0.0,
        orientation: UnitQuaternion::identity(),
        omega: Vector3::new(0.0, 150.0, -4.61538),
    };
    (top, start)
}
