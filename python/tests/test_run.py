"""Runs from Python: results as numpy arrays against the result files of
the same run, the progress callback, interruptions that keep the results,
and analysis errors with the command line's messages."""

import _thread
import csv
import json
import math
import threading

import numpy as np
import pytest

import unfold

from conftest import EXAMPLES, run_cli


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def test_rollup_arrays_match_the_result_files(tmp_path):
    model = unfold.load_model(EXAMPLES / "cantilever_rollup.toml")
    results = model.run(out=tmp_path)
    steps, nodes = len(results), model.n_nodes
    assert steps == 11 and nodes == 11
    assert results.times.shape == (steps,)
    assert results.positions.shape == (steps, nodes, 3)
    assert results.rotations.shape == (steps, nodes, 3)
    assert results.quaternions.shape == (steps, nodes, 4)
    assert results.velocities.shape == (steps, nodes, 6)
    ids, names, beams = results.table("beam")
    assert beams.shape == (steps, 10, len(names)) and names[:3] == ["N", "V2", "V3"]
    # Euler: M = 2πEI/L rolls the strip into a full circle, the tip back
    # at the clamp (README: within 1.4e-16 L) and turned by 2π about z;
    # the rotation vector is the one of angle in [0, π]: ~0
    tip = list(model.node_ids).index(11)
    assert np.linalg.norm(results.positions[-1, tip]) < 1e-12
    assert abs(results.quaternions[-1, tip, 0] + 1.0) < 1e-12  # q = −1: a turn of 2π
    # the arrays are the numbers of nodes.csv (13 significant digits) and
    # beams.csv (10)
    rows = read_csv(tmp_path / "nodes.csv")
    assert len(rows) == steps * nodes
    for row in rows:
        s, i = int(row["step"]), list(model.node_ids).index(int(row["node"]))
        for k, c in enumerate("xyz"):
            assert abs(float(row[c]) - results.positions[s, i, k]) <= 1e-12 * max(1.0, abs(float(row[c])))
        q = [float(row[c]) for c in ("qw", "qx", "qy", "qz")]
        np.testing.assert_array_equal(q, results.quaternions[s, i])
        assert abs(float(row["time"]) - results.times[s]) <= 1e-12
    for row in read_csv(tmp_path / "beams.csv"):
        s, e = int(row["step"]), ids.index(int(row["element"]))
        for k, name in enumerate(names):
            v = float(row[name])
            assert abs(v - beams[s, e, k]) <= 1e-9 * max(1.0, abs(v)), (name, v, beams[s, e, k])
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["output_steps"] == steps


def test_joint_results_are_named_as_the_columns_of_joints_csv(tmp_path):
    # three revolute joints and a prismatic one: joints.csv has `angle`
    # and `slide`, each joint's row empty in the coordinate it lacks
    model = unfold.load_model(EXAMPLES / "slider_crank.toml")
    results = model.run(out=tmp_path)
    with open(tmp_path / "joints.csv") as f:
        header = f.readline().strip().split(",")
    assert header[:6] == ["step", "time", "joint", "type", "angle", "slide"]
    ids, names, values = results.table("joint")
    assert names == header[4:]
    assert ids == [1, 2, 3, 4]
    rows = read_csv(tmp_path / "joints.csv")
    assert len(rows) == len(results) * len(ids)
    for j in ids:
        h = results.element(("joint", j))
        mine = [r for r in rows if int(r["joint"]) == j]
        assert h.joint_type == mine[0]["type"] == ("prismatic" if j == 4 else "revolute")
        coordinate = "slide" if j == 4 else "angle"
        other = "angle" if j == 4 else "slide"
        # its own coordinate, then the loads, as the file names them
        assert h.names == [coordinate] + header[6:]
        assert other not in h
        with pytest.raises(KeyError, match=f'no result named "{other}"'):
            h[other]
        e = ids.index(j)
        for s, row in enumerate(mine):
            assert row[other] == ""
            assert np.isnan(values[s, e, names.index(other)])
            for name in h.names:
                v = float(row[name])
                assert abs(v - h[name][s]) <= 1e-9 * max(1.0, abs(v)), (j, name, v)
                assert values[s, e, names.index(name)] == h[name][s]
    # the crank turns once, driven: its angle goes from 0 to 2π, and the
    # slider is back where it started
    crank, slider = results.element(("joint", 1)), results.element(("joint", 4))
    assert crank["angle"][0] == 0.0 and abs(crank["angle"][-1] - 2 * math.pi) < 1e-9
    assert abs(slider["slide"][-1]) < 1e-9 < np.max(np.abs(slider["slide"]))


