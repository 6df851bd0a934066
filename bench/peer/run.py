"""Side-by-side benchmark of unfold and Exudyn on the same problems, at equal
accuracy (README.md). Run through run.sh, which prepares the virtual
environment.

For each code and each case the step h = first_step, first_step/2, … is
halved until the largest distance between the compared point (pendulum tip,
top centre of mass) and that code's reference over the output times (every
0.01 s) is below the tolerance; the wall time of that run (the least of
--repeat runs) is the figure.
"""

import argparse
import hashlib
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np
import scipy

import exudyn_side
import unfold_side
from problems import OUTPUT_PERIOD, RHO_INFINITY, HeavyTop, Pendulum, step_sequence, steps_for
from reference import heavy_top_reference

HERE = Path(__file__).resolve().parent
REFERENCE_DIR = HERE / "reference"
OUT_DIR = HERE / "out"


def log(msg=""):
    print(msg, flush=True)


def output_times(end_time):
    return np.arange(steps_for(end_time, OUTPUT_PERIOD) + 1) * OUTPUT_PERIOD


def max_distance(a, b):
    return float(np.linalg.norm(a - b, axis=1).max())


# ---------------------------------------------------------------- references


def _fingerprint(*items):
    """Identifies what a cached reference was computed from."""
    text = repr(items)
    return hashlib.sha1(text.encode()).hexdigest()[:12]


_NOT_PHYSICAL = {"name", "sizes", "tolerance", "first_step"}


def _problem_items(cls):
    """The physical parameters of a problem (not the comparison settings)."""
    return sorted(
        (k, v)
        for k, v in vars(cls).items()
        if not k.startswith("_") and k not in _NOT_PHYSICAL and not callable(v) and not isinstance(v, classmethod)
    )


def _load_csv(path, fingerprint):
    if not path.is_file():
        return None
    with open(path) as f:
        header = f.readline()
    if f"fingerprint {fingerprint}" not in header:
        return None
    data = np.loadtxt(path, delimiter=",", comments="#", skiprows=2)
    return data[:, 1:4]


def _save_csv(path, times, positions, header):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as f:
        f.write(f"# {header}\n")
        f.write("t,x,y,z\n")
        for t, p in zip(times, positions):
            f.write(f"{t:.2f},{p[0]:.12e},{p[1]:.12e},{p[2]:.12e}\n")


def top_independent_reference(recompute):
    """Centre of mass of the heavy top by DOP853 (reference.py), cached."""
    times = output_times(HeavyTop.end_time)
    fp = _fingerprint("top-independent", _problem_items(HeavyTop), scipy.__version__, 1e-13)
    path = REFERENCE_DIR / "top_independent.csv"
    pos = None if recompute else _load_csv(path, fp)
    if pos is None:
        t0 = time.perf_counter()
        pos, drift = heavy_top_reference(times)
        log(f"  heavy top reference (DOP853, rtol 1e-13): {time.perf_counter() - t0:.1f} s, energy drift {drift:.1e}")
        _save_csv(
            path,
            times,
            pos,
            f"heavy top centre of mass, DOP853 rtol = atol = 1e-13 (scipy {scipy.__version__}), "
            f"relative energy drift {drift:.1e}; fingerprint {fp}",
        )
    return times, pos


def exudyn_pendulum_reference(n, recompute):
    """Exudyn's own fine-step reference of the n-element pendulum, cached.
    It is computed at h and 2h; |x_h − x_2h|/3 estimates its own error
    (second order)."""
    h = Pendulum.reference_step
    fp = _fingerprint("exudyn-pendulum", n, h, exudyn_side.SETTINGS_ID, _problem_items(Pendulum), exudyn_side.version())
    path = REFERENCE_DIR / f"exudyn_pendulum_n{n}.csv"
    pos = None if recompute else _load_csv(path, fp)
    if pos is not None:
        return pos
    runs = []
    for step in (h, 2 * h):
        log(f"  Exudyn reference, {n} elements, h = {step:g} s ({steps_for(Pendulum.end_time, step)} steps) ...")
        run = exudyn_side.run_pendulum(n, step)
        if not run.ok:
            raise SystemExit(f"error: Exudyn's reference run of the {n}-element pendulum at h = {step:g} s failed: {run.message}")
        log(f"    {run.wall_solve:.1f} s, {run.newton_iterations} Newton iterations")
        runs.append(run)
    estimate = max_distance(runs[0].positions, runs[1].positions) / 3.0
    log(f"    estimated error of the reference: {estimate:.1e} m")
    _save_csv(
        path,
        runs[0].times,
        runs[0].positions,
        f"pendulum tip, {n} elements, Exudyn {exudyn_side.version()} generalized-alpha rho_inf = {RHO_INFINITY}, "
        f"h = {h:g} s, estimated error {estimate:.1e} m (|x_h - x_2h|/3); fingerprint {fp}",
    )
    return runs[0].positions


