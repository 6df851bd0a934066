"""The cost of Python: the same models run from a Python-built model and
from their model file by the `unfold` command (the Rust library alone),
analysis wall time and whole-process time, best of `repeats` (the machine
is shared: the smallest time is the least disturbed).

    python python/bench/overhead.py [repeats]

Models: the ERA cell's deployment (python/examples/era_cell.py; dynamic,
265 steps) and the mast cell's folding (python/examples/mast_cell.py;
kinetostatic, 96 increments). From Python the run keeps every element's
results in memory as well as writing nothing (`out=None`); the command
line writes its result files: both are timed as each is used.
"""

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python" / "examples"))

import era_cell  # noqa: E402
import mast_cell  # noqa: E402

import unfold  # noqa: E402


def best(f, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def main(repeats: int) -> None:
    cli = os.environ.get("UNFOLD_BIN", str(ROOT / "target" / "release" / "unfold"))
    cases = {
        "ERA cell (dynamic)": lambda: era_cell.build(0.0).builder,
        "mast cell (kinetostatic)": lambda: mast_cell.build(96)[0],
    }
    rows = []
    for name, make in cases.items():
        with tempfile.TemporaryDirectory() as tmp:
            builder = make()
            path = Path(tmp) / "model.toml"
            path.write_text(builder.to_toml())

            def python_run():
                return make().build().run()

            def python_files():
                return unfold.load_model(path).run(out=Path(tmp) / "py")

            analysis = []

            def cli_run():
                subprocess.run([cli, "run", str(path), "--out", str(Path(tmp) / "cli"), "--quiet"], check=True)
                analysis.append(json.loads((Path(tmp) / "cli" / "summary.json").read_text())["wall_time_s"])

            py = best(python_run, repeats)
            py_files = best(python_files, repeats)
            cl = best(cli_run, repeats)
            rows.append((name, py, py_files, cl, min(analysis)))
    print(f"{'model':28} {'Python, built, in memory':>26} {'Python, file, with files':>26} {'unfold run (process)':>22} {'unfold run (analysis)':>22}")
    for name, py, pf, cl, an in rows:
        print(f"{name:28} {py:24.3f} s {pf:24.3f} s {cl:20.3f} s {an:20.3f} s   overhead {100 * (py / an - 1):+.1f} % / {100 * (pf / cl - 1):+.1f} %")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
