"""The folding of a triangular mast cell (reference paper §6.1): a
kinetostatic analysis, displacement controlled, of a cell of three
longerons and three diagonals hinged at their mid-points between two
triangles of battens, built with the Python builders: the Python version of
examples/mast_cell.rs (examples/mast_cell.md describes the model).

    python python/examples/mast_cell.py [output directory] [increments]

The geometry, the hinge axes (from `unfold.so3`, the library's rotations)
and the model are those of examples/mast_cell.rs written again in Python
operation by operation: the test python/tests/test_examples.py compares the
model file with the Rust one. Besides the result files, the program writes
the largest bending moment and torsion of the longerons at each increment
into `longeron_moments.csv`.
"""

from __future__ import annotations

import csv
import math
import os
import sys
from dataclasses import dataclass, field
from typing import List, Tuple

import numpy as np

import unfold
from unfold import (
    Analysis,
    BeamLine,
    Dofs,
    Driver,
    Joint,
    LoadCurve,
    ModelBuilder,
    RigidBody,
    Section,
)
from unfold import so3

PI = math.pi
CURVE_POINTS = 80
Vec = Tuple[float, float, float]


def _fmt(x: float) -> str:
    s = repr(float(x))
    return s[:-2] if s.endswith(".0") else s


def add(a: Vec, b: Vec) -> Vec:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a: Vec, b: Vec) -> Vec:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(s: float, a: Vec) -> Vec:
    return (s * a[0], s * a[1], s * a[2])


def dot(a: Vec, b: Vec) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def norm_squared(a: Vec) -> float:
    return a[0] * a[0] + a[1] * a[1] + a[2] * a[2]


def normalize(a: Vec) -> Vec:
    n = math.sqrt(norm_squared(a))
    return (a[0] / n, a[1] / n, a[2] / n)


@dataclass(frozen=True)
class Tube:
    e: float
    g: float
    diameter: float
    wall: float

    def radii(self):
        ro = self.diameter / 2.0
        return ro, ro - self.wall

    def area(self) -> float:
        ro, ri = self.radii()
        return PI * (ro * ro - ri * ri)

    def inertia(self) -> float:
        ro, ri = self.radii()
        return PI / 4.0 * ((ro * ro) * (ro * ro) - (ri * ri) * (ri * ri))

    def section(self) -> Section:
        a, i = self.area(), self.inertia()
        ga = 0.5 * self.g * a
        return Section.diagonal(self.e * a, ga, ga, self.g * 2.0 * i, self.e * i, self.e * i)


@dataclass(frozen=True)
class Design:
    """The design of examples/mast_cell.rs (`Design::default`)."""

    radius: float = 0.5
    height: float = 0.45
    folded_height: float = 0.15
    unlock: float = 0.02
    pretension_strain: float = -1.0e-3
    bar: Tube = Tube(100.0e9, 10.0e9, 0.012, 0.001)
    batten: Tube = Tube(100.0e9, 10.0e9, 0.020, 0.0015)
    corner_mass: Tuple[float, float] = (0.15, 1.5e-4)
    elements: Tuple[int, int, int] = (7, 3, 2)

    def height_at(self, twist: float) -> float:
        chord = 2.0 * self.radius * math.sin(0.5 * twist)
        return math.sqrt(max(self.height * self.height - chord * chord, 0.0))

    def folded_twist(self) -> float:
        l, h = self.height, self.folded_height
        chord = math.sqrt(l * l - h * h)
        return -2.0 * math.asin(chord / (2.0 * self.radius))

    def half_diagonal(self) -> float:
        r = self.radius
        return 0.5 * math.sqrt(self.height * self.height + 3.0 * r * r) * (1.0 + self.pretension_strain)

    def knees_at(self, twist: float) -> List[Vec]:
        h = self.height_at(twist)
        half = self.half_diagonal()
        knees = []
        for k in range(3):
            a, b = corner_angle(k), corner_angle(k + 1) + twist
            p = (self.radius * math.cos(a), self.radius * math.sin(a), 0.0)
            q = (self.radius * math.cos(b), self.radius * math.sin(b), h)
            chord = sub(q, p)
            mid = scale(0.5, add(p, q))
            u = normalize(chord)
            towards_axis = (-mid[0], -mid[1], 0.0)
            w = normalize(sub(towards_axis, scale(dot(u, towards_axis), u)))
            rho = math.sqrt(max(half * half - 0.25 * norm_squared(chord), 0.0))
            knees.append(add(mid, scale(rho, w)))
        return knees


