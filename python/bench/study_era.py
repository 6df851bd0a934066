"""The throughput of a study: N variants of the ERA cell (Monte Carlo on
the tape springs' deployment moment and the members' Rayleigh damping) on
a local Dask cluster of two workers of one thread each, against the same
variants run one by one in this process; checks that the figures agree.

    python python/bench/study_era.py [N] [directory]

N is 100 by default; the variants run the deployment to 1.2 s (the six
locks are at 0.96–0.99 s at the nominal design)."""

import math
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python" / "examples"))
sys.path.insert(0, str(Path(__file__).parent))
# the workers import the variants and the example by name
os.environ["PYTHONPATH"] = os.pathsep.join([str(ROOT / "python" / "examples"), str(Path(__file__).parent)])

from unfold import study  # noqa: E402

from era_study import era_figures, era_variant, variants  # noqa: E402


def main(n: int, directory: str) -> None:
    vs = variants(n)
    t = time.perf_counter()
    s = study.run(vs, era_variant, figures=era_figures, directory=directory, resume=False,
                  elements=["latch", "hinge_law"])
    parallel = time.perf_counter() - t
    t = time.perf_counter()
    serial = study.run_serial(vs, era_variant, figures=era_figures, elements=["latch", "hinge_law"])
    one_by_one = time.perf_counter() - t
    skip = {"wall_time", "worker_pid"}
    mismatches = 0
    for a, b in zip(s.rows, serial):
        for k in a:
            if k in skip:
                continue
            x, y = a[k], b.get(k)
            same = (isinstance(x, float) and math.isnan(x) and isinstance(y, float) and math.isnan(y)) or x == y
            mismatches += not same
    completed = sum(r["status"] == "completed" for r in s.rows)
    print(f"{n} variants: {completed} completed; study on 2 workers {parallel:.1f} s "
          f"({n / parallel:.2f} variants/s), one by one {one_by_one:.1f} s ({n / one_by_one:.2f} variants/s), "
          f"speed-up {one_by_one / parallel:.2f}; figures differing from the runs one by one: {mismatches}")
    print(f"table {s.table}; {len(s.plots)} plots in {Path(directory) / 'plots'}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 100, sys.argv[2] if len(sys.argv) > 2 else "results/era_study")
