//! Periods of conservative one-degree-of-freedom oscillators by quadrature:
//! an independent reference for pendulums (and any `m ẍ = −V′(x)`).

/// Nodes and weights of the 8-point Gauss–Legendre rule on [−1, 1]
/// (Abramowitz & Stegun table 25.4).
const GAUSS_8: [(f64, f64); 4] = [
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];

/// `∫_a^b f` by the composite 8-point Gauss–Legendre rule on `panels`
/// equal panels.
pub fn gauss_legendre(f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize) -> f64 {
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let mid = a + (p as f64 + 0.5) * h;
        for (x, w) in GAUSS_8 {
            sum += w * (f(mid - 0.5 * h * x) + f(mid + 0.5 * h * x));
        }
    }
    0.5 * h * sum
}

/// `∫_a^b f` to a relative tolerance `tol`: the panels are doubled until
/// two successive sums agree (for an analytic integrand the 8-point rule
/// converges like h¹⁶, so the last sum is far better than the difference).
/// Below about 1e-13 the round-off of integrands with cancellations takes
/// over: ask for 1e-12.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    let mut panels = 1;
    let mut last = gauss_legendre(&f, a, b, panels);
    for _ in 0..20 {
        panels *= 2;
        let next = gauss_legendre(&f, a, b, panels);
        if (next - last).abs() <= tol * next.abs() {
            return next;
        }
        last = next;
    }
    panic!("quadrature did not converge to {tol}: {last} ({panels} panels)");
}

/// Period of the oscillation of `m_eff ẍ = −V′(x)` between its turning
/// points `x_a < x_b` (where `V(x_a) = V(x_b)` is the energy), given the
/// kinetic energy `depth(x) = V(x_b) − V(x)` (written by the caller
/// without cancellation near the turning points):
///
/// ```text
/// T = 2 ∫_{x_a}^{x_b} dx / √(2 (V(x_b) − V(x)) / m_eff)
/// ```
///
/// (energy conservation, Landau & Lifshitz *Mechanics* §11, eq. 11.5). The
/// substitution `x = c + r sin φ` (`c`, `r` the centre and half width of
/// `[x_a, x_b]`) removes the inverse square-root singularities at the
/// turning points: `V(x_b) − V(x) ≈ r V′ (1 ∓ sin φ) ∝ cos² φ` near them,
/// and `dx = r cos φ dφ`, so the integrand is smooth on `[−π/2, π/2]`
/// (endpoint values by continuity are never evaluated by Gauss points).
pub fn oscillation_period(
    depth: impl Fn(f64) -> f64,
    m_eff: f64,
    x_a: f64,
    x_b: f64,
    tol: f64,
) -> f64 {
    let (c, r) = (0.5 * (x_a + x_b), 0.5 * (x_b - x_a));
    let integrand = |phi: f64| {
        let x = c + r * phi.sin();
        let kinetic = depth(x).max(0.0);
        r * phi.cos() / (2.0 * kinetic / m_eff).sqrt()
    };
    2.0 * integrate(
        integrand,
        -std::f64::consts::FRAC_PI_2,
        std::f64::consts::FRAC_PI_2,
        tol,
    )
}

/// Period of a physical pendulum released at rest from the angle `theta0`
/// (from the downward vertical, |θ₀| < π) about a horizontal axis `O`:
/// moment of inertia `i_o` about `O`, mass `m`, centre of mass at `d`
/// from `O`, gravity `g`. `I_O θ̈ = −m g d sin θ`: by quadrature of
/// [`oscillation_period`] with `V = −m g d cos θ`, whose depth below the
/// turning points is `m g d (cos θ − cos θ₀) = 2 m g d sin((θ₀ + θ)/2)
/// sin((θ₀ − θ)/2)`.
pub fn pendulum_period_by_quadrature(i_o: f64, m: f64, d: f64, g: f64, theta0: f64) -> f64 {
    let a = theta0.abs();
    let depth = |t: f64| 2.0 * m * g * d * (0.5 * (a + t)).sin() * (0.5 * (a - t)).sin();
    oscillation_period(depth, i_o, -a, a, 1e-12)
}

/// The same period in closed form: `T = 4 √(L_eq/g) K(sin²(θ₀/2))` with
/// the equivalent length `L_eq = I_O/(m d)` (Landau & Lifshitz §11,
/// problem 1; the substitution `sin(θ/2) = sin(θ₀/2) sin φ`).
pub fn pendulum_period(i_o: f64, m: f64, d: f64, g: f64, theta0: f64) -> f64 {
    let l_eq = i_o / (m * d);
    let k2 = (0.5 * theta0).sin().powi(2);
    4.0 * (l_eq / g).sqrt() * super::elliptic::complete_k(k2)
}
