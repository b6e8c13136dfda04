"""The closed forms from Python: the rod's Bellman–Wing solution along the
rod, flatland's and 3D's occluder scenes. Each is compared with the command
line's exact column where it prints one (``geosens rod --method exact``)
and with the package's own Monte Carlo estimates (fixed seeds, within four
standard errors: the estimators are unbiased, the closed forms exact)."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from conftest import SCENES

import geosens

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    tomllib = pytest.importorskip("tomli")

THIN = (0.07, 0.1, 2.0)
THICK = (2.1, 3.0, 2.0)
Z = 4.0


def assert_within(result: dict, exact: dict) -> None:
    """Every quantity ``result`` estimates is within Z standard errors of
    ``exact``'s, in the one layout both have."""
    pairs = [(("intensity",), result["intensity"], exact["intensity"])]
    for group in ("sensitivity", "gradient"):
        for name, q in (result[group] or {}).items():
            pairs.append(((group, name), q, exact[group][name]))
    assert len(pairs) > 1
    for where, q, want in pairs:
        assert q["reliable"], where
        assert q["stderr"] > 0, where
        z = (q["mean"] - want) / q["stderr"]
        assert abs(z) < Z, f"{where}: {q['mean']} ± {q['stderr']} against {want} (z = {z:.1f})"


@pytest.mark.parametrize("rod", [THIN, THICK])
@pytest.mark.parametrize("omega", [1.0, -1.0])
def test_rod_curve_is_the_command_lines_exact_column(cli, rod, omega):
    ks, ke, length = rod
    xs = np.linspace(0.0, length, 5)
    curve = geosens.rod_exact(ks, ke, length, xs, omega)
    for k, x in enumerate(xs):
        ref = cli.json("rod", "--method", "exact", "--ks", ks, "--ke", ke, "--length", length,
                       "--x", x, "--omega", omega)
        assert curve["intensity"][k] == ref["intensity"]["mean"]
        assert curve["sensitivity"]["length"][k] == ref["sensitivity"]["length"]["mean"]
        assert curve["gradient"]["x"][k] == ref["gradient"]["x"]["mean"]


def test_rod_exact_keeps_the_shape_of_x():
    one = geosens.rod_exact(*THICK, 1.0, -1)
    assert isinstance(one["intensity"], float)
    grid = geosens.rod_exact(*THICK, np.full((2, 3), 1.0), -1)
    assert grid["sensitivity"]["length"].shape == (2, 3)
    assert (grid["intensity"] == one["intensity"]).all()
    listed = geosens.rod_exact(*THICK, [0.5, 1.0], -1)
    assert listed["gradient"]["x"][1] == one["gradient"]["x"]


@pytest.mark.parametrize(
    "rod, x, omega, seed",
    [(THIN, 0.5, 1.0, 3), (THIN, 1.5, -1.0, 4), (THICK, 1.0, -1.0, 5), (THICK, 1.9, 1.0, 6)],
)
def test_rod_exact_against_transport(rod, x, omega, seed):
    """Transport estimates I, ∂I/∂length and ∂I/∂x: all three."""
    r = geosens.rod("transport", *rod, x, omega, paths=400_000, seed=seed)
    assert_within(r, geosens.rod_exact(*rod, x, omega))


@pytest.mark.parametrize(
    "scene, method",
    [("occluder.toml", "transport"), ("occluder.toml", "expectation"),
     ("polygon_occluder.toml", "transport"), ("absorbing_slab.toml", "expectation")],
)
def test_flat_exact_against_monte_carlo(scene, method):
    exact = geosens.flat_exact(SCENES / scene)
    r = geosens.flat(SCENES / scene, method, paths=400_000, seed=11)
    assert set(exact["sensitivity"]) == set(r["sensitivity"])
    assert set(exact["gradient"]) == {"x", "y"}
    assert_within(r, exact)


@pytest.mark.parametrize(
    "scene, method",
    [("occluder.toml", "transport"), ("triangle.toml", "expectation"),
     ("cube_shadow.toml", "rendering")],
)
def test_mesh_exact_against_monte_carlo(scene, method):
    exact = geosens.mesh_exact(SCENES / "mesh" / scene)
    assert exact["gradient"] is None
    r = geosens.mesh(SCENES / "mesh" / scene, method, paths=200_000, seed=12)
    assert set(exact["sensitivity"]) == set(r["sensitivity"])
    # 3D's closed form has no ∂E/∂x: compare I and the sensitivities.
    r["gradient"] = None
    assert_within(r, exact)


def test_a_dict_is_its_file():
    with open(SCENES / "occluder.toml", "rb") as f:
        flat = tomllib.load(f)
    assert geosens.flat_exact(flat) == geosens.flat_exact(SCENES / "occluder.toml")
    with open(SCENES / "mesh" / "triangle.toml", "rb") as f:
        mesh = tomllib.load(f)
    assert geosens.mesh_exact(mesh) == geosens.mesh_exact(str(SCENES / "mesh" / "triangle.toml"))


@pytest.mark.parametrize(
    "call, why",
    [
        (lambda: geosens.flat_exact(SCENES / "fog.toml"),
         "fog.toml: no analytic reference: reflectors, scattering media or several media"),
        (lambda: geosens.flat_exact(SCENES / "camera_line.toml"),
         "no analytic reference: the sensor is a camera"),
        (lambda: geosens.mesh_exact(SCENES / "mesh" / "fog_cube.toml"),
         "fog_cube.toml: no analytic reference: reflectors and media have none"),
        (lambda: geosens.mesh_exact(SCENES / "occluder.toml"),
         "this is a flatland (2D) scene"),
        (lambda: geosens.flat_exact(42), "a scene is a file path or a dict, not int"),
    ],
)
def test_no_closed_form_is_a_value_error_saying_why(call, why):
    with pytest.raises(ValueError) as e:
        call()
    assert why in str(e.value)


def test_bad_rod_input_is_the_command_lines_error(cli):
    with pytest.raises(ValueError) as e:
        geosens.rod_exact(*THIN, [1.0, 3.0], 1)
    assert str(e.value) == cli.error("rod", "--method", "exact", "--ks", THIN[0], "--ke",
                                     THIN[1], "--length", THIN[2], "--x", 3.0, "--omega", 1)
    with pytest.raises(ValueError, match="expected numbers"):
        geosens.rod_exact(*THIN, ["a"], 1)
    with pytest.raises(ValueError, match="for omega"):
        geosens.rod_exact(*THIN, 1.0, "left")
