"""Heavy top by small, independent generalized-α integrators, to learn the
error constant of each formulation at the peer benchmark's steps (a study,
not part of the harness). From bench/peer, with NumPy:

    python3 study/top_lie_alpha.py VARIANT [RHO_INF] [K,K,...]

runs h = 0.01/2^K (default K = 2..6) for 2 s and prints the largest distance
of the centre of mass from the reference `reference/top_independent.csv`
(DOP853) over the output times 0, 0.01, ..., 2 s. Variants:

- `lie`: the Lie-group generalized-α of Arnold & Brüls (2007) / Brüls,
  Cardona & Arnold (2012) on R³ × SO(3), as unfold integrates the top: the
  node at the centre of mass, translations global, rotations and angular
  velocities material (R_{n+1} = R_n exp(h ΔΘ)), the spherical joint an
  index-3 constraint Φ = x − R X = 0, consistent initial accelerations;
- `lieproj`: the same with unfold's projection of the velocities on B v = 0
  after every step, in the metric of the mass, and a, v̇, λ moved with them
  (docs/theory.md D13–D13a);
- `spatial`, `spatialproj`: the same two with spatial angular velocities
  (R_{n+1} = exp(h Δθ) R_n, ω = R Ω and ω̇ = R Ω̇ in the recurrences);
- `fixed`: the top as one rotation about the fixed point (node there, J
  about it, no constraint), material angular velocity;
- `ep`: the index-3 generalized-α on the coordinates (x, p) ∈ R⁷ with Euler
  parameters p, as Exudyn integrates its ObjectRigidBody (a vector space:
  q_{n+1} = q_n + h q̇_n + h²(½ − β) a_n + h² β a_{n+1}), the constraints
  x − R(p) X = 0 and |p|² − 1 = 0, no projection.

Newton on finite-difference Jacobians to 1e-11 of the forces (1e-9 for
`ep`): what is measured is the time discretisation alone. A run takes a
few minutes at h = 3.125e-4 s (Python). Figures (ρ∞ = 0.9) in
docs/theory.md §15.9 and bench/peer/README.md.
"""

import sys

import numpy as np

G = np.array([0.0, 0.0, -9.81])
M = 15.0
X = np.array([0.0, 1.0, 0.0])
JC = np.diag([0.234375, 0.46875, 0.234375])
JO = JC + M * (X @ X * np.eye(3) - np.outer(X, X))
OMEGA0 = np.array([0.0, 150.0, -4.61538])


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def expm(w):
    t = np.linalg.norm(w)
    W = hat(w)
    if t < 1e-8:
        return np.eye(3) + W + 0.5 * W @ W
    return np.eye(3) + np.sin(t) / t * W + (1 - np.cos(t)) / t**2 * W @ W


def params(rho):
    am = (2 * rho - 1) / (rho + 1)
    af = rho / (rho + 1)
    g = 0.5 + af - am
    b = 0.25 * (g + 0.5) ** 2
    return am, af, g, b


def newton(f, z, tol=1e-11, maxit=30):
    """Newton with a finite-difference Jacobian (central differences)."""
    r = f(z)
    scale = max(1e3, np.abs(r).max())  # forces of the top ~ m g = 147 N, m Ω² |X| ~ 3e5 N
    for _ in range(maxit):
        n = len(z)
        Jm = np.empty((n, n))
        for j in range(n):
            e = 1e-6 * max(1.0, abs(z[j]))
            zp = z.copy()
            zp[j] += e
            zm = z.copy()
            zm[j] -= e
            Jm[:, j] = (f(zp) - f(zm)) / (2 * e)
        z = z - np.linalg.solve(Jm, r)
        r = f(z)
        if np.abs(r).max() < tol * scale:
            return z
    raise RuntimeError("Newton did not converge")


