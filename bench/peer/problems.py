"""The two benchmark problems, their parameters and the comparison rules.

Both codes are given exactly these numbers (SI units); see README.md for
where they come from.
"""

import math

GRAVITY = 9.81  # m/s², along −z in both problems

# Generalized-α numerical dissipation (spectral radius at infinite frequency),
# the same in both codes.
RHO_INFINITY = 0.9

# Times at which the tip (centre of mass) is compared: every OUTPUT_PERIOD.
OUTPUT_PERIOD = 0.01


class Pendulum:
    """Flexible beam pendulum: a straight 1 m beam along +x, pinned at x = 0
    by a revolute joint about global y, released from rest in the horizontal
    and falling under gravity −9.81 z for 1 s."""

    name = "pendulum"
    length = 1.0  # m
    EA = 4.0e5  # N
    GA = 1.5e5  # N, both shear directions
    GJ = 0.8  # N·m²
    EI = 1.0  # N·m², both bending directions
    rho_A = 1.0  # kg/m
    # Rotational inertia per length of a solid circular section with
    # I/A = EI/EA = 2.5e-6 m²: ρI = ρA·I/A about each bending axis,
    # ρJ = 2ρI about the beam axis.
    rho_I = rho_A * EI / EA  # kg·m, bending axes (local 2 and 3)
    rho_J = 2.0 * rho_I  # kg·m, torsion axis (local 1)
    end_time = 1.0  # s
    sizes = (20, 80, 320)  # number of elements
    tolerance = 1.0e-3  # m, equal-accuracy tolerance on the tip
    first_step = 1.0e-2  # s, first step of the halving sequence
    # Fine step of each code's own reference for each mesh (also run at
    # twice this step to estimate the reference's own error).
    reference_step = 5.0e-5  # s


class HeavyTop:
    """Heavy top of Arnold & Brüls (2007) and Brüls & Cardona (2010): a rigid
    body on a spherical joint at the origin, centre of mass at X = (0, 1, 0) m
    in the body frame (which coincides with the global frame at t = 0),
    spinning fast about its own axis, under gravity −9.81 z, for 2 s."""

    name = "top"
    mass = 15.0  # kg
    center_of_mass = (0.0, 1.0, 0.0)  # m, body frame, from the fixed point
    inertia_com = (0.234375, 0.46875, 0.234375)  # kg·m², principal, about the COM
    omega0 = (0.0, 150.0, -4.61538)  # rad/s, material (= spatial at t = 0)
    end_time = 2.0  # s
    tolerance = 1.0e-3  # m, equal-accuracy tolerance on the centre of mass
    first_step = 1.0e-2  # s

    @classmethod
    def com_velocity0(cls):
        """Initial velocity of the centre of mass, ω × X (fixed point at rest)."""
        w, x = cls.omega0, cls.center_of_mass
        return (
            w[1] * x[2] - w[2] * x[1],
            w[2] * x[0] - w[0] * x[2],
            w[0] * x[1] - w[1] * x[0],
        )


def step_sequence(first_step, count):
    """h, h/2, h/4, …: the steps tried in turn, each dividing the end time."""
    return [first_step / 2**k for k in range(count)]


def steps_for(end_time, h):
    n = round(end_time / h)
    if not math.isclose(n * h, end_time, rel_tol=1e-12):
        raise ValueError(f"step {h} does not divide the end time {end_time}")
    return n
