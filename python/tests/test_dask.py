"""python/examples/dask_shards.py: a run's shards on a Dask cluster of two
worker processes, merged, is the single run bit for bit; two runs on one
scheduler at once each get their own result.

The cluster is a ``LocalCluster`` of two worker processes, or the scheduler
at ``$GEOSENS_DASK_SCHEDULER`` (``tcp://127.0.0.1:8786``: .ci/cluster starts
one with ``dask scheduler`` and ``dask worker`` processes)."""

from __future__ import annotations

import contextlib
import copy
import importlib.util
import os

import pytest
from conftest import REPO, SCENES, assert_same, image_bytes

import geosens

distributed = pytest.importorskip("dask.distributed")


def example():
    path = REPO / "python" / "examples" / "dask_shards.py"
    spec = importlib.util.spec_from_file_location("dask_shards", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@contextlib.contextmanager
def scheduler():
    """The address of the scheduler at $GEOSENS_DASK_SCHEDULER, else of a
    local cluster of two single-threaded worker processes."""
    address = os.environ.get("GEOSENS_DASK_SCHEDULER")
    if address:
        yield address
        return
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, dashboard_address=None
    ) as cluster:
        yield cluster.scheduler_address


def client(address):
    return distributed.Client(address, timeout=60)


def test_shards_on_a_cluster_are_the_single_run():
    ex = example()
    scene = ex.load_scene(str(SCENES / "occluder.toml"))
    paths, seed = 1_500_000, 12
    with scheduler() as address, client(address) as c:
        with distributed.get_task_stream(c) as stream:
            merged = ex.flat_on_dask(
                c, scene, "expectation", shards=4, paths=paths, seed=seed, threads=1
            )
        workers = {t["worker"] for t in stream.data}
    single = geosens.flat(SCENES / "occluder.toml", "expectation", paths=paths, seed=seed)
    assert_same(merged, single)
    assert len(stream.data) == 4 and len(workers) == 2, workers


def test_two_runs_at_once_on_one_scheduler_get_their_own_results():
    """Two clients, the same seed and shard count, scenes differing by an
    occluder moved by 0.2: each merge is its own scene's single run (shards
    keyed by seed and index alone made the second client get the first's
    states)."""
    ex = example()
    near = ex.load_scene(str(SCENES / "occluder.toml"))
    moved = copy.deepcopy(near)
    occluder = next(s for s in moved["shapes"] if s["name"] == "occluder")
    occluder["vertices"] = [[x + 0.2, y] for x, y in occluder["vertices"]]
    run = dict(shards=3, paths=400_000, seed=5, threads=1)
    with scheduler() as address, client(address) as a, client(address) as b:
        # Both runs' tasks are on the scheduler before either is gathered.
        fa = ex.submit_shards(a, "flat", near, "expectation", **run)
        fb = ex.submit_shards(b, "flat", moved, "expectation", **run)
        ra, rb = geosens.merge(a.gather(fa)), geosens.merge(b.gather(fb))
    for scene, got in [(near, ra), (moved, rb)]:
        single = geosens.flat(scene, "expectation", paths=400_000, seed=5)
        assert_same(got, single)
    assert ra["intensity"]["mean"] != rb["intensity"]["mean"]



def test_a_rendering_on_a_cluster_is_the_single_rendering():
    """A line camera (one row of 40 pixels) over five shards: every shard
    holds pixels, and the merged images are the single rendering's bytes."""
    ex = example()
    scene = ex.load_scene(str(SCENES / "camera_line.toml"))
    with scheduler() as address, client(address) as c:
        states = c.gather(
            ex.submit_shards(c, "render", scene, "rendering", shards=5, spp=32, seed=4, threads=1)
        )
    assert all(s["paths"] > 0 for s in states), [s["paths"] for s in states]
    merged = geosens.merge(states)
    single = geosens.render(scene, "rendering", spp=32, seed=4)
    assert_same(merged, single)
    assert image_bytes(merged) == image_bytes(single)