# ---------------------------------------------------------------- Lie group
def lie(h, rho=0.9, project=False, fixed=False, spatial=False, end=2.0, every=0.01):
    """Lie-group generalized-α on R³ × SO(3) (node at the centre of mass, or
    with `fixed` at the fixed point). Returns the centre of mass at the
    output times."""
    am, af, g, b = params(rho)
    if fixed:
        # one rotation, material Ω: J_O Ω̇ + Ω × J_O Ω − X × Rᵀ m g = 0
        def res(R, v, vd, lam):
            Om, Omd = v[3:], vd[3:]
            r = np.zeros(6)
            r[3:] = JO @ Omd + np.cross(Om, JO @ Om) - np.cross(X, R.T @ (M * G))
            return r
    elif spatial:
        def res(R, x, v, vd, lam):
            # spatial ω: R J_c Rᵀ ω̇ + ω × R J_c Rᵀ ω + ((R X)~)ᵀ λ = 0
            Js = R @ JC @ R.T
            r = np.zeros(9)
            r[:3] = M * vd[:3] - M * G + lam
            r[3:6] = Js @ vd[3:] + np.cross(v[3:], Js @ v[3:]) + hat(R @ X).T @ lam
            r[6:] = x - R @ X
            return r
    else:
        def res(R, x, v, vd, lam):
            # m ẍ − m g + λ = 0,  J_c Ω̇ + Ω × J_c Ω + (R X~)ᵀ λ = 0,  Φ = x − R X
            r = np.zeros(9)
            r[:3] = M * vd[:3] - M * G + lam
            r[3:6] = JC @ vd[3:] + np.cross(v[3:], JC @ v[3:]) + (R @ hat(X)).T @ lam
            r[6:] = x - R @ X
            return r

    R = np.eye(3)
    x = R @ X
    v = np.concatenate([np.cross(OMEGA0, X), OMEGA0])
    # consistent initial accelerations (and multiplier)
    Om = v[3:]
    if fixed:
        Omd = np.linalg.solve(JO, np.cross(X, R.T @ (M * G)) - np.cross(Om, JO @ Om))
        vd = np.concatenate([np.cross(Omd, X) + np.cross(Om, np.cross(Om, X)), Omd])
        lam = np.zeros(3)
    else:
        # [M, Bᵀ; B, 0] [v̇; λ] = [m g; −Ω×J_cΩ; −R Ω×(X×Ω)]
        A = np.zeros((9, 9))
        A[:3, :3] = M * np.eye(3)
        A[3:6, 3:6] = JC
        B = np.hstack([np.eye(3), hat(R @ X) if spatial else R @ hat(X)])
        A[:6, 6:] = B.T
        A[6:, :6] = B
        rhs = np.concatenate([M * G, -np.cross(Om, JC @ Om), -R @ np.cross(Om, np.cross(X, Om))])
        sol = np.linalg.solve(A, rhs)
        vd, lam = sol[:6], sol[6:]
    a = vd.copy()
    out = [x.copy()]
    nsteps = int(round(end / h))
    nout = int(round(every / h))
    for step in range(1, nsteps + 1):
        def unpack(z):
            dq = z[:6]
            an1 = (dq - v - h * (0.5 - b) * a) / (b * h)
            v1 = v + h * (1 - g) * a + h * g * an1
            vd1 = ((1 - am) * an1 + am * a - af * vd) / (1 - af)
            x1 = x + h * dq[:3]
            R1 = expm(h * dq[3:]) @ R if spatial else R @ expm(h * dq[3:])
            return an1, v1, vd1, x1, R1

        def f(z):
            an1, v1, vd1, x1, R1 = unpack(z)
            if fixed:
                return res(R1, v1, vd1, None)[3:]
            return res(R1, x1, v1, vd1, z[6:])

        # predictor (D5): v̇ = 0
        a_p = (af * vd - am * a) / (1 - am)
        dq0 = v + h * (0.5 - b) * a + h * b * a_p
        if fixed:
            z0 = dq0[3:]
            fz = lambda zz: f(np.concatenate([np.zeros(3), zz]))
            zz = newton(fz, z0)
            z = np.concatenate([np.zeros(3), zz])
            # translations follow the rotation (x = R X): not integrated
        else:
            z0 = np.concatenate([dq0, lam])
            z = newton(f, z0)
        an1, v1, vd1, x1, R1 = unpack(z)
        if fixed:
            x1 = R1 @ X
            lam1 = lam
        else:
            lam1 = z[6:]
        if project and not fixed:
            # D13: M δv − Bᵀμ = 0, B(v + δv) = 0; D13a: a, v̇, λ follow δv
            Mm = np.diag([M, M, M, 0, 0, 0])
            Mm[3:, 3:] = R1 @ JC @ R1.T if spatial else JC
            B = np.hstack([np.eye(3), hat(R1 @ X) if spatial else R1 @ hat(X)])
            A = np.zeros((9, 9))
            A[:6, :6] = Mm
            A[:6, 6:] = -B.T
            A[6:, :6] = B
            sol = np.linalg.solve(A, np.concatenate([np.zeros(6), -B @ v1]))
            dv, mu = sol[:6], sol[6:]
            c = (1 - am) / ((1 - af) * g * h)
            v1 = v1 + dv
            an1 = an1 + dv / (g * h)
            vd1 = vd1 + c * dv
            lam1 = lam1 - c * mu  # M c δv = Bᵀ c μ balanced by λ − c μ (r has +Bᵀλ)
        x, R, v, vd, a, lam = x1, R1, v1, vd1, an1, lam1
        if step % nout == 0:
            out.append(x.copy())
    return np.array(out)


