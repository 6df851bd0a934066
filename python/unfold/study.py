"""Parameter studies on Dask distributed: N variants of a model run on a
cluster (a local one by default: two worker processes of one thread each;
or a remote one given its scheduler's address), their figures gathered
into one table, with plots of their distributions.

A variant is a dictionary of parameters. The model of a variant is made by
``model``, one of:

- a function ``model(**params)`` returning an ``unfold.Model``, a
  ``ModelBuilder``, or a pair ``(model, context)`` whose ``context`` is
  passed on to ``figures``;
- an ``unfold.Model`` (or ``ModelBuilder``) to which each variant's
  parameters are applied as overrides of its model-file dictionary
  (``Model.to_dict``): a key is a path of fields separated by dots, a
  number picks an entry of a list and ``*`` every entry, e.g.
  ``{"hinge_laws.*.tape_spring.deployment_moment": 0.3,
  "analysis.rho_infinity": 0.6}`` (in a sequence of analyses
  ``"analysis.1.rho_infinity"``).

Each finished variant is a row: its index, its parameters, ``status``
(``completed``, ``failed``, ``interrupted``, ``rejected``: an invalid
model, or ``error``: an exception in the user's code), ``error``,
``wall_time`` (s), the default figures (``steps``, ``final_time``, the lock
time and the largest load of every latch, the largest load of every stop
and contact, the largest moment of the hinge laws, the largest final
displacement and the final extent of the nodes along x, y, z) and those of
``figures(results, context)`` if given. A variant that fails is a row with
its error, never a lost study.

Rows are appended, as they finish, to the journal ``journal.jsonl`` in the
study's directory: a study interrupted (Ctrl-C, a lost client) and run
again with the same directory runs only the variants not in the journal.
At the end the table is written as ``study.parquet`` if pyarrow is
installed, ``study.csv`` otherwise, with plots of the distributions of the
figures (histograms) and of the figures against each parameter (scatter)
in ``plots/``.

Why Dask rather than Ray: the variants are independent tasks of a few
seconds whose results are small dictionaries, which a task scheduler with
a Python client serves well; Dask distributed installs from PyPI as pure
Python (no binary runtime of its own), its LocalCluster starts worker
processes on one machine with no set-up and a remote cluster is the same
client given an address (``dask scheduler`` / ``dask worker`` on the
machines, or a cluster manager), and its futures give each result as it
finishes (the journal) and cancel the rest on an interruption.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import os
import random
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Union

import unfold

Params = Dict[str, Any]
Row = Dict[str, Any]

JOURNAL = "journal.jsonl"


# ---------------------------------------------------------------- variants


def grid(**values: Sequence[Any]) -> List[Params]:
    """Every combination of the given values: ``grid(a=[1, 2], b=[3, 4])``
    gives four variants, the last parameter varying fastest."""
    names = list(values)
    return [dict(zip(names, combo)) for combo in itertools.product(*(values[n] for n in names))]


def monte_carlo(n: int, seed: int = 0, **distributions: Any) -> List[Params]:
    """``n`` variants sampled at random (reproducibly from ``seed``): each
    parameter is a pair ``(low, high)`` (uniform), a list (one of its
    values, with equal chances) or a function of a ``random.Random``
    (``lambda r: r.gauss(0.2, 0.01)``)."""
    rng = random.Random(seed)
    out = []
    for _ in range(n):
        params: Params = {}
        for name, d in distributions.items():
            if callable(d):
                params[name] = d(rng)
            elif isinstance(d, tuple) and len(d) == 2:
                params[name] = rng.uniform(float(d[0]), float(d[1]))
            elif isinstance(d, list):
                params[name] = rng.choice(d)
            else:
                raise TypeError(
                    f"parameter {name!r}: a (low, high) pair, a list of values or a function of a random.Random"
                )
        out.append(params)
    return out


def apply_overrides(model_dict: Dict[str, Any], overrides: Mapping[str, Any]) -> Dict[str, Any]:
    """Sets each ``path: value`` of ``overrides`` in the model-file
    dictionary ``model_dict`` (changed in place, and returned)."""
    for path, value in overrides.items():
        parts = path.split(".")
        targets: List[Any] = [model_dict]
        for k, part in enumerate(parts):
            last = k == len(parts) - 1
            nxt: List[Any] = []
            for t in targets:
                if isinstance(t, list):
                    if part == "*":
                        keys: Iterable[Any] = range(len(t))
                    elif part.lstrip("-").isdigit():
                        keys = [int(part)]
                    else:
                        raise KeyError(f"override {path!r}: {part!r} is not an index of a list")
                elif isinstance(t, dict):
                    if part == "*":
                        keys = list(t)
                    elif not last and part not in t:
                        raise KeyError(f"override {path!r}: no field {part!r}")
                    else:
                        keys = [part]
                else:
                    raise KeyError(f"override {path!r}: {part!r} is inside a value, not a table")
                for key in keys:
                    if last:
                        t[key] = value
                    else:
                        nxt.append(t[key])
            targets = nxt
    return model_dict


# ------------------------------------------------------------- one variant


def default_figures(results: "unfold.Results", model: "unfold.Model") -> Row:
    """The figures of every run: counts, the lock time and largest load of
    every latch, the largest load of every stop and contact, the largest
    moment of the hinge laws, the final geometry."""
    row: Row = {"steps": len(results), "final_time": results.final_time}
    locks = results.lock_times()
    peaks = results.peaks
    for p in peaks["latches"]:
        row[f"lock_time_latch_{p['latch']}"] = locks.get(p["latch"], math.nan)
        row[f"peak_latch_{p['latch']}"] = p["peak_load"]
    for p in peaks["stops"]:
        row[f"peak_stop_{p['stop']}"] = p["peak_load"]
    for p in peaks["contacts"]:
        row[f"peak_contact_{p['contact']}"] = p["peak_load"]
    if peaks["latches"]:
        row["peak_latch_load"] = max(abs(p["peak_load"]) for p in peaks["latches"])
    ids, names, values = results.table("hinge_law")
    if ids and len(results) and "moment" in names:
        import numpy as np

        row["peak_hinge_moment"] = float(np.nanmax(np.abs(values[:, :, names.index("moment")])))
    import numpy as np

    x = results.final_positions
    x0 = model.reference_positions
    if len(x):
        row["final_max_displacement"] = float(np.max(np.linalg.norm(x - x0, axis=1)))
        extent = x.max(axis=0) - x.min(axis=0)
        for k, axis in enumerate("xyz"):
            row[f"final_extent_{axis}"] = float(extent[k])
    return row


def _make(model: Any, params: Params):
    """The model of a variant and the context passed to the figures."""
    context = None
    if isinstance(model, (unfold.Model, unfold.ModelBuilder)):
        d = apply_overrides(model.to_dict(), params)
        return unfold.model_from_dict(d), None
    made = model(**params)
    if isinstance(made, tuple):
        made, context = made
    if isinstance(made, unfold.ModelBuilder):
        made = made.build()
    if not isinstance(made, unfold.Model):
        raise TypeError(f"the model function returned a {type(made).__name__}, not an unfold.Model")
    return made, context


def run_variant(
    index: int,
    params: Params,
    model: Any,
    figures: Optional[Callable[..., Mapping[str, Any]]] = None,
    elements: Optional[List[str]] = None,
) -> Row:
    """Runs one variant and returns its row (never raises: an error is the
    row's ``status`` and ``error``). What each worker of a study runs, and
    what a study made one by one runs."""
    started = time.perf_counter()
    row: Row = {"index": index}
    row.update({f"param_{k}": v for k, v in params.items()})
    try:
        m, context = _make(model, params)
        results = m.run(check=False, elements=elements)
        row["status"] = results.status
        row["error"] = results.error or ""
        row.update(default_figures(results, m))
        if figures is not None:
            extra = figures(results, context) if context is not None else figures(results)
            row.update(extra)
    except unfold.ModelError as e:
        row["status"], row["error"] = "rejected", str(e)
    except Exception as e:  # the user's model or figures function
        row["status"], row["error"] = "error", f"{type(e).__name__}: {e}"
    row["wall_time"] = time.perf_counter() - started
    row["worker_pid"] = os.getpid()
    return row


# ------------------------------------------------------------------ study


@dataclass
class Study:
    """What a study produced: its rows (in the order of the variants), the
    table and plots written, the variants run by this call and those
    taken from the journal."""

    rows: List[Row]
    table: Path
    plots: List[Path] = field(default_factory=list)
    executed: List[int] = field(default_factory=list)
    resumed: List[int] = field(default_factory=list)
    wall_time: float = 0.0

    def column(self, name: str) -> List[Any]:
        """One column of the table."""
        return [r.get(name) for r in self.rows]


def _json_value(v: Any) -> Any:
    if isinstance(v, float) and not math.isfinite(v):
        return {"float": repr(v)}
    return v


def _from_json(v: Any) -> Any:
    if isinstance(v, dict) and set(v) == {"float"}:
        return float(v["float"])
    return v


def read_journal(directory: Union[str, os.PathLike]) -> Dict[int, Row]:
    """The rows of the journal of a study, by variant index (a line cut
    short by an interruption is ignored)."""
    path = Path(directory) / JOURNAL
    rows: Dict[int, Row] = {}
    if not path.exists():
        return rows
    with open(path, encoding="utf-8") as f:
        for line in f:
            try:
                entry = json.loads(line)
            except json.JSONDecodeError:
                continue
            row = {k: _from_json(v) for k, v in entry["row"].items()}
            rows[int(row["index"])] = row
    return rows


def _append(path: Path, row: Row) -> None:
    with open(path, "a", encoding="utf-8") as f:
        f.write(json.dumps({"row": {k: _json_value(v) for k, v in row.items()}}) + "\n")
        f.flush()
        os.fsync(f.fileno())


def _same_params(row: Row, params: Params) -> bool:
    return all(row.get(f"param_{k}") == v for k, v in params.items())


def write_table(rows: List[Row], directory: Path) -> Path:
    """The table: ``study.parquet`` with pyarrow, ``study.csv`` without."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        pa = None
    names: List[str] = []
    for r in rows:
        names.extend(k for k in r if k not in names)
    if pa is not None:
        columns = {n: [r.get(n) for r in rows] for n in names}
        path = directory / "study.parquet"
        pq.write_table(pa.table(columns), path)
        return path
    path = directory / "study.csv"
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=names)
        w.writeheader()
        for r in rows:
            w.writerow({n: r.get(n, "") for n in names})
    return path