def exudyn_top_fine(recompute):
    """Exudyn's heavy top at a fine step, to check its model against the
    independent reference."""
    h = 1.0e-5
    fp = _fingerprint("exudyn-top", h, exudyn_side.SETTINGS_ID, _problem_items(HeavyTop), exudyn_side.version())
    path = REFERENCE_DIR / "exudyn_top_fine.csv"
    pos = None if recompute else _load_csv(path, fp)
    if pos is None:
        run = exudyn_side.run_top(h)
        if not run.ok:
            raise SystemExit(f"error: Exudyn's fine-step heavy top failed: {run.message}")
        _save_csv(
            path,
            run.times,
            run.positions,
            f"heavy top centre of mass, Exudyn {exudyn_side.version()} generalized-alpha rho_inf = {RHO_INFINITY}, "
            f"h = {h:g} s; fingerprint {fp}",
        )
        pos = run.positions
    return h, pos


# ------------------------------------------------------------- equal accuracy


def equal_accuracy(label, run_at, reference, first_step, tolerance, halvings, repeat):
    """Halve h from first_step until the error is below tolerance; time that
    run `repeat` times. Returns a dict describing the outcome."""
    tried = []
    for h in step_sequence(first_step, halvings + 1):
        run = run_at(h)
        if not run.ok:
            tried.append({"h": h, "ok": False, "message": run.message, "wall": run.wall_solve})
            log(f"    {label}: h = {h:.4e} s  failed ({run.message}) after {run.wall_solve:.2f} s")
            continue
        err = max_distance(run.positions, reference)
        tried.append({"h": h, "ok": True, "error": err, "wall": run.wall_solve})
        timing = f"{run.wall_solve:.3f} s" if label != "unfold" else f"{run.wall_total:.3f} s (analysis {run.wall_solve:.3f} s)"
        log(
            f"    {label}: h = {h:.4e} s  error {err:.2e} m  {timing}"
            f"  ({run.steps} steps, {run.newton_iterations} Newton iterations"
            + (f", {run.jacobians} Jacobians)" if run.jacobians else ")")
        )
        if err < tolerance:
            walls = [run.wall_solve]
            totals = [run.wall_total]
            # the figure: Exudyn's SolveDynamic, unfold's whole process
            figure = "wall_total" if label == "unfold" else "wall_solve"
            for _ in range(repeat - 1):
                again = run_at(h)
                if again.ok:
                    walls.append(again.wall_solve)
                    totals.append(again.wall_total)
            return {
                "ok": True,
                "h": h,
                "error": err,
                "wall": min(totals) if figure == "wall_total" else min(walls),
                "wall_solve": min(walls),
                "walls": walls,
                "wall_total": min(totals),
                "steps": run.steps,
                "newton_iterations": run.newton_iterations,
                "jacobians": run.jacobians,
                "final": run.positions[-1].tolist(),
                "energy_final": float(run.energy[-1]) if getattr(run, "energy", np.zeros(0)).size else None,
                "tried": tried,
            }
    return {"ok": False, "tried": tried}


# ------------------------------------------------------------------- report


def fmt_side(r):
    if r is None:
        return "—"
    if not r["ok"]:
        last = r["tried"][-1]["h"] if r["tried"] else float("nan")
        return f"no step down to {last:.2e} s met the tolerance"
    return f"h {r['h']:.3e}  err {r['error']:.1e}  {r['wall']:.3f} s"