# ---------------------------------------------------------- Euler parameters
def ep_G(p):
    """Material G: Ω = G ṗ, G = 2 [−p_v, p₀ 1 − p_v~]."""
    p0, pv = p[0], p[1:]
    return 2 * np.hstack([-pv[:, None], p0 * np.eye(3) - hat(pv)])


def ep_R(p):
    p0, pv = p[0], p[1:]
    return (p0 * p0 - pv @ pv) * np.eye(3) + 2 * np.outer(pv, pv) + 2 * p0 * hat(pv)


def ep(h, rho=0.9, end=2.0, every=0.01):
    """Index-3 generalized-α on q = (x, p) ∈ R⁷ (Arnold & Brüls 2007 in a
    vector space), Euler parameters, node at the centre of mass; constraints
    Φ = (x − R(p) X, |p|² − 1). Equations of motion (Lagrange, material
    inertia): m ẍ = m g + ..., Gᵀ J_c G p̈ + 2 Ġᵀ J_c G ṗ + Φ_qᵀ λ = 0 —
    the standard Euler-parameter form (Nikravesh 1988; Shabana), with
    Ġ ṗ = 0 so that Ω̇ = G p̈."""
    am, af, g, b = params(rho)

    def Phi(q):
        x, p = q[:3], q[3:]
        return np.concatenate([x - ep_R(p) @ X, [p @ p - 1.0]])

    def Phi_q(q):
        # ∂(R(p)X)/∂p0 = 2 p0 X + 2 p_v × X,
        # ∂(R(p)X)/∂p_v = 2 (p_v·X) 1 + 2 p_v Xᵀ − 2 X p_vᵀ − 2 p0 X~
        p0, pv = q[3], q[4:]
        Jm = np.zeros((4, 7))
        Jm[:3, :3] = np.eye(3)
        Jm[:3, 3] = -(2 * p0 * X + 2 * np.cross(pv, X))
        Jm[:3, 4:] = -(2 * (pv @ X) * np.eye(3) + 2 * np.outer(pv, X) - 2 * np.outer(X, pv) - 2 * p0 * hat(X))
        Jm[3, 3:] = 2 * q[3:]
        return Jm

    def res(q, qd, qdd, lam):
        p, pd, pdd = q[3:], qd[3:], qdd[3:]
        Gm = ep_G(p)
        Gd = ep_G(pd)  # G is linear in p
        r = np.zeros(11)
        r[:3] = M * qdd[:3] - M * G
        # d/dt(∂T/∂ṗ) − ∂T/∂p with T = ½ ṗᵀ Gᵀ J G ṗ = 4 Gᵀ... written as
        # Gᵀ J_c (G p̈) + 2 Ġᵀ J_c G ṗ  (the usual form; Ġṗ = 0)
        r[3:7] = Gm.T @ JC @ (Gm @ pdd) + 2 * Gd.T @ JC @ (Gm @ pd)
        r[:7] += Phi_q(q).T @ lam
        r[7:] = Phi(q)
        return r

    p = np.array([1.0, 0, 0, 0])
    q = np.concatenate([X, p])
    # ṗ = ¼ Gᵀ Ω (G Gᵀ = 4·1 for |p| = 1)
    qd = np.concatenate([np.cross(OMEGA0, X), 0.25 * ep_G(p).T @ OMEGA0])
    # initial accelerations: res = 0 with the constraint rows replaced by
    # Φ̈ = Φ_q q̈ + Φ_qq(q̇, q̇) = 0 (the second term by central differences;
    # Φ is quadratic in p, so they are exact but for round-off)
    e = 1e-4
    phidd0 = (Phi(q + e * qd) - 2 * Phi(q) + Phi(q - e * qd)) / e**2  # Φ_qq(q̇, q̇)
    B0 = Phi_q(q)

    def f0(z):
        qdd, lam = z[:7], z[7:]
        r = res(q, qd, qdd, lam)
        r[7:] = B0 @ qdd + phidd0
        return r

    z = newton(f0, np.zeros(11), tol=1e-10)
    qdd, lam = z[:7], z[7:]
    a = qdd.copy()
    out = [q[:3].copy()]
    nsteps = int(round(end / h))
    nout = int(round(every / h))
    for step in range(1, nsteps + 1):
        def unpack(zz):
            # unknowns (q_{n+1}, λ): finite differences in q, not in q̈
            q1 = zz[:7]
            a1 = (q1 - q - h * qd - h * h * (0.5 - b) * a) / (b * h * h)
            qd1 = qd + h * (1 - g) * a + h * g * a1
            qdd1 = ((1 - am) * a1 + am * a - af * qdd) / (1 - af)
            return a1, q1, qd1, qdd1

        def f(zz):
            a1, q1, qd1, qdd1 = unpack(zz)
            return res(q1, qd1, qdd1, zz[7:])

        # predictor: q̈_{n+1} = 0
        a_p = (af * qdd - am * a) / (1 - am)
        q_p = q + h * qd + h * h * (0.5 - b) * a + h * h * b * a_p
        # 1e-9 of the forces: the round-off of q over βh² in q̈ is above 1e-11
        zz = newton(f, np.concatenate([q_p, lam]), tol=1e-9)
        a1, q1, qd1, qdd1 = unpack(zz)
        zz = np.concatenate([qdd1, zz[7:]])
        q, qd, qdd, a, lam = q1, qd1, zz[:7], a1, zz[7:]
        if step % nout == 0:
            out.append(q[:3].copy())
    return np.array(out)


