"""Bad input raises ValueError with the command line's message (its stderr
minus ``error: ``), the library's Display of its error."""

from __future__ import annotations

import re

import pytest
from conftest import SCENES

import geosens

OCC = SCENES / "occluder.toml"
ROD = ["--ks", 0.07, "--ke", 0.1, "--length", 2, "--x", 1, "--omega", 1]


def raises(f, *args, **kw) -> str:
    with pytest.raises(ValueError) as e:
        f(*args, **kw)
    return str(e.value)


@pytest.mark.parametrize("command", ["flat", "rod"])
def test_unknown_method(cli, command):
    """clap words the command line's message itself; the library's names
    the value and the same methods in the same order."""
    if command == "flat":
        msg = raises(geosens.flat, OCC, "magic")
        err = cli.error("flat", "--scene", OCC, "--method", "magic")
    else:
        msg = raises(geosens.rod, "magic", 0.07, 0.1, 2, 1, 1)
        err = cli.error("rod", "--method", "magic", *ROD)
    allowed = re.search(r"\[possible values: ([^\]]*)\]", err).group(1)
    assert "'magic'" in err
    assert msg == f'invalid run configuration: unknown method "magic": expected one of {allowed}'


def test_too_few_paths(cli):
    msg = raises(geosens.flat, OCC, "expectation", paths=1)
    assert msg == cli.error("flat", "--scene", OCC, "--method", "expectation", "--paths", 1)
    msg = raises(geosens.rod, "exact", 0.07, 0.1, 2, 1, 1, paths=1)
    assert msg == cli.error("rod", "--method", "exact", *ROD[:-2], "--omega", 1, "--paths", 1)


def test_bad_scene_value(cli, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(OCC.read_text().replace("radiance = 1.0", "radiance = -1.0"))
    msg = raises(geosens.flat, bad, "expectation", paths=1000)
    assert msg == cli.error("flat", "--scene", bad, "--method", "expectation", "--paths", 1000)
    assert "radiance -1" in msg


def test_missing_file(cli, tmp_path):
    missing = tmp_path / "nope.toml"
    for f, command in [(geosens.flat, "flat"), (geosens.mesh, "mesh")]:
        msg = raises(f, missing, "expectation")
        assert msg == cli.error(command, "--scene", missing, "--method", "expectation")
    msg = raises(geosens.render, missing, "expectation")
    assert msg == cli.error("render", "--scene", missing, "--method", "expectation", "--out", tmp_path)


@pytest.mark.parametrize(
    "call, args",
    [
        (lambda: geosens.rod("exact", 0.07, 0.05, 2, 1, 1),
         ["rod", "--method", "exact", "--ks", 0.07, "--ke", 0.05, "--length", 2, "--x", 1, "--omega", 1]),
        (lambda: geosens.rod("exact", 0.07, 0.1, 2, 1, 1, threads=5000),
         ["rod", "--method", "exact", *ROD, "--threads", 5000]),
        (lambda: geosens.rod("intensity", 0.07, 0.1, 2, 1, 0.5),
         ["rod", "--method", "intensity", *ROD[:-2], "--omega", 0.5]),
        (lambda: geosens.flat(OCC, "expectation", fd_step=0.1),
         ["flat", "--scene", OCC, "--method", "expectation", "--fd-step", 0.1]),
        (lambda: geosens.flat(OCC, "fd", fd_step=2.0),
         ["flat", "--scene", OCC, "--method", "fd", "--fd-step", 2.0]),
        (lambda: geosens.mesh(OCC, "expectation"),
         ["mesh", "--scene", OCC, "--method", "expectation"]),
        (lambda: geosens.flat(SCENES / "camera_line.toml", "expectation"),
         ["flat", "--scene", SCENES / "camera_line.toml", "--method", "expectation"]),
        (lambda: geosens.render(OCC, "expectation"),
         ["render", "--scene", OCC, "--method", "expectation", "--out", "/nonexistent/x"]),
        (lambda: geosens.render(SCENES / "camera_line.toml", "expectation", spp=1),
         ["render", "--scene", SCENES / "camera_line.toml", "--method", "expectation",
          "--spp", 1, "--out", "/nonexistent/x"]),
    ],
)
def test_more_bad_input(cli, call, args):
    assert raises(call) == cli.error(*args)


def test_python_side_checks():
    """What the command line's parser refuses before the library sees it."""
    assert "paths" in raises(geosens.flat, OCC, "expectation", paths=-5)
    assert "seed" in raises(geosens.rod, "exact", 0.07, 0.1, 2, 1, 1, seed=1.5)
    assert "scene" in raises(geosens.flat, 42, "expectation")
    assert "shard" in raises(geosens.flat, OCC, "expectation", shard=3)
    # Past u64 pyo3 raised an OverflowError naming nothing; a string was
    # taken for a number.
    assert "paths" in raises(geosens.flat, OCC, "expectation", paths=2**64)
    assert "seed" in raises(geosens.rod, "exact", 0.07, 0.1, 2, 1, 1, seed=2**70)
    assert "ks" in raises(geosens.rod, "exact", "0.07", 0.1, 2, 1, 1)
    assert "fd_step" in raises(geosens.flat, OCC, "fd", fd_step="0.01")
    with pytest.raises(ValueError, match="not a geosens state"):
        geosens.merge([{"a": 1}])


def test_a_parameter_named_like_another_quantity_is_refused(tmp_path, cli):
    """A parameter named ``I`` took the key of the intensity's image (the
    images came back as ``['I', 'rot']``, the intensity's gone); one named
    ``x`` printed a second ``∂I/∂x`` row beside the sensor gradient's."""
    import tomllib

    for path, old, new in [(SCENES / "camera_line.toml", "tx", "I"), (OCC, "occluder_tx", "x")]:
        text = path.read_text().replace(f'name = "{old}"', f'name = "{new}"')
        scene = tomllib.loads(text)
        renamed = tmp_path / path.name
        renamed.write_text(text)
        if new == "I":
            msg = raises(geosens.render, scene, "rendering", spp=4)
            err = cli.error("render", "--scene", renamed, "--method", "rendering",
                            "--spp", 4, "--out", tmp_path / "out")
        else:
            msg = raises(geosens.flat, scene, "transport", paths=1000)
            err = cli.error("flat", "--scene", renamed, "--method", "transport")
        assert f'parameter "{new}" has the name of' in msg
        assert err == msg.replace("invalid scene: ", f"invalid scene: {renamed}: ")