def failures_where_exudyn_succeeds(case):
    """Steps at which Exudyn converged and unfold did not."""
    e, u = case["exudyn"], case["unfold"]
    if not u:
        return []
    exu_ok = {t["h"] for t in e["tried"] if t["ok"]}
    return [t["h"] for t in u["tried"] if not t["ok"] and t["h"] in exu_ok]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--problems", default="pendulum,top", help="comma-separated: pendulum, top")
    ap.add_argument("--sizes", default=",".join(str(n) for n in Pendulum.sizes), help="pendulum element counts")
    ap.add_argument("--threads", type=int, default=1, help="threads of each code (default 1)")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs at the chosen step; the least counts")
    ap.add_argument("--halvings", type=int, default=10, help="most halvings of the step")
    ap.add_argument("--recompute-references", action="store_true", help="ignore the cached references")
    ap.add_argument("--no-unfold", action="store_true", help="run Exudyn only")
    ap.add_argument(
        "--unfold-residual-tolerance",
        type=float,
        default=unfold_side.RESIDUAL_TOLERANCE,
        help=f"unfold's Newton residual tolerance (default {unfold_side.RESIDUAL_TOLERANCE:g}, as Exudyn's; 0: unfold's own default)",
    )
    ap.add_argument(
        "--unfold-angular-velocities",
        choices=("spatial", "material"),
        default=unfold_side.ANGULAR_VELOCITIES,
        help=f"the frame of the angular velocities in unfold's time scheme for the heavy top (default {unfold_side.ANGULAR_VELOCITIES}; the pendulum keeps unfold's default)",
    )
    args = ap.parse_args()

    unfold_side.RESIDUAL_TOLERANCE = args.unfold_residual_tolerance or None
    unfold_side.ANGULAR_VELOCITIES = args.unfold_angular_velocities
    problems = [p.strip() for p in args.problems.split(",") if p.strip()]
    sizes = [int(s) for s in args.sizes.split(",") if s.strip()]
    for p in problems:
        if p not in ("pendulum", "top"):
            ap.error(f"unknown problem {p!r}")

    log("Peer benchmark: unfold against Exudyn, equal accuracy, same machine")
    log(
        f"  Python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
        f"exudyn {exudyn_side.version()}; {os.cpu_count()} cores; {args.threads} thread(s) per code"
    )
    log(f"  generalized-alpha, rho_inf = {RHO_INFINITY}; outputs every {OUTPUT_PERIOD} s")
    rt = unfold_side.RESIDUAL_TOLERANCE
    log(
        f"  Newton relative tolerance: Exudyn {exudyn_side.NEWTON_RELATIVE_TOLERANCE:g}, "
        f"unfold {rt:g}" + (" (residual relative to the force flux)" if rt else " (its default)")
    )

    log(f"  load average at the start: {' '.join(f'{x:.1f}' for x in os.getloadavg())}")
    if args.no_unfold:
        unfold_ok, why = False, "not run (--no-unfold)"
        log("  unfold: not run (--no-unfold)")
    else:
        try:
            unfold_ok, why = unfold_side.availability()
        except unfold_side.ModelError as e:
            raise SystemExit(f"error: {e}")
        if unfold_ok:
            log(f"  unfold: {unfold_side.describe()}")
        else:
            log("  unfold: dynamic analysis not available")
            log(f"    ({why})")

    results = {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "exudyn": exudyn_side.version(),
        "threads": args.threads,
        "rho_infinity": RHO_INFINITY,
        "unfold_residual_tolerance": unfold_side.RESIDUAL_TOLERANCE,
        "unfold_angular_velocities": unfold_side.ANGULAR_VELOCITIES,
        "unfold_available": unfold_ok,
        "unfold_unavailable_because": why,
        "load_average_start": os.getloadavg(),
        "cases": [],
    }
    rows = []

    if "pendulum" in problems:
        P = Pendulum
        log("")
        log(f"Flexible pendulum: tip error tolerance {P.tolerance:g} m against each code's own reference of the same mesh")
        exu_refs = {}
        for n in sizes:
            exu_refs[n] = exudyn_pendulum_reference(n, args.recompute_references)
        finest = max(sizes)
        for n in sizes:
            if n != finest:
                log(f"  Exudyn reference: {n} elements differ from {finest} by {max_distance(exu_refs[n], exu_refs[finest]):.2e} m (mesh error)")
        for n in sizes:
            log(f"  {n} elements")
            case = {"problem": "pendulum", "size": n}
            case["exudyn"] = equal_accuracy(
                "Exudyn",
                lambda h, n=n: exudyn_side.run_pendulum(n, h, threads=args.threads),
                exu_refs[n],
                P.first_step,
                P.tolerance,
                args.halvings,
                args.repeat,
            )
            case["unfold"] = None
            if unfold_ok:
                uref = unfold_side.run_pendulum(n, P.reference_step, threads=args.threads, reference=True)
                if uref.ok and uref.cutbacks:
                    log(f"    unfold: reference run (h = {P.reference_step:g} s): {uref.message}")
                if not uref.ok:
                    log(f"    unfold: reference run (h = {P.reference_step:g} s) failed: {uref.message}")
                    case["unfold"] = {"ok": False, "tried": [], "message": uref.message}
                else:
                    case["references_differ"] = max_distance(uref.positions, exu_refs[n])
                    log(f"    references of the two codes differ by {case['references_differ']:.2e} m")
                    case["unfold_reference_final"] = uref.positions[-1].tolist()
                    if uref.energy.size:
                        case["unfold_reference_energy"] = float(uref.energy[-1])
                        log(
                            f"    unfold reference at t = {P.end_time:g} s: tip {uref.positions[-1].tolist()}, "
                            f"T + V = {uref.energy[-1]:.3e} J (0 at the start)"
                        )
                    case["unfold"] = equal_accuracy(
                        "unfold",
                        lambda h, n=n: unfold_side.run_pendulum(n, h, threads=args.threads),
                        uref.positions,
                        P.first_step,
                        P.tolerance,
                        args.halvings,
                        args.repeat,
                    )
            u = case["unfold"]
            if u and u.get("ok") and u.get("energy_final") is not None and "unfold_reference_energy" in case:
                log(
                    f"    unfold at the equal-accuracy step: T + V = {u['energy_final']:.3e} J at t = {P.end_time:g} s "
                    f"(reference {case['unfold_reference_energy']:.3e} J; m g L/2 = {P.rho_A * P.length * 9.81 / 2:.3f} J)"
                )
            results["cases"].append(case)
            rows.append((f"pendulum {n}", case))

    if "top" in problems:
        T = HeavyTop
        log("")
        log(f"Heavy top: centre-of-mass error tolerance {T.tolerance:g} m against the independent reference")
        times, ref = top_independent_reference(args.recompute_references)
        log(f"  reference centre of mass at t = {T.end_time:g} s: {ref[-1].tolist()}")
        h_fine, exu_fine = exudyn_top_fine(args.recompute_references)
        log(f"  Exudyn at h = {h_fine:g} s differs from it by {max_distance(exu_fine, ref):.2e} m")
        case = {"problem": "top", "size": 1, "reference_final": ref[-1].tolist()}
        case["exudyn"] = equal_accuracy(
            "Exudyn",
            lambda h: exudyn_side.run_top(h, threads=args.threads),
            ref,
            T.first_step,
            T.tolerance,
            args.halvings,
            args.repeat,
        )
        case["unfold"] = None
        if unfold_ok:
            case["unfold"] = equal_accuracy(
                "unfold",
                lambda h: unfold_side.run_top(h, threads=args.threads),
                ref,
                T.first_step,
                T.tolerance,
                args.halvings,
                args.repeat,
            )
        for side in ("exudyn", "unfold"):
            r = case[side]
            if r and r["ok"]:
                d = float(np.linalg.norm(np.array(r["final"]) - ref[-1]))
                r["final_error"] = d
                log(f"    {side}: centre of mass at t = {T.end_time:g} s {r['final']} ({d:.2e} m from the reference)")
        results["cases"].append(case)
        rows.append(("heavy top", case))

    log("")
    log("Summary (wall time at equal accuracy; Exudyn: SolveDynamic alone, unfold: the whole `unfold run` process;")
    log("         in parentheses the ratio to unfold's analysis time from its summary.json)")
    log(f"  {'case':<14} {'Exudyn':<44} {'unfold':<44} Exudyn/unfold")
    for label, case in rows:
        e, u = case["exudyn"], case["unfold"]
        if not unfold_ok:
            u_text, ratio = "unfold: dynamic analysis not available" if not args.no_unfold else "not run", "—"
        else:
            u_text = fmt_side(u)
            ratio = "—"
            if e["ok"] and u and u["ok"]:
                # unfold's own timing of the analysis alone in parentheses
                ratio = f"{e['wall'] / u['wall']:.1f} ({e['wall'] / u['wall_solve']:.1f})"
        log(f"  {label:<14} {fmt_side(e):<44} {u_text:<44} {ratio}")
        if unfold_ok:
            bad = failures_where_exudyn_succeeds(case)
            if bad:
                log(f"  {'':<14} unfold fails where Exudyn succeeds, at h = {', '.join(f'{h:.3e}' for h in bad)} s")

    pend = [(case["size"], case) for label, case in rows if case["problem"] == "pendulum"]
    if pend:
        log("")
        log("Pendulum: wall time per step and element at the equal-accuracy step (constant = cost linear in n)")
        for side in ("exudyn", "unfold"):
            cells = []
            for n, case in pend:
                r = case[side]
                if r and r["ok"]:
                    cells.append(f"{n}: {1e6 * r['wall_solve'] / (r['steps'] * n):.1f} µs")
                else:
                    cells.append(f"{n}: —")
            log(f"  {side:<8} " + "   ".join(cells))

    log(f"\n  load average at the end: {' '.join(f'{x:.1f}' for x in os.getloadavg())}")
    results["load_average_end"] = os.getloadavg()
    OUT_DIR.mkdir(exist_ok=True)
    out = OUT_DIR / "results.json"
    out.write_text(json.dumps(results, indent=1))
    log(f"\nresults in {out.relative_to(HERE.parents[1])}")


if __name__ == "__main__":
    sys.exit(main())