def test_dynamics_energies_and_events_match_the_files(tmp_path):
    model = unfold.load_model(EXAMPLES / "bar_drop.toml")
    results = model.run(out=tmp_path)
    e = results.energies
    rows = read_csv(tmp_path / "energies.csv")
    assert len(rows) == len(results) == len(e["kinetic"])
    for s, row in enumerate(rows):
        for name in ("kinetic", "strain", "gravity", "balance_error"):
            v = float(row[name])
            assert abs(v - e[name][s]) <= 1e-6 * max(1.0, abs(v))
    events = read_csv(tmp_path / "events.csv")
    assert len(events) == len(results.events) > 0
    for row, ev in zip(events, results.events):
        assert float(row["time"]) == ev["time"]  # written to the last digit
        assert row["kind"] == ev["kind"]
    contacts = json.loads((tmp_path / "summary.json").read_text())["contacts"]
    assert contacts == results.peaks["contacts"]


def test_modes_match_modes_csv(tmp_path):
    model = unfold.load_model(EXAMPLES / "cantilever_modes.toml")
    results = model.run(out=tmp_path)
    modes = results.modes
    assert len(modes) == 2
    rows = read_csv(tmp_path / "modes.csv")
    groups = []
    for r in rows:
        if not groups or groups[-1][0]["analysis"] != r["analysis"]:
            groups.append([])
        groups[-1].append(r)
    assert len(groups) == len(modes)
    for m, mine in zip(modes, groups):
        assert len(mine) == len(m) > 0
        for k, r in enumerate(mine):
            assert float(r["frequency_hz"]) == m.frequencies[k]
        assert m.shapes.shape == (len(m), model.n_nodes, 6)
    # the tip tension stiffens the first pair: 3.56 Hz -> 11.68 Hz (README)
    assert abs(modes[0].frequencies[0] - 3.56) < 0.01 and abs(modes[1].frequencies[0] - 11.68) < 0.01


def test_progress_callback_every_steps_and_seconds():
    model = unfold.load_model(EXAMPLES / "double_pendulum.toml")
    seen = []
    results = model.run(progress=seen.append, every_steps=5)
    assert seen and seen[0].step == 0
    steps = [p.step for p in seen]
    assert all(b - a == 5 for a, b in zip(steps, steps[1:]))
    times = [p.time for p in seen]
    assert times == sorted(times) and times[-1] <= results.final_time
    assert all(p.analysis_type == "dynamic" and p.iterations >= 0 for p in seen)
    every = []
    model.run(progress=every.append)
    assert len(every) == results.analyses[0]["increments"] + 1
    timed = []
    model.run(progress=timed.append, every_seconds=1e9)
    assert len(timed) == 1  # the first step only


def test_exception_in_callback_stops_the_run_keeping_results(tmp_path):
    model = unfold.load_model(EXAMPLES / "double_pendulum.toml")

    def stop_at_ten(p):
        if p.step == 10:
            raise KeyboardInterrupt

    with pytest.raises(unfold.Interrupted) as e:
        model.run(out=tmp_path, progress=stop_at_ten, every_steps=1)
    assert isinstance(e.value, KeyboardInterrupt)
    results = e.value.results
    assert results.status == "interrupted"
    # the step during which the stop was asked is kept, after the output
    # steps before it (every 5 steps, `output_every`)
    assert list(results.increments) == [0, 5, 10]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "interrupted" and summary["output_steps"] == 3
    assert "interrupted" in str(e.value) and "results up to t = " in str(e.value)

    def fail(p):
        if p.step == 3:
            raise ValueError("no more")

    with pytest.raises(ValueError, match="no more") as e:
        model.run(progress=fail)
    assert list(e.value.results.increments) == [0, 3] and e.value.results.status == "interrupted"


def test_ctrl_c_stops_the_run_keeping_results(tmp_path):
    # a Ctrl-C while the analysis runs without the GIL: SIGINT's handler
    # raises KeyboardInterrupt in the main thread when the run looks at the
    # signals, between two steps
    # 2 s of the example run in about 30 ms, less than the 50 ms between
    # two looks at the signals: 200 s make sure the Ctrl-C comes mid-run
    text = (EXAMPLES / "double_pendulum.toml").read_text()
    assert "end_time = 2.0" in text
    path = tmp_path / "long_pendulum.toml"
    path.write_text(text.replace("end_time = 2.0", "end_time = 200.0"))
    model = unfold.load_model(path)
    started = threading.Event()

    def first(p):
        started.set()

    timer = threading.Thread(target=lambda: (started.wait(), _thread.interrupt_main()))
    timer.start()
    with pytest.raises(unfold.Interrupted) as e:
        model.run(out=tmp_path / "out", progress=first, every_seconds=1e9)
    timer.join()
    results = e.value.results
    assert 0 < len(results) and results.final_time < 200.0
    assert results.status == "interrupted"
    assert results.times[-1] == results.final_time
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "interrupted" and summary["output_steps"] == len(results)


