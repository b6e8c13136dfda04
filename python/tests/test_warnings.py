"""The estimator's caveats are RuntimeWarnings, the lines the command line
prints on stderr after ``warning: ``."""

from __future__ import annotations

import json
import sys
import warnings

import pytest
from conftest import SCENES, assert_same

import geosens

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    tomllib = pytest.importorskip("tomli")


def cli_warnings(stderr: str) -> list:
    """The command line's warnings, each joined again from the lines it is
    wrapped into (100 columns, continuation lines indented by two spaces)."""
    out = []
    for line in stderr.splitlines():
        if line.startswith("warning: "):
            out.append(line.removeprefix("warning: "))
        elif line.startswith("  ") and out:
            out[-1] += " " + line[2:]
    return out


def test_caveats_are_runtime_warnings(cli, tmp_path):
    # The occluder's corner 10⁻⁴ above the sensor: fd's default half step
    # carries it past the sensor's zenith both ways (tests/flat_core.rs).
    with open(SCENES / "occluder.toml", "rb") as f:
        scene = tomllib.load(f)
    occ = next(s for s in scene["shapes"] if s["name"] == "occluder")
    occ["vertices"] = [[-0.6, 1e-4], [0.0, 1e-4]]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        py = geosens.flat(scene, "fd", paths=100_000, seed=2)
    path = tmp_path / "near.json"
    path.write_text(json.dumps(scene))
    p = cli.run("flat", "--scene", path, "--method", "fd", "--paths", 100_000, "--seed", 2,
                "--json")
    assert_same(py, geosens.from_json(p.stdout))
    want = cli_warnings(p.stderr)
    assert want and all("occluder_tx" in w or "occluder" in w for w in want)
    assert [str(w.message) for w in caught] == want
    assert all(w.category is RuntimeWarning for w in caught)
    # Issued at the caller's line, not inside the package (flat's went to
    # geosens/__init__.py, one frame short).
    assert all(w.filename == __file__ for w in caught), [w.filename for w in caught]
    caveated = [k for k, v in py["sensitivity"].items() if "caveat" in v]
    assert caveated and not any(py["sensitivity"][k]["reliable"] for k in caveated)


def test_no_caveat_no_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        geosens.flat(SCENES / "occluder.toml", "fd", paths=10_000)


def thin_fog(camera: bool = False) -> dict:
    """scenes/mesh/fog_cube.toml with its fog optically thin (fd's caveat),
    its sensor a 2×2 camera if ``camera``."""
    with open(SCENES / "mesh" / "fog_cube.toml", "rb") as f:
        scene = tomllib.load(f)
    for s in scene["shapes"]:
        if "medium" in s:
            s["medium"] = {"ks": 1e-4, "ke": 2e-4}
    if camera:
        scene["sensor"] = {"kind": "camera", "position": [0, 0, 0], "look_at": [0, 0, 2],
                           "up": [0, 1, 0], "fov_deg": 30.0, "width": 2, "height": 2}
    return scene


THIN_ROD = ("fd", 1e-4, 2e-4, 2.0, 1.0, 1.0)

# Every function that issues the estimator's caveats, each at its own call
# depth inside the package.
CAVEATED = {
    "rod": lambda: geosens.rod(*THIN_ROD, paths=1000),
    "mesh": lambda: geosens.mesh(thin_fog(), "fd", paths=1000),
    "render": lambda: geosens.render(thin_fog(camera=True), "fd", spp=2),
    "merge": lambda: geosens.merge(
        [geosens.rod(*THIN_ROD, paths=1000, shard=(i, 2)) for i in (1, 2)]
    ),
}


@pytest.mark.parametrize("name", CAVEATED)
def test_every_caveat_is_issued_at_the_callers_line(name):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        CAVEATED[name]()
    assert caught and all(w.category is RuntimeWarning for w in caught)
    assert all(w.filename == __file__ for w in caught), [w.filename for w in caught]


def test_old_keys_read_with_a_deprecation_at_the_callers_line():
    """The rod's and the rendering's earlier keys still read, each with a
    DeprecationWarning that names the new spelling, at the user's line."""
    rod = geosens.rod("transport", 2.1, 3.0, 2.0, 1.0, -1.0, paths=10_000)
    img = geosens.render(SCENES / "camera_line.toml", "expectation", spp=4)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert rod["sensitivity"]["mean"] == rod["sensitivity"]["length"]["mean"]
        assert rod["sensitivity"]["stderr"] == rod["sensitivity"]["length"]["stderr"]
        assert rod["gradient_x"] == rod["gradient"]["x"]
        assert rod.get("gradient_x") == rod["gradient"]["x"]
        assert img["I"] == img["intensity"]
    assert [w.category for w in caught] == [DeprecationWarning] * 5
    assert all(w.filename == __file__ for w in caught), [w.filename for w in caught]
    assert 'use r["sensitivity"]["length"]["mean"]' in str(caught[0].message)
    assert 'use r["gradient"]["x"]' in str(caught[2].message)
    # New keys, unknown keys and what is saved: no old key.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert "gradient_x" not in rod and "I" not in img
        assert rod.get("nothing") is None
        with pytest.raises(KeyError):
            rod["sensitivity"]["nothing"]
        assert "gradient_x" not in json.loads(json.dumps(rod))
