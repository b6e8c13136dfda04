"""Shared fixtures: the repository, the command line to compare with.

The command line is ``$GEOSENS_BIN`` if set, else the repository's release
binary (``cargo build --release`` builds it if missing, in
``$CARGO_TARGET_DIR`` or ``target/``). Every comparison runs it with the same
inputs and seed as the Python call.
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any, Dict, List, Tuple

import pytest

import geosens

REPO = Path(__file__).resolve().parents[2]
SCENES = REPO / "scenes"


def _binary() -> Path:
    env = os.environ.get("GEOSENS_BIN")
    if env:
        return Path(env)
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    if not target.is_absolute():
        target = REPO / target
    binary = target / "release" / "geosens"
    if not binary.exists():
        subprocess.run(
            ["cargo", "build", "--release", "--bin", "geosens"], cwd=REPO, check=True
        )
    return binary


class Cli:
    """The ``geosens`` command line, run from the repository's root."""

    def __init__(self, binary: Path) -> None:
        self.binary = binary

    def run(self, *args: Any, check: bool = True) -> subprocess.CompletedProcess:
        p = subprocess.run(
            [str(self.binary), *map(str, args)],
            cwd=REPO,
            capture_output=True,
            text=True,
        )
        if check and p.returncode != 0:
            raise AssertionError(f"geosens {args} failed: {p.stderr}")
        return p

    def json(self, *args: Any) -> Dict[str, Any]:
        """The ``--json`` line of ``geosens ARGS --json``, read as the
        package reads it (:func:`geosens.from_json`: the rod's in the layout
        of every result)."""
        return geosens.from_json(self.run(*args, "--json").stdout)

    def error(self, *args: Any) -> str:
        """The message of a run that fails: its stderr minus ``error: ``."""
        p = self.run(*args, check=False)
        assert p.returncode != 0, f"geosens {args} did not fail"
        err = p.stderr.strip()
        assert err.startswith("error: "), err
        return err[len("error: ") :]


@pytest.fixture(scope="session")
def cli() -> Cli:
    return Cli(_binary())


@pytest.fixture(autouse=True)
def at_repo(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every test runs from the repository's root, as the command line does
    (scene paths are relative to it)."""
    monkeypatch.chdir(REPO)


def without_seconds(d: Any) -> Any:
    """``d`` without its ``"seconds"`` keys (the only field that differs
    between two identical runs)."""
    if isinstance(d, dict):
        return {k: without_seconds(v) for k, v in d.items() if k != "seconds"}
    if isinstance(d, list):
        return [without_seconds(v) for v in d]
    return d


def image_bytes(result: Dict[str, Any]) -> List[Tuple[str, bytes, bytes]]:
    """A rendering's images as bytes, to compare bit for bit."""
    return [
        (k, v["mean"].tobytes(), v["stderr"].tobytes())
        for k, v in result["images"].items()
    ]


def assert_same(a: Dict[str, Any], b: Dict[str, Any]) -> None:
    """``a`` and ``b`` are the same result bit for bit but for ``"seconds"``
    (and the images, compared with :func:`image_bytes`): compared as JSON
    text, whose floats are the shortest that read back to the same bits (so
    that 0.0 and -0.0, equal as numbers, differ)."""
    strip = lambda d: {k: v for k, v in without_seconds(d).items() if k != "images"}
    assert json.dumps(strip(a)) == json.dumps(strip(b))