def test_analysis_error_has_the_messages_of_the_command_line(tmp_path, cli):
    # a cantilever loaded far beyond its strength: the load increments
    # fail at the smallest step
    text = (EXAMPLES / "cantilever_rollup.toml").read_text()
    text = text.replace("62.83185307179586", "1.0e9").replace(
        "initial_increment = 0.1", "initial_increment = 0.5\nmin_increment = 0.25\nmax_iterations = 3"
    )
    path = tmp_path / "overload.toml"
    path.write_text(text)
    model = unfold.load_model(path)
    with pytest.raises(unfold.AnalysisError) as e:
        model.run()
    assert e.value.results.status == "failed" and len(e.value.results) >= 1
    cli_run = run_cli(cli, "run", path, "--out", tmp_path / "out", "--quiet")
    assert cli_run.returncode == 1
    assert f"error: {e.value}" in cli_run.stderr.splitlines()
    results = model.run(check=False)
    assert results.status == "failed" and results.error == str(e.value)


def test_start_checks_are_model_errors(tmp_path, cli):
    # a mechanism in statics: `unfold run` refuses it with exit code 2
    m = unfold.ModelBuilder("free link")
    a, b = m.node([0, 0, 0]), m.node([1, 0, 0])
    s = m.section(unfold.Section.diagonal(1e6, 1e6, 1e6, 1e3, 1e3, 1e3))
    m.add(unfold.BeamLine.between(a, b, 2, s))
    m.add(unfold.Joint.revolute(a, unfold.Ground).axis([0, 0, 1]))
    model = m.build()
    with pytest.raises(unfold.ModelError) as e:
        model.check()
    with pytest.raises(unfold.ModelError) as r:
        model.run()
    assert str(r.value) == str(e.value) and r.value.results.status == "rejected"
    path = tmp_path / "free.toml"
    path.write_text(m.to_toml())
    loaded = unfold.load_model(path)
    with pytest.raises(unfold.ModelError) as f:
        loaded.run()
    out = run_cli(cli, "run", path, "--out", tmp_path / "out", "--quiet")
    assert out.returncode == 2 and f"error: {f.value}" in out.stderr.splitlines()


def test_elements_kept_and_lookup():
    model = unfold.load_model(EXAMPLES / "four_bar.toml")
    results = model.run(elements=["joint"])
    assert {k for k, _ in results.elements()} == {"joint"}
    kind, id_ = results.elements()[0]
    h = results.element((kind, id_))
    assert h.values.shape == (len(results), len(h.names))
    with pytest.raises(KeyError):
        results.element(("beam", 1))
    with pytest.raises(ValueError, match="no kind of element"):
        model.run(elements=["beems"])


def test_bodies_ending_inside_one_another_are_warned_of(tmp_path):
    # the tutorial's wing with hinge 3's axis along the panel (z) instead
    # of the hinge line (y): panel 2 turns in the plane of panel 1 and ends
    # on it; the warning of `unfold run` is in the results, with or without
    # result files (docs/model-format.md, "Checks, warnings and limits")
    text = (EXAMPLES / "wing_rigid.toml").read_text()
    hinge_3 = 'id = 300\ntype = "revolute"\nnodes = [20, 30]\naxis = [0.0, 1.0, 0.0]'
    assert hinge_3 in text
    path = tmp_path / "wrong_axis.toml"
    path.write_text(text.replace(hinge_3, hinge_3.replace("[0.0, 1.0, 0.0]", "[0.0, 0.0, 1.0]")))
    expected = "100% of rigid body 31 lies inside rigid body 21 at the end of the run (t = 5)"
    results = unfold.load_model(path).run()
    assert results.status == "completed"
    assert [w for w in results.warnings if w.startswith(expected)], results.warnings
    written = unfold.load_model(path).run(out=tmp_path / "out")
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert [w for w in summary["warnings"] if w.startswith(expected)], summary["warnings"]
    assert [w for w in written.warnings if w.startswith(expected)]
    # the right model: none
    right = unfold.load_model(EXAMPLES / "wing_rigid.toml").run()
    assert not [w for w in right.warnings if "lies inside" in w], right.warnings
