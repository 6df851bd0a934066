"""The variants of the ERA cell's study (python/bench/study_era.py), in a
module of their own so that the workers import them by name."""

from unfold import study

import era_cell


def era_variant(**params):
    cell = era_cell.build(**params)
    return cell.build(), cell


def era_figures(results, cell):
    return era_cell.figures(cell, results)


def variants(n, seed=1):
    return [
        dict(end_time=1.2, **p)
        for p in study.monte_carlo(n, seed=seed, deployment_moment=(0.18, 0.22), rayleigh_beta=(0.0, 2e-5))
    ]
