"""Parameter studies on a two-worker local Dask cluster: the figures of the
variants are those of the same variants run one by one; a failed variant is
a row with its error; an interrupted study resumes without running its
finished variants again. The 100-variant study of the ERA cell is the
benchmark python/bench/study_era.py (its time is in docs/python.md); here a
reduced one."""

import math
import os

import pytest

import unfold
from unfold import study

import era_cell


def era_variant(**params):
    cell = era_cell.build(**params)
    return cell.build(), cell


def era_figures(results, cell):
    return era_cell.figures(cell, results)


# fewer steps than the example's 2 s: the six locks are before 1 s (0.96–0.99 s
# at the nominal design), 1.2 s leaves room for the weaker springs
SPAN = {"end_time": 1.2}


def variants(n, seed=1):
    return [
        dict(SPAN, **p)
        for p in study.monte_carlo(
            n, seed=seed, deployment_moment=(0.18, 0.22), rayleigh_beta=(0.0, 2e-5)
        )
    ]


@pytest.fixture(scope="module")
def client():
    from dask.distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


def compare(rows, serial):
    skip = {"wall_time", "worker_pid"}
    assert len(rows) == len(serial)
    for a, b in zip(rows, serial):
        assert set(a) == set(b)
        for k in a:
            if k in skip:
                continue
            if isinstance(a[k], float) and math.isnan(a[k]):
                assert math.isnan(b[k]), k
            else:
                assert a[k] == b[k], (k, a[k], b[k])


def test_era_study_matches_runs_one_by_one(tmp_path, client):
    vs = variants(4)
    s = study.run(vs, era_variant, figures=era_figures, directory=tmp_path, client=client,
                  elements=["latch", "hinge_law"])
    assert s.executed == list(range(4)) and s.resumed == []
    assert all(r["status"] == "completed" for r in s.rows)
    # the variants ran on both workers
    assert len({r["worker_pid"] for r in s.rows}) == 2
    serial = study.run_serial(vs, era_variant, figures=era_figures, elements=["latch", "hinge_law"])
    compare(s.rows, serial)
    # a stronger tape spring locks earlier
    pairs = sorted((r["param_deployment_moment"], r["last_lock"]) for r in s.rows)
    assert pairs[0][1] > pairs[-1][1]
    # the table and the plots
    assert s.table.name in ("study.parquet", "study.csv") and s.table.exists()
    if s.table.suffix == ".parquet":
        import pyarrow.parquet as pq

        table = pq.read_table(s.table)
        assert table.num_rows == 4 and "last_lock" in table.column_names
    assert any(p.name.startswith("hist_last_lock") for p in s.plots)
    assert any(p.name.startswith("scatter_deployment_moment") for p in s.plots)


def test_failed_variants_are_rows_with_their_errors(tmp_path, client):
    vs = [dict(SPAN, deployment_moment=0.2), dict(SPAN, deployment_moment=-0.2), dict(SPAN, design="no design")]
    s = study.run(vs, era_variant, figures=era_figures, directory=tmp_path, client=client, plots=False,
                  elements=["latch", "hinge_law"])
    assert [r["status"] for r in s.rows] == ["completed", "rejected", "error"]
    # an invalid model: the ModelError's message, as the command line's
    assert "tape_spring: deployment_moment" in s.rows[1]["error"], s.rows[1]["error"]
    # an exception of the user's function
    assert s.rows[2]["error"].startswith("AttributeError"), s.rows[2]["error"]
    assert math.isfinite(s.rows[0]["last_lock"])


def test_overrides_of_a_base_model_and_a_diverged_variant(tmp_path, client):
    base = era_cell.build(0.0, **SPAN).build()
    # a single analysis is a table of the model dictionary (a sequence a
    # list of tables: "analysis.1.rho_infinity")
    vs = [
        {"hinge_laws.*.tape_spring.deployment_moment": 0.2},
        {"hinge_laws.*.tape_spring.deployment_moment": 0.25},
        {"analysis.max_iterations": 1, "analysis.min_step": 1e-3},
    ]
    s = study.run(vs, base, directory=tmp_path, client=client, plots=False, elements=["latch", "hinge_law"])
    lock = [max(v for k, v in r.items() if k.startswith("lock_time_latch_")) for r in s.rows[:2]]
    assert lock[1] < lock[0]
    # one Newton iteration per step cannot follow the motion: the analysis
    # stops, its message in the row
    assert s.rows[2]["status"] == "failed" and "no convergence" in s.rows[2]["error"]
    serial = study.run_serial(vs, base, elements=["latch", "hinge_law"])
    compare(s.rows, serial)


def test_interrupted_study_resumes_without_running_finished_variants(tmp_path, client):
    vs = variants(4, seed=2)
    seen = []

    def interrupt(row):
        seen.append(row["index"])
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        study.run(vs, era_variant, figures=era_figures, directory=tmp_path, client=client, on_row=interrupt,
                  plots=False, elements=["latch", "hinge_law"])
    journaled = study.read_journal(tmp_path)
    assert sorted(journaled) == sorted(seen)
    s = study.run(vs, era_variant, figures=era_figures, directory=tmp_path, client=client, plots=False,
                  elements=["latch", "hinge_law"])
    assert s.resumed == sorted(seen)
    assert sorted(s.executed) == sorted(set(range(4)) - set(seen))
    for i in seen:
        assert s.rows[i] == journaled[i]
    assert len(study.read_journal(tmp_path)) == 4