def error(pos):
    ref = np.loadtxt("reference/top_independent.csv", delimiter=",", skiprows=2)
    n = min(len(pos), len(ref))
    return np.linalg.norm(pos[:n] - ref[:n, 1:4], axis=1).max()


if __name__ == "__main__":
    which = sys.argv[1] if len(sys.argv) > 1 else "lie"
    rho = float(sys.argv[2]) if len(sys.argv) > 2 else 0.9
    ks = [int(k) for k in sys.argv[3].split(",")] if len(sys.argv) > 3 else [2, 3, 4, 5, 6]
    for k in ks:
        h = 0.01 / 2**k
        if which == "lie":
            e = error(lie(h, rho))
        elif which == "lieproj":
            e = error(lie(h, rho, project=True))
        elif which == "spatial":
            e = error(lie(h, rho, spatial=True))
        elif which == "spatialproj":
            e = error(lie(h, rho, project=True, spatial=True))
        elif which == "fixed":
            e = error(lie(h, rho, fixed=True))
        elif which == "ep":
            e = error(ep(h, rho))
        else:
            sys.exit(f"unknown variant {which!r}: lie, lieproj, spatial, spatialproj, fixed or ep")
        print(f"{which} rho={rho} h={h:.4e} error={e:.4e}", flush=True)
