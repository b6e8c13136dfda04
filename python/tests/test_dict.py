"""A scene given as a dict of the file's schema is the scene of the file."""

from __future__ import annotations

import copy
import json
import sys

import pytest
from conftest import SCENES, assert_same, image_bytes

import geosens

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    tomllib = pytest.importorskip("tomli")


def load(name: str) -> dict:
    with open(SCENES / name, "rb") as f:
        return tomllib.load(f)


def test_flat_dict_is_its_file():
    scene = load("occluder.toml")
    a = geosens.flat(scene, "expectation", paths=200_000, seed=8)
    b = geosens.flat(SCENES / "occluder.toml", "expectation", paths=200_000, seed=8)
    assert_same(a, b)


def test_mesh_dict_is_its_file():
    scene = load("mesh/triangle.toml")
    a = geosens.mesh(scene, "rendering", paths=100_000, seed=8)
    b = geosens.mesh(SCENES / "mesh" / "triangle.toml", "rendering", paths=100_000, seed=8)
    assert_same(a, b)


def test_render_dict_is_its_file():
    scene = load("camera_line.toml")
    a = geosens.render(scene, "expectation", spp=32, seed=2)
    b = geosens.render(SCENES / "camera_line.toml", "expectation", spp=32, seed=2)
    assert_same(a, b)
    assert image_bytes(a) == image_bytes(b)


def test_sweep_edits_the_dict(cli, tmp_path):
    """A sweep moves the occluder by editing the dict; each point is the
    command line's run on the same scene written to a file (JSON)."""
    base = load("occluder.toml")
    for dy in (0.0, 0.25):
        scene = copy.deepcopy(base)
        occ = next(s for s in scene["shapes"] if s["name"] == "occluder")
        occ["vertices"] = [[x, y + dy] for x, y in occ["vertices"]]
        py = geosens.flat(scene, "expectation", paths=100_000, seed=3)
        path = tmp_path / f"sweep{dy}.json"
        path.write_text(json.dumps(scene))
        ref = cli.json("flat", "--scene", path, "--method", "expectation",
                       "--paths", 100_000, "--seed", 3)
        assert_same(py, ref)


def test_numpy_values_are_plain_values():
    """A sweep built with numpy (arrays of vertices, numpy scalars) is the
    same scene as its lists and floats."""
    np = pytest.importorskip("numpy")
    base = load("occluder.toml")
    scene = copy.deepcopy(base)
    occ = next(s for s in scene["shapes"] if s["name"] == "occluder")
    occ["vertices"] = np.array(occ["vertices"]) + np.array([0.0, np.float64(0.1)])
    scene["sensor"]["point"] = [np.float32(0.0), np.int64(0)]
    plain = copy.deepcopy(base)
    occ = next(s for s in plain["shapes"] if s["name"] == "occluder")
    occ["vertices"] = [[x, y + 0.1] for x, y in occ["vertices"]]
    assert_same(
        geosens.flat(scene, "rendering", paths=50_000, seed=4),
        geosens.flat(plain, "rendering", paths=50_000, seed=4),
    )


def test_a_dict_that_is_no_scene_value_is_a_value_error():
    scene = load("occluder.toml")
    scene["shapes"][1]["vertices"][0][0] = float("nan")
    with pytest.raises(ValueError, match="not finite"):
        geosens.flat(scene, "rendering", paths=1000)
    scene = load("occluder.toml")
    scene["sensor"]["point"] = {1, 2}
    with pytest.raises(ValueError, match="invalid scene: set is not a scene value"):
        geosens.flat(scene, "rendering", paths=1000)
