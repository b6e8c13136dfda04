"""geosens.optimize: the records of ``geosens optimize --json``, on a small
flatland inverse problem whose targets are the closed form's irradiances
at a known pose of the occluder (the lamp y = 2, x ∈ [-1, 1], radiance 1;
the occluder at y = 1, x ∈ [-0.6, 0.2], moved by ``occ_tx``)."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import threading
import time

import pytest
import geosens

#: The pose the targets are made at (the start is 0).
TRUE_TX = 0.15
#: Where the sensors are.
POINTS = [-0.5, -0.1, 0.3, 0.7]
KEYS = {"iteration", "parameters", "average", "loss", "gradient", "paths", "seconds", "sampling_seconds"}


def irradiance(x0: float, tx: float) -> float:
    """The closed form at (x0, 0), normal +y: E = Σ (sin φ₂ − sin φ₁) over
    the lamp's visible angular intervals (φ from the normal, radiance 1)."""

    def sin_phi(x: float, y: float) -> float:
        return (x - x0) / math.hypot(x - x0, y)

    lamp = (sin_phi(-1.0, 2.0), sin_phi(1.0, 2.0))
    occ = (sin_phi(-0.6 + tx, 1.0), sin_phi(0.2 + tx, 1.0))
    seen = lamp[1] - lamp[0]
    hidden = max(0.0, min(lamp[1], occ[1]) - max(lamp[0], occ[0]))
    return seen - hidden


def problem(objective: str = "least_squares", bounds=(-0.5, 0.5)) -> dict:
    measurements = [
        {"kind": "irradiance", "point": [x, 0.0], "normal": [0.0, 1.0]} for x in POINTS
    ]
    if objective == "least_squares":
        for m in measurements:
            m["target"] = irradiance(m["point"][0], TRUE_TX)
    return {
        "shapes": [
            {"name": "lamp", "vertices": [[-1.0, 2.0], [1.0, 2.0]],
             "surface": {"kind": "emitter", "radiance": 1.0}},
            {"name": "occluder", "vertices": [[-0.6, 1.0], [0.2, 1.0]],
             "surface": {"kind": "absorber"}},
        ],
        "parameters": [
            {"name": "occ_tx", "shape": "occluder", "motion": {"kind": "translate_x"},
             "bounds": list(bounds)},
        ],
        "measurements": measurements,
        "objective": {"kind": objective},
    }


def timeless(records: list) -> str:
    """The records as JSON text without their wall times (``"seconds"``,
    ``"sampling_seconds"``), the only fields two identical runs differ in."""
    return json.dumps(
        [{k: v for k, v in r.items() if k not in ("seconds", "sampling_seconds")}
         for r in records]
    )


SMALL = dict(iterations=5, paths_per_step=2048, seed=3)


def test_the_closed_form_is_what_geosens_estimates():
    """The targets' formula, checked once against an estimate."""
    scene = problem()
    del scene["measurements"], scene["objective"]
    scene["sensor"] = {"kind": "irradiance", "point": [0.2, 0.0], "normal": [0.0, 1.0]}
    r = geosens.flat(scene, "intensity", paths=400_000, seed=5)
    i = r["intensity"]
    assert abs(i["mean"] - irradiance(0.2, 0.0)) < 5 * i["stderr"]


def test_records_keys_and_shapes():
    records = geosens.optimize(problem(), "expectation", **SMALL)
    assert [r["iteration"] for r in records] == list(range(6))
    for r in records:
        assert KEYS <= set(r) <= KEYS | {"notes"}
        assert set(r["parameters"]) == {"occ_tx"}
        assert set(r["gradient"]) == {"occ_tx"}
        assert set(r["loss"]) == {"mean", "stderr"}
        assert set(r["gradient"]["occ_tx"]) == {"mean", "stderr"}
        # Every measurement's paths.
        assert r["paths"] == 2048 * len(POINTS)
        assert 0 <= r["sampling_seconds"] <= r["seconds"]
    assert records[0]["parameters"]["occ_tx"] == 0.0


def test_the_records_are_the_command_lines(cli, tmp_path):
    scene = tmp_path / "problem.json"
    scene.write_text(json.dumps(problem()))
    lines = cli.run(
        "optimize", "--scene", scene, "--method", "transport", "--optimizer", "sgd",
        "--iterations", 4, "--paths-per-step", 1024, "--step", 0.5, "--batches", 4,
        "--seed", 9, "--json",
    ).stdout.splitlines()
    expected = [json.loads(line) for line in lines]
    kw = dict(optimizer="sgd", iterations=4, paths_per_step=1024, step=0.5, batches=4, seed=9)
    for s in (problem(), scene, str(scene)):
        got = geosens.optimize(s, "transport", **kw)
        assert timeless(got) == timeless(expected)


def test_reproducible_whatever_the_threads():
    runs = [
        geosens.optimize(problem(), "expectation", threads=t, **SMALL) for t in (1, 2, 1)
    ]
    texts = [timeless(r) for r in runs]
    assert texts[0] == texts[1] == texts[2]
    other = geosens.optimize(problem(), "expectation", **{**SMALL, "seed": 4})
    assert timeless(other) != texts[0]


