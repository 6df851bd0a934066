"""Shared fixtures: the repository's paths and the `unfold` command (the
release build that `cargo test --release` leaves, for comparing messages
with the command line's)."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
sys.path.insert(0, str(ROOT / "python" / "examples"))
# the workers of a local Dask cluster import the tests' modules and the
# examples by name
os.environ["PYTHONPATH"] = os.pathsep.join(
    [str(ROOT / "python" / "examples"), str(Path(__file__).parent)]
    + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else [])
)


@pytest.fixture(scope="session")
def cli():
    """The `unfold` command: $UNFOLD_BIN, target/release/unfold, or built
    with cargo."""
    path = os.environ.get("UNFOLD_BIN")
    if path:
        return Path(path)
    path = ROOT / "target" / "release" / "unfold"
    if not path.exists():
        if shutil.which("cargo") is None:
            pytest.skip("no unfold command and no cargo to build it")
        subprocess.run(["cargo", "build", "--release", "--bin", "unfold"], cwd=ROOT, check=True)
    return path


def run_cli(cli, *args, cwd=None):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, cwd=cwd)
