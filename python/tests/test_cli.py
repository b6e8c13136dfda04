"""Every function returns the command line's ``--json`` line bit for bit
(but for ``"seconds"``) for the same inputs and seed; a rendering's images are
its ``.npy`` files."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import SCENES, assert_same, image_bytes

import geosens

THIN = (0.07, 0.1, 2.0)
THICK = (2.1, 3.0, 2.0)


@pytest.mark.parametrize(
    "method, rod, x, omega, paths, seed",
    [
        ("expectation", THIN, 1.0, 1.0, 200_000, 3),
        ("transport", THICK, 1.9, -1.0, 100_000, 7),
        ("fd", THIN, 0.0, -1.0, 100_000, 11),
        ("exact", THICK, 1.0, 1.0, 1_000_000, 1),
    ],
)
def test_rod(cli, method, rod, x, omega, paths, seed):
    ks, ke, length = rod
    py = geosens.rod(method, ks, ke, length, x, omega, paths=paths, seed=seed)
    ref = cli.json(
        "rod", "--method", method, "--ks", ks, "--ke", ke, "--length", length,
        "--x", x, "--omega", omega, "--paths", paths, "--seed", seed,
    )
    assert_same(py, ref)
    assert py["method"] == method
    assert py["paths"] == (0 if method == "exact" else paths)


def test_rod_fd_step_and_threads(cli):
    py = geosens.rod("fd", *THIN, 1.0, 1.0, paths=100_000, seed=2, fd_step=0.01, threads=1)
    ref = cli.json(
        "rod", "--method", "fd", "--ks", THIN[0], "--ke", THIN[1], "--length", THIN[2],
        "--x", 1, "--omega", 1, "--paths", 100_000, "--seed", 2, "--fd-step", 0.01,
    )
    assert_same(py, ref)


@pytest.mark.parametrize(
    "scene, method",
    [("occluder.toml", "expectation"), ("fog.toml", "transport"), ("occluder.toml", "rendering")],
)
def test_flat(cli, scene, method):
    path = SCENES / scene
    py = geosens.flat(path, method, paths=200_000, seed=5)
    ref = cli.json("flat", "--scene", path, "--method", method, "--paths", 200_000, "--seed", 5)
    assert_same(py, ref)
    assert set(py["sensitivity"]) and py["paths"] == 200_000


@pytest.mark.parametrize("method", ["expectation", "transport"])
def test_mesh(cli, method):
    path = SCENES / "mesh" / "triangle.toml"
    py = geosens.mesh(str(path), method, paths=100_000, seed=9)
    ref = cli.json("mesh", "--scene", path, "--method", method, "--paths", 100_000, "--seed", 9)
    assert_same(py, ref)
    if method == "transport":
        assert set(py["gradient"]) == {"x", "y", "z"}


@pytest.mark.parametrize(
    "scene, method, spp",
    [("camera_line.toml", "rendering", 256), ("mesh/camera_shadow.toml", "expectation", 4)],
)
def test_render(cli, tmp_path, scene, method, spp):
    path = SCENES / scene
    py = geosens.render(path, method, spp=spp, seed=4)
    p = cli.run("render", "--scene", path, "--method", method, "--spp", spp, "--seed", 4,
                "--out", tmp_path)
    ref = geosens.from_json(p.stdout)
    assert_same(py, ref)
    assert list(py["images"]) == ["I", *ref["sensitivity"]]
    for key, img in py["images"].items():
        stem = "I" if key == "I" else f"d_{key}"
        for field, suffix in [("mean", ""), ("stderr", "_stderr")]:
            want = np.load(tmp_path / f"{stem}{suffix}.npy")
            got = img[field]
            assert got.dtype == np.float64 and got.shape == (py["height"], py["width"])
            assert got.shape == want.shape
            assert got.tobytes() == want.astype(np.float64).tobytes()
    assert image_bytes(py)
