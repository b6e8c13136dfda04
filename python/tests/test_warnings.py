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
    assert_same(py, json.loads(p.stdout))
    want = [line.removeprefix("warning: ") for line in p.stderr.splitlines()]
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
