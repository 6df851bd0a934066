"""The ERA cell (reference paper §6.2) built with the Python builders and
deployed in dynamics by the tape springs of its six mid-hinges until every
latch has locked: the Python version of examples/era.rs for one cell
(examples/era.md describes the design and every parameter).

    python python/examples/era_cell.py [output directory] [gravity in g]

The design, the geometry and the model are those of examples/era/design.rs,
geometry.rs, hinge.rs and model.rs, written again in Python operation by
operation, so that the model is the same to the last bit (the test
python/tests/test_era.py compares the model files and the lock instants).
`build` takes the parameters a study varies: the tape springs' deployment
moment and locking peak, the latches' angle, the members' Rayleigh damping,
the folded scale (the initial fold) and the numerical dissipation.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field, replace
from typing import Dict, List, Optional, Tuple

import unfold
from unfold import (
    Analysis,
    BeamLine,
    Dofs,
    HingeLaw,
    Joint,
    Latch,
    ModelBuilder,
    RigidBody,
    Section,
    TapeSpring,
)

PI = math.pi
G0 = 9.80665  # standard gravity (m/s²)
Vec = Tuple[float, float, float]


# ----------------------------------------------------------------- design


@dataclass(frozen=True)
class Tube:
    """A thin-walled circular CFRP tube (examples/era/design.rs, `Tube`)."""

    diameter: float
    wall: float
    e: float = 110.0e9
    g: float = 12.0e9
    density: float = 1600.0

    def radii(self) -> Tuple[float, float]:
        ro = 0.5 * self.diameter
        return ro, ro - self.wall

    def area(self) -> float:
        ro, ri = self.radii()
        return PI * (ro * ro - ri * ri)

    def inertia(self) -> float:
        ro, ri = self.radii()
        # `powi(4)` of the Rust code: (x·x)·(x·x)
        return 0.25 * PI * ((ro * ro) * (ro * ro) - (ri * ri) * (ri * ri))

    def section(self) -> Section:
        a, i = self.area(), self.inertia()
        ga = 0.5 * self.g * a
        rho = self.density
        return (
            Section.diagonal(self.e * a, ga, ga, self.g * 2.0 * i, self.e * i, self.e * i)
            .mass_per_length(rho * a)
            .inertia_per_length([rho * 2.0 * i, rho * i, rho * i])
        )


@dataclass(frozen=True)
class Fitting:
    """A fitting as a solid cylinder about the vertical."""

    mass: float
    radius: float
    height: float

    def inertia(self) -> List[float]:
        m, r, h = self.mass, self.radius, self.height
        horizontal = m * (3.0 * r * r + h * h) / 12.0
        return [horizontal, horizontal, 0.5 * m * r * r]


@dataclass(frozen=True)
class HingeSpring:
    """The tape-spring hinge law of a mid-hinge (docs/joints.md §4.1)."""

    deployment_moment: float = 0.2
    locking_peak: float = 10.0
    locked_stiffness: float = 200.0
    snap_width: float = math.radians(5.0)
    elastic_slope: float = 400.0


@dataclass(frozen=True)
class Design:
    """The design of a cell (examples/era/design.rs, `Design::default`)."""

    side: float = 1.0
    height: float = 1.0
    clevis_radius: float = 0.06
    diagonal_clevis_height: float = 0.04
    folded_scale: float = 0.2
    longeron: Tube = Tube(0.025, 0.0015)
    horizontal: Tube = Tube(0.020, 0.0010)
    diagonal: Tube = Tube(0.016, 0.0010)
    corner_base_mass: float = 0.08
    clevis_mass: float = 0.02
    corner_size: Tuple[float, float] = (0.07, 0.06)
    mid_hinge: Fitting = Fitting(0.06, 0.02, 0.04)
    mid_hinge_diagonal_mass: float = 0.02
    mesh: Tuple[int, int, int] = (4, 2, 3)  # longeron, half horizontal, diagonal
    hinge: HingeSpring = field(default_factory=HingeSpring)
    rayleigh_beta: float = 0.0
    # the latches lock at this opening angle (rad; π: the halves in line)
    locking_opening: float = PI

    def corner_body(self, clevises: int) -> Fitting:
        return Fitting(
            self.corner_base_mass + self.clevis_mass * float(clevises),
            self.corner_size[0],
            self.corner_size[1],
        )

    def mid_hinge_fitting(self, top: bool) -> Fitting:
        f = self.mid_hinge
        if top:
            f = replace(f, mass=f.mass + self.mid_hinge_diagonal_mass)
        return f


# --------------------------------------------------------------- geometry


def _sub(a: Vec, b: Vec) -> Vec:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _norm(v: Vec) -> float:
    # nalgebra's norm: the square root of the sum of squares, in order
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def _dot(a: Vec, b: Vec) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a: Vec, b: Vec) -> Vec:
    return (
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    )


@dataclass(frozen=True)
class Face:
    columns: Tuple[int, int]
    fold: float


@dataclass
class FacePoints:
    top: Tuple[Vec, Vec]
    top_mid: Vec
    bottom: Tuple[Vec, Vec]
    bottom_mid: Vec
    diagonal: Tuple[Vec, Vec]


@dataclass
class Configuration:
    scale: float
    columns: List[Tuple[float, float]]
    faces: List[FacePoints]
    opening: float


class Geometry:
    """One cell: an equilateral triangle of longerons centred on the origin,
    its mid-hinges folding outwards (examples/era/geometry.rs)."""

    def __init__(self, design: Design):
        self.design = design
        r = design.side / math.sqrt(3.0)
        self.columns = []
        for k in range(3):
            a = PI / 2.0 + 2.0 * PI * float(k) / 3.0
            self.columns.append((r * math.cos(a), r * math.sin(a)))
        self.faces = [Face((k, (k + 1) % 3), -1.0) for k in range(3)]
        p, q = self._clevises(self.columns, 0, "top")
        self.half_length = 0.5 * _norm(_sub(q, p))

    def faces_at(self, k: int) -> int:
        return sum(1 for f in self.faces if k in f.columns)

    def face_normal(self, f: int) -> Vec:
        a, b = self.faces[f].columns
        pa, pb = self.columns[a], self.columns[b]
        t = (pb[0] - pa[0], pb[1] - pa[1], 0.0)
        n = _norm(t)
        t = (t[0] / n, t[1] / n, t[2] / n)
        return (-t[1], t[0], 0.0)

    def _clevises(self, columns, f: int, kind: str) -> Tuple[Vec, Vec]:
        d = self.design
        a, b = self.faces[f].columns
        pa, pb = self.columns[a], self.columns[b]
        theta = math.atan2(pb[1] - pa[1], pb[0] - pa[0])
        z = {"top": d.height, "bottom": 0.0, "diagonal": d.diagonal_clevis_height}[kind]

        def at(column, angle):
            e = (math.cos(angle), math.sin(angle))
            return (column[0] + d.clevis_radius * e[0], column[1] + d.clevis_radius * e[1], z)

        return at(columns[a], theta), at(columns[b], theta + PI)

    def _mid_hinge(self, p: Vec, q: Vec, fold: float, top: bool) -> Vec:
        chord = _sub(q, p)
        w = _norm(chord)
        rise = math.sqrt(max(self.half_length * self.half_length - 0.25 * w * w, 0.0))
        if top:
            out = (fold * -chord[1] / w, fold * chord[0] / w, fold * 0.0 / w)
        else:
            out = (0.0, 0.0, 1.0)
        return tuple(0.5 * (p[i] + q[i]) + rise * out[i] for i in range(3))

    def at(self, s: float) -> Configuration:
        columns = [(s * c[0], s * c[1]) for c in self.columns]
        faces = []
        for f, face in enumerate(self.faces):
            top = self._clevises(columns, f, "top")
            bottom = self._clevises(columns, f, "bottom")
            faces.append(
                FacePoints(
                    top=top,
                    top_mid=self._mid_hinge(top[0], top[1], face.fold, True),
                    bottom=bottom,
                    bottom_mid=self._mid_hinge(bottom[0], bottom[1], face.fold, False),
                    diagonal=self._clevises(columns, f, "diagonal"),
                )
            )
        chord = _norm(_sub(faces[0].top[1], faces[0].top[0]))
        return Configuration(s, columns, faces, self._opening_at_chord(chord))

    def _opening_at_chord(self, chord: float) -> float:
        return 2.0 * math.asin(min(0.5 * chord / self.half_length, 1.0))

    def hinge_axis(self, f: int, top: bool) -> Vec:
        return (0.0, 0.0, 1.0) if top else self.face_normal(f)

    def opening_sense(self, f: int, top: bool) -> float:
        face = self.at(self.design.folded_scale).faces[f]
        p, q, m = (face.top[0], face.top[1], face.top_mid) if top else (
            face.bottom[0],
            face.bottom[1],
            face.bottom_mid,
        )
        u, w = _sub(p, m), _sub(q, m)
        angle = math.atan2(_dot(_cross(u, w), self.hinge_axis(f, top)), _dot(u, w))
        return math.copysign(1.0, angle)


# ------------------------------------------------------------------ model


@dataclass
class Hinge:
    """The entities of one mid-hinge."""

    joint: "unfold.JointHandle"
    law: "unfold.HingeLawHandle"
    latch: "unfold.LatchHandle"
    reference_opening: float


@dataclass
class Cell:
    """A model of the cell and its parts."""

    builder: ModelBuilder
    hinges: List[Hinge]  # top then bottom of each face
    support: "unfold.NodeHandle"
    configuration: Configuration

    def build(self) -> "unfold.Model":
        return self.builder.build()


def _fmt(x: float) -> str:
    # a float as Rust's `{}` writes it (0.01, 0, 1.5)
    s = repr(float(x))
    return s[:-2] if s.endswith(".0") else s


def build(
    gravity: float = 0.0,
    *,
    design: Optional[Design] = None,
    deployment_moment: Optional[float] = None,
    locking_peak: Optional[float] = None,
    latch_angle: Optional[float] = None,
    rayleigh_beta: Optional[float] = None,
    folded_scale: Optional[float] = None,
    rho_infinity: float = 0.5,
    end_time: float = 2.0,
    time_step: float = 0.01,
) -> Cell:
    """The deployment model of the cell (examples/era/deploy.rs, `model`):
    built folded, the first longeron's bottom corner body clamped, every
    mid-hinge with its tape spring and latch, fixed steps of `time_step`
    with `ρ∞ = rho_infinity`; gravity `gravity` (g) along the longerons,
    downwards. The keywords change one parameter of the design each: the
    tape springs' `M_d` and `M_L` (N·m), the opening angle at which the
    latches lock (rad, π in line), the members' Rayleigh `β` (s), the
    folded scale (the initial fold)."""
    d = design or Design()
    if deployment_moment is not None:
        d = replace(d, hinge=replace(d.hinge, deployment_moment=deployment_moment))
    if locking_peak is not None:
        d = replace(d, hinge=replace(d.hinge, locking_peak=locking_peak))
    if latch_angle is not None:
        d = replace(d, locking_opening=latch_angle)
    if rayleigh_beta is not None:
        d = replace(d, rayleigh_beta=rayleigh_beta)
    if folded_scale is not None:
        d = replace(d, folded_scale=folded_scale)
    geometry = Geometry(d)
    c = geometry.at(d.folded_scale)
    m = ModelBuilder(
        f"Deployment of the ERA cell by its mid-hinge tape springs, gravity {_fmt(gravity)} g"
    )

    def section(tube: Tube, name: str):
        s = tube.section().named(name)
        return s.rayleigh_damping(0.0, d.rayleigh_beta) if d.rayleigh_beta > 0.0 else s

    longeron_s = m.section(section(d.longeron, "longeron"))
    horizontal_s = m.section(section(d.horizontal, "horizontal"))
    diagonal_s = m.section(section(d.diagonal, "diagonal"))
    if gravity != 0.0:
        m.gravity([0.0, 0.0, -gravity * G0])

    def member(a: Vec, b: Vec, elements: int, s):
        na, nb = m.node(list(a)), m.node(list(b))
        return m.add(BeamLine.between(na, nb, elements, s))

    def hinge(a, b, point: Vec, axis: Vec):
        return m.add(Joint.revolute(a, b).at(list(point)).axis(list(axis)))

    def fitting(node, f: Fitting):
        m.add(RigidBody.at(node, f.mass).inertia(f.inertia()))

    n_longeron, n_half, n_diagonal = d.mesh
    columns = []
    for k, p in enumerate(c.columns):
        line = member((p[0], p[1], 0.0), (p[0], p[1], d.height), n_longeron, longeron_s)
        bottom, top = line.start(), line.end()
        faces = geometry.faces_at(k)
        fitting(top, d.corner_body(faces))
        fitting(bottom, d.corner_body(2 * faces))
        columns.append((bottom, top))

    hinges: List[Hinge] = []
    for f, face in enumerate(geometry.faces):
        p = c.faces[f]
        a, b = (columns[k] for k in face.columns)

        def horizontal(top: bool):
            if top:
                ends, mid, bodies = p.top, p.top_mid, (a[1], b[1])
            else:
                ends, mid, bodies = p.bottom, p.bottom_mid, (a[0], b[0])
            halves = [member(ends[k], mid, n_half, horizontal_s) for k in range(2)]
            axis = geometry.hinge_axis(f, top)
            for k in range(2):
                hinge(halves[k].start(), bodies[k], ends[k], axis)
            fitting(halves[0].end(), d.mid_hinge_fitting(top))
            sense = geometry.opening_sense(f, top)
            joint = hinge(
                halves[0].end(), halves[1].end(), mid, tuple(sense * x for x in axis)
            )
            # the tape spring and the latch (examples/era/hinge.rs): the
            # hinge locks at θ_L = γ_L − γ_ref
            h = d.hinge
            law = m.add(
                HingeLaw.on(joint, h.elastic_slope).tape_spring(
                    TapeSpring(
                        h.deployment_moment,
                        d.locking_opening - c.opening,
                        h.locking_peak,
                        h.locked_stiffness,
                        h.snap_width,
                    )
                )
            )
            latch = m.add(Latch.on(joint, d.locking_opening - c.opening))
            hinges.append(Hinge(joint, law, latch, c.opening))
            return halves

        top_halves = horizontal(True)
        horizontal(False)
        diagonals = [member(p.diagonal[k], p.top_mid, n_diagonal, diagonal_s) for k in range(2)]
        for k in range(2):
            hinge(diagonals[k].start(), (a[0], b[0])[k], p.diagonal[k], (0.0, 0.0, 1.0))
            hinge(diagonals[k].end(), top_halves[0].end(), p.top_mid, (0.0, 0.0, 1.0))

    support = columns[0][0]
    m.fix(support, Dofs.ALL)
    m.analysis(
        Analysis.dynamic()
        .end_time(end_time)
        .time_step(time_step)
        .max_step(time_step)
        .rho_infinity(rho_infinity)
        .error_tolerance(1e-4)
        .fixed_step()
    )
    return Cell(m, hinges, support, c)


def figures(cell: Cell, results: "unfold.Results") -> Dict[str, float]:
    """The figures of a deployment: the lock instant of each mid-hinge
    (s, NaN if open), the last one, the largest latch moment (N·m) and the
    largest tape-spring moment (N·m)."""
    locks = results.lock_times()
    out: Dict[str, float] = {}
    for k, h in enumerate(cell.hinges):
        out[f"lock_time_{k}"] = locks.get(h.latch.id, math.nan)
    times = [out[f"lock_time_{k}"] for k in range(len(cell.hinges))]
    out["last_lock"] = max(times) if all(t == t for t in times) else math.nan
    out["peak_latch_moment"] = max(
        (abs(p["peak_load"]) for p in results.peaks["latches"]), default=0.0
    )
    _, names, values = results.table("hinge_law")
    if values.size:
        out["peak_hinge_moment"] = float(abs(values[:, :, names.index("moment")]).max())
    return out


def main(argv: List[str]) -> int:
    out = argv[1] if len(argv) > 1 else "results/era_cell_python"
    gravity = float(argv[2]) if len(argv) > 2 else 0.0
    cell = build(gravity)
    model = cell.build()
    print(f"{model.describe()}")

    def progress(p):
        print(f"  t = {p.time:.3f} s  step {p.step}  {p.iterations} iterations", flush=True)

    results = model.run(out=out, progress=progress, every_seconds=1.0)
    f = figures(cell, results)
    locks = ", ".join(f"{f[f'lock_time_{k}']:.4f}" for k in range(len(cell.hinges)))
    print(
        f"{results.status}: {len(results)} steps, {results.wall_time:.2f} s; locks at t = [{locks}] s; "
        f"largest latch moment {f['peak_latch_moment']:.2f} N·m; results in {out}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