def corner_angle(k: int) -> float:
    return 2.0 * PI * float(k) / 3.0


def hinge_axis(r_a, r_b) -> Vec:
    """The axis of the rotation `R_Aᵀ R_B` (the hinge that both
    configurations allow)."""
    return normalize(tuple(so3.log(so3.compose(so3.inverse(r_a), r_b))))


@dataclass
class Geometry:
    bottom: List[Vec]
    top: List[Vec]
    top_folded: List[Vec]
    twist: float
    knee: List[Vec]
    knee_folded: List[Vec]
    inward: List[Vec]
    axes: dict = field(default_factory=dict)


def geometry(d: Design) -> Geometry:
    r, l = d.radius, d.height
    twist = d.folded_twist()

    def at(angle, z):
        return (r * math.cos(angle), r * math.sin(angle), z)

    bottom = [at(corner_angle(k), 0.0) for k in range(3)]
    top = [at(corner_angle(k), l) for k in range(3)]
    top_folded = [at(corner_angle(k) + twist, d.folded_height) for k in range(3)]
    knee = [scale(0.5, add(bottom[k], top[(k + 1) % 3])) for k in range(3)]
    knee_folded = d.knees_at(twist)
    inward = []
    for k in range(3):
        a = corner_angle(k) + PI / 3.0
        inward.append((-math.cos(a), -math.sin(a), -0.0))
    fixed, r_top = (1.0, 0.0, 0.0, 0.0), so3.exp([0.0 * twist, 0.0 * twist, 1.0 * twist])
    axes = {name: [None] * 3 for name in ("longeron_bottom", "longeron_top", "diagonal_bottom", "knee", "diagonal_top")}
    for k in range(3):
        k1 = (k + 1) % 3
        r_longeron = so3.rotation_between(sub(top[k], bottom[k]), sub(top_folded[k], bottom[k]))
        r_lower = so3.rotation_between(sub(knee[k], bottom[k]), sub(knee_folded[k], bottom[k]))
        r_upper = so3.rotation_between(sub(top[k1], knee[k]), sub(top_folded[k1], knee_folded[k]))
        axes["longeron_bottom"][k] = hinge_axis(fixed, r_longeron)
        axes["longeron_top"][k] = hinge_axis(r_top, r_longeron)
        axes["diagonal_bottom"][k] = hinge_axis(fixed, r_lower)
        axes["knee"][k] = hinge_axis(r_lower, r_upper)
        axes["diagonal_top"][k] = hinge_axis(r_top, r_upper)
    return Geometry(bottom, top, top_folded, twist, knee, knee_folded, inward, axes)


@dataclass
class Parts:
    bottom: list
    top: list
    knees: list
    longerons: list
    diagonals: list
    knee_drivers: list = field(default_factory=list)


def cell(d: Design):
    """The cell without drivers: bars, corner bodies, hinges, supports and
    the pretension of the diagonals."""
    g = geometry(d)
    m = ModelBuilder(
        f"Folding of a triangular mast cell: r = {_fmt(d.radius)} m, L = {_fmt(d.height)} m, "
        f"folded to {_fmt(d.folded_height)} m"
    )
    m.analysis(Analysis.kinetostatic())
    bar = m.section(d.bar.section().named("bar"))
    batten = m.section(d.batten.section().named("batten"))
    corners = [(m.node(list(g.bottom[k])), m.node(list(g.top[k]))) for k in range(3)]
    bottom, top = [c[0] for c in corners], [c[1] for c in corners]
    longeron, diagonal = [], []
    for k in range(3):
        longeron.append((m.node(list(g.bottom[k])), m.node(list(g.top[k]))))
        diagonal.append(
            (
                m.node(list(g.bottom[k])),
                m.node(list(g.knee[k])),
                m.node(list(g.knee[k])),
                m.node(list(g.top[(k + 1) % 3])),
            )
        )
    nl, nd, nb = d.elements
    longerons = [m.beam_line(longeron[k][0], longeron[k][1], nl, bar) for k in range(3)]
    diagonals = []
    for k in range(3):
        lower_end, knee_lower, knee_upper, upper_end = diagonal[k]
        elements = []
        for a, b in ((lower_end, knee_lower), (knee_upper, upper_end)):
            elements += m.add(BeamLine.between(a, b, nd, bar).axial_strain(d.pretension_strain)).elements
        diagonals.append(elements)
    for level in (bottom, top):
        for k in range(3):
            m.beam_line(level[k], level[(k + 1) % 3], nb, batten)
    mass, inertia = d.corner_mass
    for node in bottom + top:
        m.add(RigidBody.at(node, mass).inertia([inertia] * 3))
    for node in bottom:
        m.fix(node, Dofs.ALL)
    axes = g.axes
    for k in range(3):
        lower_end, upper_end = longeron[k]
        m.add(Joint.revolute(bottom[k], lower_end).axis(list(axes["longeron_bottom"][k])))
        m.add(Joint.revolute(top[k], upper_end).axis(list(axes["longeron_top"][k])))
    for k in range(3):
        lower_end, knee_lower, knee_upper, upper_end = diagonal[k]
        m.add(Joint.revolute(bottom[k], lower_end).axis(list(axes["diagonal_bottom"][k])))
        m.add(Joint.revolute(knee_lower, knee_upper).axis(list(axes["knee"][k])))
        m.add(Joint.revolute(top[(k + 1) % 3], upper_end).axis(list(axes["diagonal_top"][k])))
    parts = Parts(bottom, top, [diagonal[k][1] for k in range(3)], [l.elements for l in longerons], diagonals)
    return m, parts


