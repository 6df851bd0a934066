"""The ERA cell of python/examples/era_cell.py against the Rust example
(examples/era.rs, compiled into the module as `unfold._unfold._reference`):
the same model file, and the same lock instants and largest latch moment
to 1e-12 (the same arithmetic on the same input: they agree to the last
bit; the tolerance is the task's)."""

import math

import pytest

from unfold._unfold import _reference

import era_cell


@pytest.mark.parametrize("gravity", [0.0, 0.01])
def test_python_cell_is_the_rust_cell(gravity):
    cell = era_cell.build(gravity)
    assert cell.builder.to_toml() == _reference.era_cell_model(gravity)


def test_python_deployment_locks_as_the_rust_one():
    rust = _reference.era_cell_deployment(0.0)
    assert rust["error"] is None
    cell = era_cell.build(0.0)
    results = cell.build().run(elements=["latch", "hinge_law"])
    assert results.status == "completed"
    figures = era_cell.figures(cell, results)
    locks = [figures[f"lock_time_{k}"] for k in range(6)]
    assert [h.latch.id for h in cell.hinges] == rust["latches"]
    # every mid-hinge locks, at the instants of the Rust run
    for mine, theirs in zip(locks, rust["locks"]):
        assert theirs is not None and abs(mine - theirs) <= 1e-12, (locks, rust["locks"])
    assert abs(figures["peak_latch_moment"] - rust["peak_latch_moment"]) <= 1e-12 * rust["peak_latch_moment"]
    # the same steps to the end
    assert results.analyses[0]["increments"] == rust["steps"]
    assert results.analyses[0]["iterations"] == rust["iterations"]
    assert results.final_time == rust["time"]
    # the locks are within the span, a few milliseconds apart (examples/era.md)
    assert 0.0 < min(locks) and max(locks) < 2.0 and max(locks) - min(locks) < 0.1
