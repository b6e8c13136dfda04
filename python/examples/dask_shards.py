"""One geosens run split into shards over a Dask cluster, merged bit for bit.

    python python/examples/dask_shards.py [SCHEDULER] [--kind flat|mesh|render]
        [--scene FILE] [--method M] [--paths N | --spp N] [--seed S]
        [--shards K] [--threads T] [--out DIR] [--check]

``SCHEDULER`` is a ``dask.distributed`` scheduler's address (``tcp://host:8786``,
from ``dask scheduler`` and ``dask worker`` on the machines); without it the
script starts a ``LocalCluster`` on this machine. Each shard
(``geosens.flat(scene, method, shard=(i, K))``, or ``mesh``, or ``render``)
runs on a worker and returns its exact state (a dict of integers);
``geosens.merge`` folds them in the run's own order, so the result is the
single run's whatever the number of shards, workers or threads (``--check``
runs it here and compares). A rendering's images go to ``--out`` as ``.npy``
files named as ``geosens render`` names them. The scene travels to the workers as a dict, so they need geosens
installed but not the file (a 3D scene's OBJ files excepted: the workers
read those, relative to their working folder).
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import uuid
from pathlib import Path
from typing import Any, Dict, List, Optional

import numpy as np

import geosens

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

#: The estimation functions a run can be split over: a probe's (``paths``
#: per run) and a camera's (``spp`` paths per pixel).
KINDS = {"flat": geosens.flat, "mesh": geosens.mesh, "render": geosens.render}


def load_scene(path: str) -> Dict[str, Any]:
    """A scene file (TOML or JSON) as the dict the workers receive."""
    with open(path, "rb") as f:
        return json.load(f) if path.endswith(".json") else tomllib.load(f)


def submit_shards(
    client: Any,
    kind: str,
    scene: Any,
    method: str,
    *,
    shards: int,
    paths: int = 1_000_000,
    spp: int = 64,
    seed: int = 1,
    threads: int = 0,
    fd_step: Optional[float] = None,
) -> List[Any]:
    """Submits the ``shards`` shards of one run of ``geosens.<kind>`` to
    ``client``'s scheduler (one task each, ``threads`` threads per task: 0
    = all the worker's cores) and returns their futures, in shard order.
    ``paths`` is the run's (flat, mesh), ``spp`` a rendering's per pixel.
    """
    if kind not in KINDS:
        raise ValueError(f"kind {kind!r}: expected one of {', '.join(KINDS)}")
    size = {"spp": spp} if kind == "render" else {"paths": paths}
    # A task's key is what the scheduler knows it by: two tasks submitted
    # under one key are one task, and the second client gets the first's
    # result. Shard i of n of another scene, method or path count is another
    # task, and so is the same call after a scene's file (or its OBJ) was
    # edited, which no key made of the arguments would see: each run gets a
    # key of its own. (The state's hash of the scene, which `merge` checks,
    # is known only once a shard has run.)
    run = uuid.uuid4().hex[:16]
    return [
        client.submit(
            KINDS[kind],
            scene,
            method,
            seed=seed,
            threads=threads,
            fd_step=fd_step,
            shard=(i, shards),
            key=f"geosens-{kind}-{run}-{i}-of-{shards}",
            **size,
        )
        for i in range(1, shards + 1)
    ]


def run_on_dask(client: Any, kind: str, scene: Any, method: str, **run: Any) -> Dict[str, Any]:
    """``geosens.<kind>(scene, method, ...)``, its shards run on ``client``'s
    workers (:func:`submit_shards`, which takes ``run``) and merged here."""
    return geosens.merge(client.gather(submit_shards(client, kind, scene, method, **run)))


def flat_on_dask(client: Any, scene: Any, method: str, **run: Any) -> Dict[str, Any]:
    """``geosens.flat(scene, method, ...)`` on ``client``'s workers
    (:func:`run_on_dask`)."""
    return run_on_dask(client, "flat", scene, method, **run)


def same(a: Dict[str, Any], b: Dict[str, Any]) -> bool:
    """Whether two results are the same bit for bit but for ``seconds``
    (as JSON text, whose floats read back to their bits; images by their
    bytes)."""
    strip = lambda d: {k: v for k, v in d.items() if k not in ("seconds", "images")}
    if json.dumps(strip(a)) != json.dumps(strip(b)):
        return False
    ia, ib = a.get("images", {}), b.get("images", {})
    return ia.keys() == ib.keys() and all(
        ia[q][k].tobytes() == ib[q][k].tobytes() for q in ia for k in ("mean", "stderr")
    )


def npy_stem(key: str) -> str:
    """The command line's file name of an image (``geosens render --out``):
    ``I``, ``d_<param>``, ``grad_<axis>``, other characters than letters,
    digits, ``-`` and ``_`` as ``_``."""
    if key == "I":
        return key
    stem = f"grad_{key[4:]}" if key.startswith("∂I/∂") else f"d_{key}"
    return re.sub(r"[^A-Za-z0-9_-]", "_", stem)


def main(argv: Optional[list] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scheduler", nargs="?", help="scheduler address (default: a LocalCluster)")
    p.add_argument("--kind", choices=list(KINDS), default="flat")
    p.add_argument("--scene", default="scenes/occluder.toml")
    p.add_argument("--method", default="expectation")
    p.add_argument("--paths", type=int, default=4_000_000, help="paths of the run (flat, mesh)")
    p.add_argument("--spp", type=int, default=64, help="paths per pixel (render)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--shards", type=int, default=8)
    p.add_argument("--threads", type=int, default=1, help="threads per shard (0: all cores)")
    p.add_argument("--out", help="folder a rendering's images go to (.npy)")
    p.add_argument("--check", action="store_true", help="compare with the single run here")
    args = p.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    scene = load_scene(args.scene)
    size = {"spp": args.spp} if args.kind == "render" else {"paths": args.paths}
    cluster = None if args.scheduler else LocalCluster(threads_per_worker=1)
    with Client(args.scheduler or cluster) as client:
        merged = run_on_dask(
            client, args.kind, scene, args.method, shards=args.shards, seed=args.seed,
            threads=args.threads, **size,
        )
    if cluster is not None:
        cluster.close()
    images = merged.pop("images", {})
    print(json.dumps(merged), flush=True)
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        for q, image in images.items():
            for k, a in image.items():
                np.save(out / f"{npy_stem(q)}{'_stderr' if k == 'stderr' else ''}.npy", a)
    if args.check:
        single = KINDS[args.kind](scene, args.method, seed=args.seed, **size)
        ok = same(dict(merged, images=images), single)
        print("the single run, bit for bit" if ok else "DIFFERS from the single run",
              file=sys.stderr)
        return 0 if ok else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
