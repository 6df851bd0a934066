"""The mast cell of python/examples/mast_cell.py against the Rust example
(examples/mast_cell.rs): the same model file."""

from unfold._unfold import _reference

import mast_cell


def test_python_mast_cell_is_the_rust_one():
    m, parts = mast_cell.build(24)
    assert m.to_toml() == _reference.mast_cell_model(24)
    assert len(parts.knee_drivers) == 3
