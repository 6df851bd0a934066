"""The builders from Python: the same models as the Rust builders, the same
checks and messages as model files and the command line."""

import math

import numpy as np
import pytest

import unfold
from unfold import (
    Analysis,
    AngleUnit,
    BeamLine,
    Component,
    CurveHandle,
    Dofs,
    Driver,
    Gravity,
    Ground,
    Joint,
    Load,
    LoadCurve,
    ModelBuilder,
    Section,
)

from conftest import run_cli


def cantilever(elements=8, load=-1.0):
    m = ModelBuilder("cantilever")
    root, tip = m.node([0.0, 0.0, 0.0]), m.node([2.0, 0.0, 0.0])
    s = m.section(Section.diagonal(1e8, 4e7, 4e7, 1e5, 1e5, 1e5))
    line = m.add(BeamLine.between(root, tip, elements, s).orientation([0.0, 0.0, 1.0]))
    m.fix(root, Dofs.ALL)
    m.add(Load.force(tip, [0.0, 0.0, load]))
    return m, root, tip, line


def test_cantilever_deflection_and_handles():
    m, root, tip, line = cantilever()
    assert [n.id for n in line.nodes] == [1, 3, 4, 5, 6, 7, 8, 9, 2]
    assert len(line.elements) == 8 and line.elements[0].kind == "beam"
    assert line.start() == root and line.end() == tip and len(line.interior()) == 7
    results = m.build().run()
    # tip deflection ≈ P L³/3EI = 8/3e5 (Euler–Bernoulli), within 1 % with
    # 8 elements (one-point integration, docs/theory.md; README's example)
    z = results.position(tip)[-1, 2]
    assert abs(z + 8.0 / 3e5) < 1e-2 * 8.0 / 3e5
    assert results.status == "completed" and results.error is None


def test_driven_arm_as_the_readme_rust_example():
    # README.md's Rust example, from Python: the same figures
    m = ModelBuilder("driven arm")
    hub, tip = m.node([0.0, 0.0, 0.0]), m.node([1.0, 0.0, 0.0])
    ea, ga, gj, ei, rho_a = 7.92e6, 1.49e6, 244.0, 325.0, 0.305
    tube = m.section(Section.diagonal(ea, ga, ga, gj, ei, ei).mass_per_length(rho_a))
    arm = m.add(BeamLine.between(hub, tip, 10, tube).orientation([0.0, 0.0, 1.0]))
    hinge = m.add(Joint.revolute(hub, Ground).axis([0.0, 0.0, 1.0]))
    smooth = m.curve(LoadCurve.smooth_step(0.0, 1.0))
    drive = m.add(Driver.on(hinge).angle(90.0, AngleUnit.Deg).curve(smooth))
    m.add(Gravity.of([0.0, 0.0, -9.81]).curve(CurveHandle.CONSTANT))
    m.analysis(Analysis.kinetostatic().initial_increment(0.1))
    assert 'type = "revolute"' in m.to_toml()
    results = m.build().run()
    q, l = rho_a * 9.81, 1.0
    sag = q * l**4 / (8.0 * ei) + q * l * l / (2.0 * ga)
    x = results.position(arm.end())[-1]
    assert abs(x[0]) < 1e-2 and abs(x[1] - 1.0) < 1e-2
    assert abs(-x[2] - sag) < 1e-2 * sag
    # the hinge holds the arm's weight; the driver carries no torque
    assert abs(results.element(hinge)["Fz"][-1] - q * l) < 1e-6 * q * l
    assert abs(results.element(drive)["load"][-1]) < 1e-6 * q * l * l
    assert abs(results.element(drive)["coordinate"][-1] - math.pi / 2) < 1e-9


def test_dofs_and_components():
    assert Component.X | Component.Rz == Dofs.NONE | [Component.X, Component.Rz]
    assert Component.Z in Dofs.TRANSLATIONS and Component.Rz not in Dofs.TRANSLATIONS
    m, root, tip, _ = cantilever()
    m2 = ModelBuilder("t")
    a = m2.node([0, 0, 0])
    m2.fix(a, [Component.X, Component.Rz])
    assert m2.to_dict()["supports"][0]["fixed"] == ["x", "rz"]


def test_toml_and_dict_round_trips_give_the_same_results():
    m, _, tip, _ = cantilever()
    direct = m.build().run()
    from_toml = unfold.model_from_toml(m.to_toml()).run()
    from_dict = unfold.model_from_dict(m.build().to_dict()).run()
    for r in (from_toml, from_dict):
        np.testing.assert_array_equal(r.positions, direct.positions)
    # a model crosses processes (Dask) by its model file
    import pickle

    again = pickle.loads(pickle.dumps(m.build()))
    np.testing.assert_array_equal(again.run().positions, direct.positions)


def invalid_builder():
    m = ModelBuilder("bad")
    a, b = m.node([0, 0, 0]), m.node([0, 0, 0])
    s = m.section(Section.diagonal(1e8, 4e7, 4e7, 1e5, -1e5, 1e5))
    m.add(BeamLine.between(a, b, 2, s))
    return m


def test_builder_errors_are_model_errors_with_the_messages_of_model_files(tmp_path, cli):
    m = invalid_builder()
    with pytest.raises(unfold.ModelError) as built:
        m.build()
    message = str(built.value)
    assert "EI2" in message or "stiffness" in message, message
    assert message.startswith("section \"section_1\""), message
    assert built.value.errors and all(len(e) == 2 for e in built.value.errors)
    # the same model as a file: the same problems, each after the file's name
    path = tmp_path / "bad.toml"
    path.write_text(m.to_toml())
    with pytest.raises(unfold.ModelError) as loaded:
        unfold.load_model(path)
    lines = str(loaded.value).splitlines()
    assert lines == [f"{path}: {line}" for line in message.splitlines()]
    # and the command line says the same after `error: `
    checked = run_cli(cli, "check", path)
    assert checked.returncode == 2
    assert checked.stderr.strip() == f"error: {loaded.value}"


def test_unreadable_and_malformed_files(tmp_path, cli):
    with pytest.raises(unfold.ModelError, match="cannot read the file"):
        unfold.load_model(tmp_path / "missing.toml")
    path = tmp_path / "typo.toml"
    path.write_text('titel = "x"\n[[nodes]]\nid = 1\nx = [0.0, 0.0, 0.0]\n')
    with pytest.raises(unfold.ModelError) as e:
        unfold.load_model(path)
    assert "titel" in str(e.value)
    checked = run_cli(cli, "check", path)
    assert checked.returncode == 2 and checked.stderr.strip() == f"error: {e.value}"


def test_add_refuses_what_is_not_an_entity():
    m = ModelBuilder("x")
    with pytest.raises(TypeError, match="cannot add a str"):
        m.add("node")
    with pytest.raises(TypeError):
        Joint.revolute(m.node([0, 0, 0]), "ground")
