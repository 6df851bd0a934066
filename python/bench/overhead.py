"""The cost of Python: the same models built with the Python builders and
run from Python, against their model file run by the `unfold` command (the
Rust program alone), both writing the same result files; best of
`repeats` runs, alternated (the machine is shared: the smallest time is
the least disturbed). The Python time includes building the model in
Python (and, for the mast cell, its assembly run); the command's, starting
the process and reading the file.

    python python/bench/overhead.py [repeats]

Models: the ERA cell's deployment (python/examples/era_cell.py; dynamic,
265 steps) and the mast cell's folding (python/examples/mast_cell.py;
kinetostatic, 96 increments). The last column runs without result files
(every element's results kept in memory); `elements=[]` keeps the
nodes alone in memory besides the files.
"""

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
    print(
        f"{'model':26} {'unfold run MODEL':>18} {'Python: run(out)':>24} {'overhead':>9} "
        f"{'run(out, elements=[])':>19} {'overhead':>9} {'Python: run()':>21}"
    )
    for name, make in cases.items():
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "model.toml"
            path.write_text(make().to_toml())

            def cli_run():
                subprocess.run([cli, "run", str(path), "--out", str(Path(tmp) / "cli"), "--quiet"], check=True, stdout=subprocess.DEVNULL)

            def python_files():
                make().build().run(out=Path(tmp) / "py")

            def python_files_only():
                make().build().run(out=Path(tmp) / "py", elements=[])

            def python_memory():
                make().build().run()

            # alternated, so that a change of the machine's load falls on both
            cl, pf, po, pm = [], [], [], []
            for _ in range(repeats):
                cl.append(best(cli_run, 1))
                pf.append(best(python_files, 1))
                po.append(best(python_files_only, 1))
                pm.append(best(python_memory, 1))
            c, f, o, m = min(cl), min(pf), min(po), min(pm)
            print(
                f"{name:26} {c:16.3f} s {f:22.3f} s {100 * (f / c - 1):+8.1f} % {o:17.3f} s {100 * (o / c - 1):+8.1f} % {m:19.3f} s"
            )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
