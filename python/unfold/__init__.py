"""unfold from Python: finite-element simulation of flexible mechanisms and
deployable space structures.

Build a model with the typed builders (the same names and defaults as the
Rust builders of ``unfold::model::builder``) or read a model file, run its
analyses, and read the results as numpy arrays::

    import unfold
    from unfold import ModelBuilder, Section, BeamLine, Dofs, Load

    m = ModelBuilder("cantilever")
    root, tip = m.node([0, 0, 0]), m.node([2, 0, 0])
    s = m.section(Section.diagonal(1e8, 4e7, 4e7, 1e5, 1e5, 1e5))
    m.add(BeamLine.between(root, tip, 8, s).orientation([0, 0, 1]))
    m.fix(root, Dofs.ALL)
    m.add(Load.force(tip, [0, 0, -1]))
    results = m.build().run()
    results.position(tip)[-1]          # the tip's final position

``unfold.study`` runs parameter studies of many variants of a model on a
Dask cluster (docs/python.md).
"""

from . import _unfold
from ._unfold import *  # noqa: F401,F403
from ._unfold import (  # noqa: F401
    AnalysisError,
    Interrupted,
    ModelError,
    OutputError,
    UnfoldError,
    __version__,
    load_model,
    model_from_dict,
    model_from_toml,
)

__all__ = [name for name in dir(_unfold) if not name.startswith("_")] + ["study"]


def __getattr__(name):
    # `unfold.study` is imported on first use: it needs Dask only then
    if name == "study":
        import importlib

        return importlib.import_module(".study", __name__)
    raise AttributeError(f"module 'unfold' has no attribute {name!r}")


import sys as _sys

# `import unfold.so3` finds the submodule of the extension
_sys.modules[__name__ + ".so3"] = _unfold.so3
