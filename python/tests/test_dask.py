"""python/examples/dask_shards.py: a run's shards on a Dask cluster of two
worker processes, merged, is the single run bit for bit."""

from __future__ import annotations

import importlib.util

import pytest
from conftest import REPO, SCENES, assert_same

import geosens

distributed = pytest.importorskip("dask.distributed")


def example():
    path = REPO / "python" / "examples" / "dask_shards.py"
    spec = importlib.util.spec_from_file_location("dask_shards", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_shards_on_a_local_cluster_are_the_single_run():
    ex = example()
    scene = ex.load_scene(str(SCENES / "occluder.toml"))
    paths, seed = 1_500_000, 12
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        with distributed.get_task_stream(client) as stream:
            merged = ex.flat_on_dask(
                client, scene, "expectation", shards=4, paths=paths, seed=seed, threads=1
            )
        workers = {t["worker"] for t in stream.data}
    single = geosens.flat(SCENES / "occluder.toml", "expectation", paths=paths, seed=seed)
    assert_same(merged, single)
    assert len(stream.data) == 4 and len(workers) == 2, workers
