"""Shards: ``shard=(i, n)`` returns a shard's exact state, and
``geosens.merge`` of all ``n`` states is the single run bit for bit, through
Python (dicts, JSON text) as through the command line's state files."""

from __future__ import annotations

import json
import random

import pytest
from conftest import SCENES, assert_same, image_bytes, without_seconds

import geosens

OCC = str(SCENES / "occluder.toml")
LINE = str(SCENES / "camera_line.toml")
PATHS = 1_200_000  # 19 blocks of 65536 paths: the shards are uneven


def flat_shards(n, **kw):
    return [geosens.flat(OCC, "expectation", paths=PATHS, seed=6, shard=(i, n), **kw)
            for i in range(1, n + 1)]


@pytest.fixture(scope="module")
def four():
    return flat_shards(4)


def test_four_shards_are_one_run(four):
    single = geosens.flat(OCC, "expectation", paths=PATHS, seed=6)
    states = list(four)
    random.Random(1).shuffle(states)
    merged = geosens.merge(states)
    assert_same(merged, single)
    # The same through JSON text.
    assert_same(geosens.merge([json.dumps(s) for s in four]), single)


def test_states_are_the_command_lines(cli, tmp_path, four):
    """A Python state is the CLI's state file but for its time; the CLI's
    files merge in Python, and both merge as the CLI does."""
    files = []
    for i in range(1, 5):
        f = tmp_path / f"s{i}.json"
        cli.run("flat", "--scene", OCC, "--method", "expectation", "--paths", PATHS,
                "--seed", 6, "--shard", f"{i}/4", "--state", f)
        files.append(f)
        assert without_seconds(json.loads(f.read_text())) == without_seconds(four[i - 1])
    ref = cli.json("merge", *files)
    assert_same(geosens.merge(files), ref)
    assert_same(geosens.merge([str(f) for f in files[:2]] + four[2:]), ref)


def test_rod_shards():
    args = ("transport", 2.1, 3.0, 2.0, 1.0, -1.0)
    single = geosens.rod(*args, paths=300_000, seed=4)
    states = [geosens.rod(*args, paths=300_000, seed=4, shard=(i, 3)) for i in (1, 2, 3)]
    assert_same(geosens.merge(states), single)


def test_render_shards(cli, tmp_path):
    single = geosens.render(LINE, "rendering", spp=64, seed=3)
    states = [geosens.render(LINE, "rendering", spp=64, seed=3, shard=(i, 3)) for i in (3, 1, 2)]
    merged = geosens.merge(states)
    assert_same(merged, single)
    assert image_bytes(merged) == image_bytes(single)
    assert merged["images"]["I"]["mean"].shape == (1, 40)


def test_missing_and_duplicated_shards(cli, tmp_path, four):
    with pytest.raises(ValueError) as e:
        geosens.merge(four[:2] + four[3:])
    assert str(e.value) == "cannot merge: shard 3/4 missing: a run of 4 shards merges only whole"
    with pytest.raises(ValueError) as e:
        geosens.merge([four[0], four[1], four[1], four[3]])
    assert str(e.value) == "cannot merge: shard 2/4 given twice: states[1] and states[2]"
    # State files: the CLI's messages, word for word.
    files = []
    for i, s in enumerate(four, 1):
        f = tmp_path / f"s{i}.json"
        f.write_text(json.dumps(s))
        files.append(str(f))
    for subset in (files[:3], [files[0], files[1], files[1], files[3]]):
        with pytest.raises(ValueError) as e:
            geosens.merge(subset)
        assert str(e.value) == cli.error("merge", *subset)


def test_other_runs_do_not_merge(four):
    other = geosens.flat(OCC, "expectation", paths=PATHS, seed=7, shard=(3, 4))
    with pytest.raises(ValueError, match="not of one run: seed 7 against 6"):
        geosens.merge(four[:2] + [other] + four[3:])
    with pytest.raises(ValueError, match="nothing to merge"):
        geosens.merge([])


def test_shard_errors(cli, tmp_path):
    with pytest.raises(ValueError) as e:
        geosens.rod("exact", 0.07, 0.1, 2, 1, 1, shard=(1, 2))
    assert str(e.value) == cli.error(
        "rod", "--method", "exact", "--ks", 0.07, "--ke", 0.1, "--length", 2, "--x", 1,
        "--omega", 1, "--shard", "1/2", "--state", tmp_path / "s.json")
    with pytest.raises(ValueError, match=r"shard 0/4: expected I/N with 1 ≤ I ≤ N"):
        geosens.flat(OCC, "expectation", shard=(0, 4))
    with pytest.raises(ValueError, match=r"shard 5/4: expected I/N"):
        geosens.render(LINE, "expectation", shard=(5, 4))


def test_render_state_files_merge_as_the_command_line(cli, tmp_path):
    """The CLI's rendering states merged in Python: its JSON line and, bit for
    bit, the .npy images `geosens merge --out` writes."""
    import numpy as np

    files = []
    for i in (1, 2):
        f = tmp_path / f"r{i}.json"
        cli.run("render", "--scene", LINE, "--method", "expectation", "--spp", 32,
                "--seed", 9, "--shard", f"{i}/2", "--state", f)
        files.append(f)
    out = tmp_path / "merged"
    ref = geosens.from_json(cli.run("merge", *files, "--out", out).stdout)
    py = geosens.merge(files)
    assert_same(py, ref)
    single = geosens.render(LINE, "expectation", spp=32, seed=9)
    assert image_bytes(py) == image_bytes(single)
    for key, img in py["images"].items():
        stem = "I" if key == "I" else f"d_{key}"
        assert img["mean"].tobytes() == np.load(out / f"{stem}.npy").tobytes()
        assert img["stderr"].tobytes() == np.load(out / f"{stem}_stderr.npy").tobytes()
