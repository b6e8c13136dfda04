"""One geosens run split into shards over a Dask cluster, merged bit for bit.

    python python/examples/dask_shards.py [SCHEDULER] [--scene FILE]
        [--method M] [--paths N] [--seed S] [--shards K] [--threads T]
        [--check]

``SCHEDULER`` is a ``dask.distributed`` scheduler's address (``tcp://host:8786``,
from ``dask scheduler`` and ``dask worker`` on the machines); without it the
script starts a ``LocalCluster`` on this machine. Each shard
``geosens.flat(scene, method, shard=(i, K))`` runs on a worker and returns its
exact state (a dict of integers); ``geosens.merge`` folds them in the run's
own order, so the result is the single run's whatever the number of shards,
workers or threads (``--check`` runs it here and compares). The scene travels
to the workers as a dict, so they need geosens installed but not the file.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any, Dict, Optional

import geosens

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def load_scene(path: str) -> Dict[str, Any]:
    """A scene file (TOML or JSON) as the dict the workers receive."""
    with open(path, "rb") as f:
        return json.load(f) if path.endswith(".json") else tomllib.load(f)


def flat_on_dask(
    client: Any,
    scene: Any,
    method: str,
    *,
    shards: int,
    paths: int = 1_000_000,
    seed: int = 1,
    threads: int = 0,
    fd_step: Optional[float] = None,
) -> Dict[str, Any]:
    """``geosens.flat(scene, method, paths=paths, seed=seed)``, its shards
    run on ``client``'s workers (one task each, ``threads`` threads per
    task: 0 = all the worker's cores) and merged here."""
    futures = [
        client.submit(
            geosens.flat,
            scene,
            method,
            paths=paths,
            seed=seed,
            threads=threads,
            fd_step=fd_step,
            shard=(i, shards),
            key=f"geosens-flat-{seed}-{i}-of-{shards}",
        )
        for i in range(1, shards + 1)
    ]
    return geosens.merge(client.gather(futures))


def main(argv: Optional[list] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scheduler", nargs="?", help="scheduler address (default: a LocalCluster)")
    p.add_argument("--scene", default="scenes/occluder.toml")
    p.add_argument("--method", default="expectation")
    p.add_argument("--paths", type=int, default=4_000_000)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--shards", type=int, default=8)
    p.add_argument("--threads", type=int, default=1, help="threads per shard (0: all cores)")
    p.add_argument("--check", action="store_true", help="compare with the single run here")
    args = p.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    scene = load_scene(args.scene)
    cluster = None if args.scheduler else LocalCluster(threads_per_worker=1)
    with Client(args.scheduler or cluster) as client:
        merged = flat_on_dask(
            client, scene, args.method, shards=args.shards, paths=args.paths,
            seed=args.seed, threads=args.threads,
        )
    if cluster is not None:
        cluster.close()
    print(json.dumps(merged), flush=True)
    if args.check:
        single = geosens.flat(scene, args.method, paths=args.paths, seed=args.seed)
        merged.pop("seconds"), single.pop("seconds")
        same = json.dumps(merged) == json.dumps(single)
        print("the single run, bit for bit" if same else "DIFFERS from the single run",
              file=sys.stderr)
        return 0 if same else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
