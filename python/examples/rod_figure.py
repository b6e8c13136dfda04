"""The sensitivity along the rod from Python: the book's figure (the paper's
Fig. 6) redone with ``geosens.rod`` and matplotlib.

    python python/examples/rod_figure.py OUT.png [--paths N] [--seed S]

Rows: the four methods that estimate s = ∂I/∂length (differentiable
rendering, expectation differentiation, the transport model, central finite
differences, whose probe stays inside the rod: x < 2); columns: the paper's thin rod (κs = 0.07, κe = 0.1) and thick
rod (κs = 2.1, κe = 3), length 2. Each panel: the estimates at 21 positions,
both directions, with ±σ error bars, over the exact curves
(``geosens.rod_exact``). Needs matplotlib (``pip install matplotlib``); a few
seconds on two cores with the default 100000 paths per point.
"""

from __future__ import annotations

import argparse
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import geosens  # noqa: E402

RODS = {"thin": (0.07, 0.1), "thick": (2.1, 3.0)}
LENGTH = 2.0
METHODS = ["rendering", "expectation", "transport", "fd"]
DIRECTIONS = {+1.0: ("ω = +1", "tab:blue"), -1.0: ("ω = −1", "tab:orange")}


def along(method, ks, ke, omega, xs, **run):
    """The sensitivity at each x: (mean, σ) arrays; one seed per point."""
    seed = run.pop("seed", 1)
    rs = [
        geosens.rod(method, ks, ke, LENGTH, x, omega, seed=seed + i, **run)
        for i, x in enumerate(xs)
    ]
    return geosens.arrays(rs)["sensitivity"]["length"]


def figure(paths: int = 100_000, seed: int = 1):
    xs = np.linspace(0.0, LENGTH, 21)
    fine = np.linspace(0.0, LENGTH, 201)
    fig, axes = plt.subplots(
        len(METHODS), len(RODS), figsize=(10, 12), sharex=True, squeeze=False
    )
    for col, (name, (ks, ke)) in enumerate(RODS.items()):
        for row, method in enumerate(METHODS):
            ax = axes[row][col]
            for k, (omega, (label, color)) in enumerate(DIRECTIONS.items()):
                exact = geosens.rod_exact(ks, ke, LENGTH, fine, omega)["sensitivity"]["length"]
                ax.plot(fine, exact, color=color, lw=1, label=f"exact, {label}")
                # fd shortens the rod: its probe must stay inside (x < length).
                at = xs[xs < LENGTH] if method == "fd" else xs
                mean, sigma = along(
                    method, ks, ke, omega, at, paths=paths,
                    seed=seed + 1000 * (4 * row + 2 * col + k),
                )
                ax.errorbar(
                    at, mean, yerr=sigma, fmt="o", ms=3, capsize=2, color=color,
                    label=f"{method}, {label}",
                )
            ax.set_title(f"{name} rod (κs = {ks}, κe = {ke}): s by {method}", fontsize=9)
            ax.set_ylabel("∂I/∂length")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="best")
    for ax in axes[-1]:
        ax.set_xlabel("x")
    fig.suptitle(f"Sensitivity to the length along the rod, ±σ, {paths} paths per point")
    fig.tight_layout()
    return fig


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", help="the PNG to write")
    p.add_argument("--paths", type=int, default=100_000, help="paths per point")
    p.add_argument("--seed", type=int, default=1)
    args = p.parse_args(argv)
    figure(args.paths, args.seed).savefig(args.out, dpi=120)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
