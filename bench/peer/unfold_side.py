"""The benchmark problems in unfold: model-file generators and the runner.

The models follow docs/model-format.md: `[analysis] type = "dynamic"` with
`end_time`, `time_step`, `rho_infinity`, `adaptive = false` (fixed steps)
and `output_every`; the initial velocities of a node are `velocity` and
`angular_velocity` in `[[nodes]]` (global frame).

Two ways of running them:
- `cli`: `unfold run` of the binary `$UNFOLD`, else `target/release/unfold`
  of this repository, when `unfold check` accepts the dynamic models;
- `library`: otherwise, the library through `peer_dynamics`
  (`unfold_runner.rs`, a bench target of this repository built with
  `cargo bench --no-run --bench peer_dynamics`, or `$UNFOLD_PEER_RUNNER`),
  which parses the same model file, runs `DynamicAnalysis` and writes the
  compared node at the output times (`nodes.csv`) and `summary.json`.
Either is timed as a whole process (parsing and result files included).
"""

import csv
import json
import os
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from problems import GRAVITY, OUTPUT_PERIOD, RHO_INFINITY, HeavyTop, Pendulum, steps_for

REPO = Path(__file__).resolve().parents[2]

TIP_NODE = 2  # pendulum: node at x = L
TOP_NODE = 1  # heavy top: node at the centre of mass


@dataclass
class Run:
    ok: bool
    times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    energy: np.ndarray = field(default_factory=lambda: np.zeros(0))  # J, T + V at the output times (library runner)
    wall_solve: float = 0.0  # s, the analysis as timed by unfold (summary.json)
    wall_total: float = 0.0  # s, the whole `unfold run` process
    steps: int = 0
    newton_iterations: int = 0
    jacobians: int = 0
    cutbacks: int = 0
    message: str = ""


def _vec(v):
    return "[" + ", ".join(repr(float(x) + 0.0) for x in v) + "]"  # no -0.0


# Newton's relative residual tolerance given to unfold (its residual relative
# to the force flux; `residual_tolerance` of [analysis]); None: unfold's
# default, 1e-8. With 1e-8 the pendulum of 80 elements stalls at its first
# step from rest (relative residual 2.2e-8 to 6.7e-8 whatever the step,
# 690 cut-backs at h = 2.5e-3 s), as Exudyn's Newton does at 1e-8 (see
# exudyn_side.NEWTON_RELATIVE_TOLERANCE): the round-off floor of the stiff
# beam. Both codes get 1e-6 (`run.py --unfold-residual-tolerance`).
RESIDUAL_TOLERANCE = 1.0e-6

# The frame of the angular velocities in unfold's time scheme for the
# heavy top (`[analysis] angular_velocities`, docs/theory.md §15.9):
# "spatial", whose error constant on the top is half the material scheme's,
# or "material" (unfold's default; `run.py --unfold-angular-velocities`).
# The pendulum turns about a fixed axis, where both schemes give the same
# steps, and keeps the default.
ANGULAR_VELOCITIES = "spatial"


def _analysis(end_time, h, dynamic=True, cutbacks=False, angular_velocities=None):
    """The [analysis] table: fixed steps h; with `cutbacks` False also
    min_step = h, so that a step that fails stops the run, as Exudyn's
    (otherwise unfold cuts the step back, down to 1e-6 h, and may take
    minutes before it gives up)."""
    if not dynamic:  # the same model as a static analysis, to check the rest of it
        return f'[analysis]\ntype = "static"\nend_time = {end_time!r}\n'
    every = max(1, round(OUTPUT_PERIOD / h))
    return (
        "[analysis]\n"
        'type = "dynamic"\n'
        f"end_time = {end_time!r}\n"
        f"time_step = {h!r}\n"
        f"rho_infinity = {RHO_INFINITY!r}\n"
        + (f"residual_tolerance = {RESIDUAL_TOLERANCE!r}\n" if RESIDUAL_TOLERANCE else "")
        + (f'angular_velocities = "{angular_velocities}"\n' if angular_velocities else "")
        + "adaptive = false        # fixed steps, as Exudyn's (its step reduction is off)\n"
        + ("" if cutbacks else f"min_step = {h!r}        # no cut-back: a failed step stops the run\n")
        + f"output_every = {every}   # results every {OUTPUT_PERIOD} s\n"
    )


def _node(nid, x, velocity=None, angular_velocity=None, dynamic=True):
    s = f"[[nodes]]\nid = {nid}\nx = {_vec(x)}\n"
    if velocity is not None and dynamic:
        s += f"velocity = {_vec(velocity)}\n"
    if angular_velocity is not None and dynamic:
        s += f"angular_velocity = {_vec(angular_velocity)}\n"
    return s


# No VTK files: Exudyn writes no solution file either (its sensors are kept
# in memory); unfold still writes its CSV files, nodes.csv among them.
_OUTPUT = "[output]\nvtk = false\n"