def _numeric(rows: List[Row], name: str) -> List[float]:
    return [
        float(r[name])
        for r in rows
        if isinstance(r.get(name), (int, float)) and not isinstance(r.get(name), bool) and math.isfinite(float(r[name]))
    ]


def plot(rows: List[Row], directory: Path, fmt: str = "png", key: Optional[Sequence[str]] = None) -> List[Path]:
    """Histograms of every figure that varies, and for each parameter the
    key figures against it (``key``: by default the last lock, the largest
    latch and hinge loads and the largest final displacement, then the
    figures of each latch, six at most), into ``directory/plots``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = directory / "plots"
    out.mkdir(parents=True, exist_ok=True)
    skip = {"index", "worker_pid"}
    names: List[str] = []
    for r in rows:
        names.extend(k for k in r if k not in names and k not in skip)
    params = [n for n in names if n.startswith("param_")]
    figures = [n for n in names if not n.startswith("param_")]
    varying = [n for n in figures if len(set(_numeric(rows, n))) > 1]
    written = []
    for name in varying:
        fig, ax = plt.subplots(figsize=(5, 3.5))
        ax.hist(_numeric(rows, name), bins=min(30, max(5, len(rows) // 4)))
        ax.set_xlabel(name)
        ax.set_ylabel("variants")
        ax.set_title(f"{name} ({len(_numeric(rows, name))} variants)")
        fig.tight_layout()
        path = out / f"hist_{name}.{fmt}"
        fig.savefig(path)
        plt.close(fig)
        written.append(path)
    if key is None:
        # the figures of the whole structure first, then those of each part
        first = ["last_lock", "peak_latch_moment", "peak_latch_load", "peak_hinge_moment", "final_max_displacement"]
        rest = [n for n in varying if n.startswith(("lock_time", "peak_")) and n not in first]
        key = ([n for n in first if n in varying] + rest)[:6]
    key = [k for k in key if k in varying]
    for p in params:
        if len(set(_numeric(rows, p))) < 2 or not key:
            continue
        fig, axes = plt.subplots(1, len(key), figsize=(4 * len(key), 3.5), squeeze=False)
        for ax, name in zip(axes[0], key):
            pairs = [
                (float(r[p]), float(r[name]))
                for r in rows
                if isinstance(r.get(p), (int, float)) and isinstance(r.get(name), (int, float)) and math.isfinite(r[name])
            ]
            ax.scatter([a for a, _ in pairs], [b for _, b in pairs], s=12)
            ax.set_xlabel(p[len("param_"):])
            ax.set_ylabel(name)
        fig.tight_layout()
        path = out / f"scatter_{p[len('param_'):]}.{fmt}"
        fig.savefig(path)
        plt.close(fig)
        written.append(path)
    return written


def run(
    variants: Sequence[Params],
    model: Any,
    *,
    figures: Optional[Callable[..., Mapping[str, Any]]] = None,
    directory: Union[str, os.PathLike] = "study",
    address: Optional[str] = None,
    client: Any = None,
    n_workers: int = 2,
    threads_per_worker: int = 1,
    resume: bool = True,
    elements: Optional[List[str]] = None,
    plots: bool = True,
    plot_format: str = "png",
    on_row: Optional[Callable[[Row], None]] = None,
) -> Study:
    """Runs the ``variants`` of ``model`` on a Dask cluster (see the module
    documentation) and returns the ``Study``.

    - ``address``: the scheduler of a running cluster
      (``"tcp://host:8786"``); otherwise ``client``, an existing
      ``dask.distributed.Client``; otherwise a ``LocalCluster`` of
      ``n_workers`` processes of ``threads_per_worker`` threads, started
      and closed here;
    - ``resume``: take the rows of the variants already in the journal of
      ``directory`` (same index, same parameters) instead of running them
      again; ``False`` starts a new journal;
    - ``elements``: the kinds of element whose results the runs keep (all
      by default; the default figures need ``latch``, ``stop``,
      ``contact`` and ``hinge_law``);
    - ``on_row``: called in this process with each row as it is journaled.
    """
    from dask.distributed import Client, LocalCluster, as_completed

    started = time.perf_counter()
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    journal = directory / JOURNAL
    if not resume and journal.exists():
        journal.unlink()
    done = read_journal(directory) if resume else {}
    rows: Dict[int, Row] = {}
    for i, params in enumerate(variants):
        if i in done and _same_params(done[i], params):
            rows[i] = done[i]
    resumed = sorted(rows)
    pending = [i for i in range(len(variants)) if i not in rows]
    own_cluster = None
    if pending:
        if client is None:
            if address is not None:
                client = Client(address)
            else:
                own_cluster = LocalCluster(
                    n_workers=n_workers,
                    threads_per_worker=threads_per_worker,
                    processes=True,
                    dashboard_address=None,
                )
                client = Client(own_cluster)
        try:
            futures = [
                client.submit(run_variant, i, dict(variants[i]), model, figures, elements, pure=False)
                for i in pending
            ]
            try:
                for future in as_completed(futures):
                    row = future.result()
                    _append(journal, row)
                    rows[row["index"]] = row
                    if on_row is not None:
                        on_row(row)
            except BaseException:
                # an interruption: what finished is in the journal
                client.cancel(futures)
                raise
        finally:
            if own_cluster is not None:
                client.close()
                own_cluster.close()
    ordered = [rows[i] for i in range(len(variants))]
    table = write_table(ordered, directory)
    written = plot(ordered, directory, plot_format) if plots else []
    return Study(
        rows=ordered,
        table=table,
        plots=written,
        executed=pending,
        resumed=resumed,
        wall_time=time.perf_counter() - started,
    )


def run_serial(
    variants: Sequence[Params],
    model: Any,
    *,
    figures: Optional[Callable[..., Mapping[str, Any]]] = None,
    elements: Optional[List[str]] = None,
) -> List[Row]:
    """The rows of the variants run one by one in this process (the
    reference of a study's figures, and of its throughput)."""
    return [run_variant(i, dict(p), model, figures, elements) for i, p in enumerate(variants)]
