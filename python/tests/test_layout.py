"""One layout for every result: the rod's, flatland's, 3D's and a
rendering's results name the same things the same way, the command line's
lines read into it (``geosens.from_json``), and ``geosens.arrays`` turns a
sweep of them into arrays."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from conftest import SCENES

import geosens

KEYS = ["method", "intensity", "sensitivity", "gradient", "paths", "seconds"]
QUANTITY = {"mean", "stderr", "nonzero", "reliable"}


def test_rod_flat_and_mesh_share_one_layout():
    rod = geosens.rod("transport", 2.1, 3.0, 2.0, 1.0, -1.0, paths=10_000)
    flat = geosens.flat(SCENES / "occluder.toml", "transport", paths=10_000)
    mesh = geosens.mesh(SCENES / "mesh" / "triangle.toml", "transport", paths=10_000)
    for r, params, axes in [(rod, ["length"], ["x"]),
                            (flat, ["occluder_tx", "occluder_ty", "occluder_rotate",
                                    "occluder_scale"], ["x", "y"]),
                            (mesh, ["tri_tx", "tri_ty", "tri_tz", "tri_rot", "tri_scale"],
                             ["x", "y", "z"])]:
        assert list(r) == KEYS
        assert set(r["intensity"]) == QUANTITY
        assert list(r["sensitivity"]) == params
        assert list(r["gradient"]) == axes
        for q in [*r["sensitivity"].values(), *r["gradient"].values()]:
            assert set(q) == QUANTITY


def test_what_a_method_does_not_estimate_looks_the_same_everywhere():
    rod = geosens.rod("intensity", 2.1, 3.0, 2.0, 1.0, -1.0, paths=1000)
    flat = geosens.flat(SCENES / "occluder.toml", "intensity", paths=1000)
    assert rod["sensitivity"] == flat["sensitivity"] == {}
    assert rod["gradient"] is None and flat["gradient"] is None
    rod = geosens.rod("expectation", 2.1, 3.0, 2.0, 1.0, -1.0, paths=1000)
    assert list(rod["sensitivity"]) == ["length"] and rod["gradient"] is None


def test_a_rendering_names_its_intensity_as_the_others_do():
    img = geosens.render(SCENES / "camera_line.toml", "expectation", spp=4)
    assert "intensity" in img and set(img["intensity"]) == QUANTITY
    assert list(img["sensitivity"]) == ["tx", "rot"]


def test_from_json_reads_the_command_lines_lines(cli):
    line = cli.run("rod", "--method", "transport", "--ks", 2.1, "--ke", 3, "--length", 2,
                   "--x", 1, "--omega", -1, "--paths", 10_000, "--json").stdout
    r = geosens.from_json(line)
    assert list(r) == KEYS
    assert r == geosens.from_json(r) == geosens.from_json(line.encode())
    with pytest.raises(ValueError, match="not list"):
        geosens.from_json("[1, 2]")


def test_results_pickle_as_they_are():
    """A result crosses processes (Dask) with its class, old keys and all."""
    r = geosens.rod("transport", 2.1, 3.0, 2.0, 1.0, -1.0, paths=1000)
    back = pickle.loads(pickle.dumps(r))
    assert back == r and type(back) is type(r)
    with pytest.warns(DeprecationWarning):
        assert back["gradient_x"] == r["gradient"]["x"]


def test_arrays_of_a_sweep_along_the_rod():
    xs = [0.5, 1.0, 1.5]
    rs = [geosens.rod("transport", 2.1, 3.0, 2.0, x, -1, paths=10_000, seed=i)
          for i, x in enumerate(xs)]
    a = geosens.arrays(rs)
    mean, stderr = a["sensitivity"]["length"]
    assert mean.tolist() == [r["sensitivity"]["length"]["mean"] for r in rs]
    assert stderr.tolist() == [r["sensitivity"]["length"]["stderr"] for r in rs]
    assert a["intensity"].mean.dtype == np.float64
    assert a["gradient"]["x"].stderr.tolist() == [r["gradient"]["x"]["stderr"] for r in rs]
    assert a["paths"].tolist() == [10_000] * 3
    assert "method" not in a
    # One result: arrays of one entry.
    assert geosens.arrays(rs[0])["intensity"].mean.tolist() == [rs[0]["intensity"]["mean"]]


def test_arrays_of_scenes_and_renderings():
    flat = [geosens.flat(SCENES / "occluder.toml", "expectation", paths=5000, seed=s)
            for s in (1, 2)]
    a = geosens.arrays(flat)
    assert set(a["sensitivity"]) == set(flat[0]["sensitivity"]) and a["gradient"] is None
    imgs = [geosens.render(SCENES / "camera_line.toml", "expectation", spp=4, seed=s)
            for s in (1, 2)]
    a = geosens.arrays(imgs)
    assert a["images"]["tx"].mean.shape == (2, 1, 40)
    assert (a["images"]["I"].stderr[1] == imgs[1]["images"]["I"]["stderr"]).all()
    assert a["intensity"].mean.shape == (2,)


def test_arrays_of_an_optimisation():
    scene = {
        "shapes": [
            {"name": "lamp", "vertices": [[-1.0, 2.0], [1.0, 2.0]],
             "surface": {"kind": "emitter", "radiance": 1.0}},
            {"name": "occluder", "vertices": [[-0.6, 1.0], [0.2, 1.0]],
             "surface": {"kind": "absorber"}},
        ],
        "parameters": [{"name": "occ_tx", "shape": "occluder",
                        "motion": {"kind": "translate_x"}}],
        "measurements": [{"kind": "irradiance", "point": [0.0, 0.0], "normal": [0.0, 1.0],
                          "target": 0.2}],
        "objective": {"kind": "least_squares"},
    }
    records = geosens.optimize(scene, "expectation", iterations=3, paths_per_step=1024)
    a = geosens.arrays(records)
    assert a["iteration"].tolist() == [0, 1, 2, 3]
    assert a["parameters"]["occ_tx"].tolist() == [r["parameters"]["occ_tx"] for r in records]
    assert a["loss"].mean.shape == (4,)


def test_arrays_refuses_results_that_differ():
    a = geosens.rod("transport", 2.1, 3.0, 2.0, 1.0, -1, paths=1000)
    b = geosens.rod("expectation", 2.1, 3.0, 2.0, 1.0, -1, paths=1000)
    with pytest.raises(ValueError, match=r"results\[1\]\['gradient'\] is None"):
        geosens.arrays([a, b])
    c = geosens.rod("intensity", 2.1, 3.0, 2.0, 1.0, -1, paths=1000)
    with pytest.raises(ValueError, match=r"results\[1\] has no \['sensitivity'\]\['length'\]"):
        geosens.arrays([b, c])
    with pytest.raises(ValueError, match="no results"):
        geosens.arrays([])
    with pytest.raises(ValueError, match=r"results\[0\] is not a result dict \(int\)"):
        geosens.arrays([1])
