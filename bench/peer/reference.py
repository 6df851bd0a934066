"""Independent reference of the heavy top: Euler's equations about the fixed
point with a unit quaternion for the orientation, integrated by DOP853
(SciPy) at rtol = atol = 1e-13.

    J Ω̇ + Ω × JΩ = X × Rᵀ(m g),    q̇ = ½ q ⊗ (0, Ω),    x_com = R X,

with J = J_c + m (|X|² 1 − X Xᵀ) the inertia about the fixed point
(parallel axes) and Ω the material angular velocity.
"""

import numpy as np
from scipy.integrate import solve_ivp

from problems import GRAVITY, HeavyTop


def _rotation(q):
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def heavy_top_reference(times, rtol=1e-13, top=HeavyTop):
    """Centre-of-mass positions at `times` (an increasing array from 0).
    Returns (positions (n×3), energy drift relative to the initial energy)."""
    m = top.mass
    X = np.array(top.center_of_mass)
    J = np.diag(top.inertia_com) + m * (X @ X * np.eye(3) - np.outer(X, X))
    J_inv = np.linalg.inv(J)
    weight = np.array([0.0, 0.0, -m * GRAVITY])

    def rhs(_t, y):
        q, om = y[:4], y[4:]
        R = _rotation(q)
        torque = np.cross(X, R.T @ weight)
        om_dot = J_inv @ (torque - np.cross(om, J @ om))
        w, x, yq, z = q
        # q̇ = ½ q ⊗ (0, Ω)
        q_dot = 0.5 * np.array(
            [
                -x * om[0] - yq * om[1] - z * om[2],
                w * om[0] + yq * om[2] - z * om[1],
                w * om[1] + z * om[0] - x * om[2],
                w * om[2] + x * om[1] - yq * om[0],
            ]
        )
        return np.concatenate([q_dot, om_dot])

    def energy(y):
        R = _rotation(y[:4])
        om = y[4:]
        return 0.5 * om @ J @ om - weight @ (R @ X)

    y0 = np.concatenate([[1.0, 0.0, 0.0, 0.0], top.omega0])
    sol = solve_ivp(
        rhs,
        (times[0], times[-1]),
        y0,
        method="DOP853",
        t_eval=times,
        rtol=rtol,
        atol=rtol,
    )
    if not sol.success:
        raise RuntimeError(f"heavy top reference: {sol.message}")
    pos = np.array([_rotation(sol.y[:4, k]) @ X for k in range(len(times))])
    e0 = energy(y0)
    drift = max(abs(energy(sol.y[:, k]) - e0) for k in range(len(times))) / abs(e0)
    return pos, drift