# Gravity is constant in time: the default curve of `[gravity]` is the ramp f(t) = t.
_CONSTANT_CURVE = '[[curves]]\nname = "constant"\nfunction = "linear"\noffset = 1.0\nslope = 0.0\n'


def pendulum_toml(n, h, p=Pendulum, dynamic=True, cutbacks=False):
    """Model file of the flexible pendulum with n elements and step h
    (dynamic=False: the same model as a static analysis; cutbacks: steps may
    be cut back)."""
    return "\n".join(
        [
            f'title = "Flexible beam pendulum falling from the horizontal, {n} elements"\n',
            _analysis(p.end_time, h, dynamic, cutbacks),
            "[[sections]]\n"
            'name = "beam"\n'
            f"EA = {p.EA!r}\nGA2 = {p.GA!r}\nGA3 = {p.GA!r}\nGJ = {p.GJ!r}\n"
            f"EI2 = {p.EI!r}\nEI3 = {p.EI!r}\n"
            f"mass_per_length = {p.rho_A!r}\n"
            f"inertia_per_length = {_vec([p.rho_J, p.rho_I, p.rho_I])}\n",
            _node(1, [0.0, 0.0, 0.0]),
            _node(TIP_NODE, [p.length, 0.0, 0.0]),
            "[[beam_lines]]\n"
            f"nodes = [1, {TIP_NODE}]\n"
            f"elements = {n}\n"
            'section = "beam"\n'
            "orientation = [0.0, 0.0, 1.0]\n"
            "first_node = 3\n"
            "first_element = 2\n",
            "[[joints]]              # the pin: revolute to the ground about global y\n"
            "id = 1\n"
            'type = "revolute"\n'
            "nodes = [1]\n"
            "axis = [0.0, 1.0, 0.0]\n",
            _CONSTANT_CURVE,
            f'[gravity]\nacceleration = [0.0, 0.0, {-GRAVITY!r}]\ncurve = "constant"\n',
            _OUTPUT,
        ]
    )


def top_toml(h, t=HeavyTop, dynamic=True):
    """Model file of the heavy top with step h: the node at the centre of mass,
    a spherical joint to the ground at the origin (dynamic=False: the same
    model as a static analysis, without initial velocities)."""
    return "\n".join(
        [
            'title = "Heavy top (Arnold & Brüls 2007) on a spherical joint"\n',
            _analysis(t.end_time, h, dynamic, angular_velocities=ANGULAR_VELOCITIES),
            _node(TOP_NODE, t.center_of_mass, velocity=t.com_velocity0(), angular_velocity=t.omega0, dynamic=dynamic),
            "[[rigid_bodies]]\n"
            "id = 1\n"
            f"node = {TOP_NODE}\n"
            f"mass = {t.mass!r}\n"
            f"inertia = {_vec(t.inertia_com)}\n",
            "[[joints]]\n"
            "id = 2\n"
            'type = "spherical"\n'
            f"nodes = [{TOP_NODE}]\n"
            "position = [0.0, 0.0, 0.0]\n",
            _CONSTANT_CURVE,
            f'[gravity]\nacceleration = [0.0, 0.0, {-GRAVITY!r}]\ncurve = "constant"\n',
            _OUTPUT,
        ]
    )


def binary():
    b = os.environ.get("UNFOLD")
    return Path(b) if b else REPO / "target" / "release" / "unfold"


def _check(b, text, d, name):
    """`unfold check` of a model file: "" when accepted, else its message."""
    model = Path(d) / f"{name}.toml"
    model.write_text(text)
    r = subprocess.run([str(b), "check", str(model)], capture_output=True, text=True)
    if r.returncode == 0:
        return ""
    lines = [l.strip() for l in (r.stderr or r.stdout).strip().splitlines()]
    if not lines:
        return f"exit code {r.returncode}"
    detail = [l for l in lines[1:] if l.startswith("unknown field") or l.startswith("unknown variant")]
    return " ".join([lines[0]] + detail[:1])[:300]


class ModelError(Exception):
    """unfold rejects a generated model as input: the generator, not the
    analysis, is at fault."""


def runner():
    """The library runner `peer_dynamics`: `$UNFOLD_PEER_RUNNER`, else built
    (or found up to date) by cargo. None when it cannot be built."""
    r = os.environ.get("UNFOLD_PEER_RUNNER")
    if r:
        return Path(r)
    cmd = ["cargo", "bench", "--no-run", "--bench", "peer_dynamics", "--message-format=json"]
    try:
        out = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    except OSError:
        return None
    for line in out.stdout.splitlines():
        try:
            msg = json.loads(line)
        except ValueError:
            continue
        if msg.get("reason") == "compiler-artifact" and msg.get("target", {}).get("name") == "peer_dynamics" and msg.get("executable"):
            return Path(msg["executable"])
    return None


# How unfold is run: "cli" or "library" (set by availability()).
MODE = {"how": "cli", "runner": None}


