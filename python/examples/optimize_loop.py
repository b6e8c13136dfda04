"""What a notebook's own optimisation loop costs beyond its sampling.

    python python/examples/optimize_loop.py [--iterations N] [--threads T]
        [--paths 1024,4096,16384,65536]

The problem: flatland's occluder (the lamp y = 2, x ∈ [-1, 1], radiance 1;
an absorbing segment at y = 1 from -0.6 to 0.2, moved by ``occ_tx``), four
irradiance sensors at y = 0 whose targets are the closed form at
occ_tx = 0.15, least squares. Two loops at each path count (paths per
measurement and iteration):

- by hand, as a user would write it: each iteration builds the scene dict
  at the current ``occ_tx`` (the occluder's vertices moved) with one
  measurement's sensor, calls ``geosens.flat(scene, "expectation")`` per
  measurement, forms the loss Σ (I − T)² and its gradient Σ 2 (I − T) ∂I
  (the naive product: biased by the covariance of I and ∂I, which share
  paths; the library's batched
  products are not) and takes an Adam step in numpy;
- ``geosens.optimize`` on the same problem (8 batches, the defaults).

For each it prints the wall time per iteration (``geosens.optimize``'s: the
time between two records reaching its ``progress``), the sampling time in
it (the by-hand loop: the sum of the calls' ``"seconds"``;
``geosens.optimize``: the records' ``"sampling_seconds"``), medians over the
iterations, and the rest, the overhead (Python,
JSON, the scene built and checked again, threads started), absolute and
relative to the sampling.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import geosens

TRUE_TX = 0.15
POINTS = [-0.5, -0.1, 0.3, 0.7]


def irradiance(x0: float, tx: float) -> float:
    """Closed form at (x0, 0), normal +y: Σ (sin φ₂ − sin φ₁) over the
    lamp's visible angular intervals."""

    def s(x: float, y: float) -> float:
        return (x - x0) / math.hypot(x - x0, y)

    lamp = (s(-1.0, 2.0), s(1.0, 2.0))
    occ = (s(-0.6 + tx, 1.0), s(0.2 + tx, 1.0))
    return lamp[1] - lamp[0] - max(0.0, min(lamp[1], occ[1]) - max(lamp[0], occ[0]))


TARGETS = [irradiance(x, TRUE_TX) for x in POINTS]


def sensor(x: float) -> dict:
    return {"kind": "irradiance", "point": [x, 0.0], "normal": [0.0, 1.0]}


def scene_at(tx: float, x: float) -> dict:
    """The scene a user rebuilds: the occluder where ``tx`` puts it, the
    sensor at (x, 0), ``occ_tx`` a parameter (its derivative) at 0."""
    return {
        "shapes": [
            {"name": "lamp", "vertices": [[-1.0, 2.0], [1.0, 2.0]],
             "surface": {"kind": "emitter", "radiance": 1.0}},
            {"name": "occluder", "vertices": [[-0.6 + tx, 1.0], [0.2 + tx, 1.0]],
             "surface": {"kind": "absorber"}},
        ],
        "parameters": [
            {"name": "occ_tx", "shape": "occluder", "motion": {"kind": "translate_x"}},
        ],
        "sensor": sensor(x),
    }


def problem() -> dict:
    scene = scene_at(0.0, 0.0)
    del scene["sensor"]
    scene["parameters"][0]["bounds"] = [-0.5, 0.5]
    scene["measurements"] = [{**sensor(x), "target": t} for x, t in zip(POINTS, TARGETS)]
    scene["objective"] = {"kind": "least_squares"}
    return scene


def by_hand(iterations: int, paths: int, threads: int, step: float = 0.02):
    """The user's loop: (wall, sampling) seconds per iteration, final tx."""
    tx, m, v = 0.0, 0.0, 0.0
    b1, b2, eps = 0.9, 0.999, 1e-8
    walls, sampling = [], []
    for t in range(iterations):
        start = time.perf_counter()
        loss, grad, sampled = 0.0, 0.0, 0.0
        for k, (x, target) in enumerate(zip(POINTS, TARGETS)):
            r = geosens.flat(scene_at(tx, x), "expectation", paths=paths,
                             seed=1 + t * len(POINTS) + k, threads=threads)
            i = r["intensity"]["mean"]
            di = r["sensitivity"]["occ_tx"]["mean"]
            loss += (i - target) ** 2
            grad += 2.0 * (i - target) * di
            sampled += r["seconds"]
        m = b1 * m + (1 - b1) * grad
        v = b2 * v + (1 - b2) * grad * grad
        mh, vh = m / (1 - b1 ** (t + 1)), v / (1 - b2 ** (t + 1))
        tx = float(np.clip(tx - step * mh / (math.sqrt(vh) + eps), -0.5, 0.5))
        walls.append(time.perf_counter() - start)
        sampling.append(sampled)
    return np.array(walls), np.array(sampling), tx


def library(iterations: int, paths: int, threads: int):
    """``geosens.optimize``: wall seconds per iteration as Python sees them
    (between two records reaching ``progress``), the records' sampling
    seconds, final tx."""
    stamps = []
    records = geosens.optimize(problem(), "expectation", iterations=iterations,
                               paths_per_step=paths, threads=threads,
                               progress=lambda r: stamps.append(time.perf_counter()))
    walls = np.diff(stamps)
    sampling = np.array([r["sampling_seconds"] for r in records[1:]])
    return walls, sampling, records[-1]["parameters"]["occ_tx"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--iterations", type=int, default=50)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--paths", default="1024,4096,16384,65536")
    args = ap.parse_args()
    # Warm up (the first call loads and starts what later ones reuse).
    geosens.flat(scene_at(0.0, 0.0), "expectation", paths=1000)
    print(f"{len(POINTS)} measurements, {args.iterations} iterations, "
          f"threads={args.threads or 'all'}; per iteration, ms (median):")
    print(f"{'paths':>7} {'loop':>18} {'wall':>8} {'sampling':>9} {'overhead':>9} "
          f"{'overhead/sampling':>18} {'final tx':>9}")
    for paths in [int(p) for p in args.paths.split(",")]:
        for name, loop in [("by hand (flat)", by_hand), ("geosens.optimize", library)]:
            walls, sampling, tx = loop(args.iterations, paths, args.threads)
            # Medians: the machine's other work lands in a few iterations.
            w, s = np.median(walls) * 1e3, np.median(sampling) * 1e3
            print(f"{paths:>7} {name:>18} {w:8.3f} {s:9.3f} {w - s:9.3f} "
                  f"{(w - s) / s:18.3f} {tx:9.4f}")


if __name__ == "__main__":
    main()