def test_the_loss_falls_and_the_parameter_finds_the_pose():
    """Adam from 0 overshoots 0.15 (to about 0.2 by iteration 16) and
    settles; over the last ten iterations occ_tx is within 0.005 of it and
    the loss is noise, within a few standard errors of 0 (the estimate is
    unbiased, so it can be negative)."""
    records = geosens.optimize(problem(), "expectation", paths_per_step=8192, seed=2)
    assert len(records) == 101
    start = records[0]["loss"]["mean"]
    for r in records[-10:]:
        assert abs(r["parameters"]["occ_tx"] - TRUE_TX) < 0.005
        assert r["loss"]["mean"] < 0.01 * start
        assert abs(r["loss"]["mean"]) < 4 * r["loss"]["stderr"]


def test_progress_sees_every_record_and_false_ends_the_run():
    seen = []
    records = geosens.optimize(problem(), "expectation", progress=seen.append, **SMALL)
    assert seen == records

    def until_two(r):
        return r["iteration"] < 2

    records = geosens.optimize(problem(), "expectation", progress=until_two, **SMALL)
    assert [r["iteration"] for r in records] == [0, 1, 2]

    def boom(r):
        raise LookupError("the progress's own")

    with pytest.raises(LookupError, match="the progress's own"):
        geosens.optimize(problem(), "expectation", progress=boom, **SMALL)


def test_bounds_clamp_with_a_note():
    """Bounds [-0.05, 0.05] keep occ_tx short of the true 0.15."""
    records = geosens.optimize(
        problem(bounds=(-0.05, 0.05)), "expectation", iterations=12, paths_per_step=2048,
        step=0.02, seed=2,
    )
    assert max(r["parameters"]["occ_tx"] for r in records) == 0.05
    assert any("clamped to bounds: occ_tx" in n for r in records for n in r.get("notes", []))


def test_bad_problems_name_the_field(cli, tmp_path):
    no_target = problem()
    del no_target["measurements"][1]["target"]
    with pytest.raises(ValueError, match="target") as e:
        geosens.optimize(no_target, "expectation", **SMALL)
    assert "measurements[1]" in str(e.value)
    f = tmp_path / "no_target.json"
    f.write_text(json.dumps(no_target))
    err = cli.error("optimize", "--scene", f, "--method", "expectation")
    assert err == str(e.value).replace("invalid scene: ", f"invalid scene: {f}: ")
    with pytest.raises(ValueError) as in_file:
        geosens.optimize(f, "expectation", **SMALL)
    assert str(in_file.value) == err

    with pytest.raises(ValueError, match="bounds") as e:
        geosens.optimize(problem(bounds=(0.5, -0.5)), "expectation", **SMALL)
    assert "reversed" in str(e.value) and "occ_tx" in str(e.value)

    no_objective = problem()
    del no_objective["objective"]
    with pytest.raises(ValueError, match="objective"):
        geosens.optimize(no_objective, "expectation", **SMALL)


@pytest.mark.parametrize(
    "kw, word",
    [
        (dict(step=0.0), "step"),
        (dict(step=float("nan")), "step"),
        (dict(iterations=0), "iterations"),
        (dict(iterations=2**40), "iterations"),
        (dict(batches=1), "batches"),
        (dict(optimizer="newton"), "optimizer"),
        (dict(paths_per_step=-1), "paths_per_step"),
        (dict(tolerance="0.1"), "tolerance"),
    ],
)
def test_bad_settings_name_the_argument(kw, word):
    with pytest.raises(ValueError, match=word):
        geosens.optimize(problem(), "expectation", **{**SMALL, **kw})


def test_the_gil_is_released():
    count = 0
    done = threading.Event()

    def tick() -> None:
        nonlocal count
        while not done.is_set():
            count += 1
            time.sleep(0.001)

    t = threading.Thread(target=tick)
    t.start()
    try:
        geosens.optimize(problem(), "expectation", iterations=10, paths_per_step=16384, threads=1)
    finally:
        done.set()
        t.join()
    assert count > 20


SIGINT = r"""
import os, signal, sys, threading, time
sys.path.insert(0, {tests!r})
import geosens
from test_optimize import problem

def fire():
    time.sleep(1.0)
    os.kill(os.getpid(), signal.SIGINT)

threading.Thread(target=fire, daemon=True).start()
start = time.monotonic()
try:
    geosens.optimize(problem(), "transport", iterations=10**6, paths_per_step=16384, threads=1)
except KeyboardInterrupt as e:
    n = len(e.records)
    assert [r["iteration"] for r in e.records] == list(range(n)), e.records
    print(f"interrupted after {{time.monotonic() - start:.2f}} s, {{n}} records")
    sys.exit(0 if n > 0 else 5)
print("the run ended")
sys.exit(3)
"""


def test_ctrl_c_stops_between_iterations():
    from pathlib import Path

    script = SIGINT.format(tests=str(Path(__file__).parent))
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 0, f"{out.stdout} {out.stderr}"
    assert float(out.stdout.split()[2]) < 10, out.stdout


def test_the_timing_example_runs():
    """python/examples/optimize_loop.py (a smoke test: few iterations)."""
    from conftest import REPO

    out = subprocess.run(
        [sys.executable, "-W", "ignore", str(REPO / "python" / "examples" / "optimize_loop.py"),
         "--iterations", "3", "--paths", "512", "--threads", "1"],
        capture_output=True, text=True, check=True, timeout=60,
    ).stdout
    assert "by hand (flat)" in out and "geosens.optimize" in out