def availability():
    """(True, "") when unfold can run the dynamic models, by its binary or by
    the library runner, else (False, reason). Raises ModelError when the
    library runner rejects a generated model as input."""
    b = binary()
    why = ""
    if not b.is_file() or not os.access(b, os.X_OK):
        why = f"no unfold binary at {b} (set UNFOLD or run `cargo build --release`)"
    else:
        with tempfile.TemporaryDirectory() as d:
            for name, text in (("pendulum", pendulum_toml(2, 1e-2)), ("top", top_toml(1e-2))):
                error = _check(b, text, d, name)
                if error and not why:
                    why = f"`unfold check` rejects the dynamic {name} model: {error}"
    if not why:
        MODE["how"] = "cli"
        return True, ""
    r = runner()
    if r is None or not r.is_file():
        return False, why + "; and the library runner (cargo bench --no-run --bench peer_dynamics) could not be built"
    MODE["how"], MODE["runner"] = "library", r
    # the generated models as input (exit code 2: rejected)
    with tempfile.TemporaryDirectory() as d:
        for name, text in (("pendulum", pendulum_toml(2, 1e-2)), ("top", top_toml(1e-2))):
            model = Path(d) / f"{name}.toml"
            model.write_text(text)
            node = TIP_NODE if name == "pendulum" else TOP_NODE
            p = subprocess.run([str(r), str(model), str(Path(d) / name), str(node)], capture_output=True, text=True)
            if p.returncode == 2:
                raise ModelError(f"unfold rejects the {name} model: {p.stderr.strip()[:300]}")
    return True, ""


def describe():
    """How unfold is run, for the log."""
    if MODE["how"] == "library":
        return f"the library through {MODE['runner']} (the command-line tool does not run dynamic analyses)"
    return f"{binary()} ({version()})"


def _read_node(out, node, end_time):
    """Times, positions of `node` at the output times and the total energy
    there (when the file has it), from nodes.csv."""
    times, pos, energy = [], [], []
    with open(out / "nodes.csv", newline="") as f:
        for row in csv.DictReader(f):
            if int(row["node"]) == node:
                times.append(float(row["time"]))
                pos.append([float(row["x"]), float(row["y"]), float(row["z"])])
                if row.get("energy"):
                    energy.append(float(row["energy"]))
    times, pos = np.array(times), np.array(pos).reshape(-1, 3)
    expected = np.arange(steps_for(end_time, OUTPUT_PERIOD) + 1) * OUTPUT_PERIOD
    if times.size != expected.size or np.abs(times - expected).max() > 1e-9:
        raise ValueError(f"nodes.csv: node {node} is not written at every {OUTPUT_PERIOD} s ({times.size} rows)")
    return times, pos, np.array(energy if len(energy) == times.size else [])


def _run(text, node, end_time, h, threads, allow_cutbacks=False):
    with tempfile.TemporaryDirectory() as d:
        model, out = Path(d) / "model.toml", Path(d) / "out"
        model.write_text(text)
        if MODE["how"] == "library":
            cmd = [str(MODE["runner"]), str(model), str(out), str(node), "--threads", str(threads)]
        else:
            cmd = [str(binary()), "run", str(model), "--out", str(out), "--quiet", "--threads", str(threads)]
        t0 = time.perf_counter()
        r = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        run = Run(ok=r.returncode == 0, wall_solve=wall, wall_total=wall, steps=steps_for(end_time, h))
        if not run.ok:
            lines = (r.stderr or r.stdout).strip().splitlines()
            run.message = lines[-1] if lines else f"exit {r.returncode}"
            return run
        try:
            summary = json.loads((out / "summary.json").read_text())
            run.wall_solve = float(summary["wall_time_s"])
            run.steps = int(summary["increments"])
            run.newton_iterations = int(summary["iterations"])
            run.cutbacks = int(summary.get("cutbacks", 0))
            first = summary.get("first_cutbacks") or []
            if run.cutbacks > 0:
                run.message = f"{run.cutbacks} cut-back(s) of the step" + (f", the first at {first[0]}" if first else "")
            if run.cutbacks > 0 and not allow_cutbacks:
                # as Exudyn's adaptive step is off, a run is at the step h or fails
                run.ok = False
                return run
            run.times, run.positions, run.energy = _read_node(out, node, end_time)
        except (OSError, ValueError, KeyError) as e:
            run.ok, run.message = False, str(e)
        return run


def run_pendulum(n, h, threads=1, reference=False):
    """reference=True: the fine-step reference, whose steps may be cut back
    (it lands on the output times all the same)."""
    return _run(pendulum_toml(n, h, cutbacks=reference), TIP_NODE, Pendulum.end_time, h, threads, allow_cutbacks=reference)


def run_top(h, threads=1):
    return _run(top_toml(h), TOP_NODE, HeavyTop.end_time, h, threads)


def version():
    r = subprocess.run([str(binary()), "--version"], capture_output=True, text=True)
    return r.stdout.strip() if r.returncode == 0 else "unknown"