def assemble(d: Design) -> Tuple[float, float]:
    """The pretensioned equilibrium before any driver acts: the drop of
    the top corners and the inward displacement of the knees (m)."""
    g = geometry(d)
    m, parts = cell(d)
    m.analysis(Analysis.kinetostatic().initial_increment(1.0))
    model = m.build()
    results = model.run(elements=[])
    ids = list(model.node_ids)
    x, x0 = results.final_positions, model.reference_positions
    top = ids.index(parts.top[0].id)
    knee = ids.index(parts.knees[0].id)
    return float(x[top][2] - x0[top][2]), dot(tuple(x[knee] - x0[knee]), g.inward[0])


def build(increments: int = 96, d: Design = Design()):
    """The model: the cell, the knee drivers of stages (a) and (b), and the
    analysis in `increments` equal increments."""
    g = geometry(d)
    top_drop, knee_inward = assemble(d)
    m, parts = cell(d)
    step = 2.0 / float(max(increments, 1))
    m.analysis(
        Analysis.kinetostatic()
        .end_time(2.0)
        .initial_increment(step)
        .max_increment(step)
        .min_increment(step * 1e-4)
    )
    knee_final = dot(sub(g.knee_folded[0], g.knee[0]), g.inward[0])
    knee_unlocked = knee_inward + d.unlock
    push = [[0.0, knee_inward / knee_final], [1.0, knee_unlocked / knee_final]]
    for i in range(1, CURVE_POINTS + 1):
        s = float(i) / float(CURVE_POINTS)
        knee = d.knees_at(g.twist * s * s)[0]
        inward = max(dot(sub(knee, g.knee[0]), g.inward[0]), knee_unlocked)
        push.append([1.0 + s * s, inward / knee_final])
    curve = m.curve(LoadCurve.points(push).named("push_knees"))
    for k in range(3):
        parts.knee_drivers.append(
            m.add(Driver.translation(parts.knees[k], list(g.inward[k])).value(knee_final).curve(curve))
        )
    return m, parts


def main(argv: List[str]) -> int:
    out = argv[1] if len(argv) > 1 else "results/mast_cell_python"
    increments = int(argv[2]) if len(argv) > 2 else 96
    m, parts = build(increments)
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "mast_cell.toml"), "w") as f:
        f.write(m.to_toml())
    model = m.build()
    print(model.describe())
    results = model.run(out=out)
    # the largest bending moment √(M2² + M3²) and torsion of the longerons
    ids, names, beams = results.table("beam")
    longeron = [ids.index(b.id) for l in parts.longerons for b in l]
    m2, m3, t = (beams[:, longeron, names.index(n)] for n in ("M2", "M3", "T"))
    bending = np.hypot(m2, m3).max(axis=1)
    torsion = np.abs(t).max(axis=1)
    with open(os.path.join(out, "longeron_moments.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time", "max_bending", "max_torsion"])
        for row in zip(results.times, bending, torsion):
            w.writerow([f"{v:.9e}" for v in row])
    k = int(np.argmax(bending))
    print(
        f"{results.status}: {len(results) - 1} increments, {results.wall_time:.2f} s; largest longeron "
        f"bending {bending[k]:.3f} N·m at t = {results.times[k]:.3f}, torsion {torsion.max():.3f} N·m; "
        f"results in {out}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
