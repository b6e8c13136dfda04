"""python/examples/rod_figure.py draws its figure (few paths: a smoke test;
the estimates themselves are checked against the command line elsewhere),
reading results in their current layout (a deprecated key is an error)."""

from __future__ import annotations

import subprocess
import sys

import pytest
from conftest import REPO

pytest.importorskip("matplotlib")


def test_rod_figure_writes_a_png(tmp_path):
    out = tmp_path / "rod.png"
    subprocess.run(
        [sys.executable, "-W", "error:the earlier layout's key:DeprecationWarning", str(REPO / "python" / "examples" / "rod_figure.py"), str(out),
         "--paths", "2000"],
        check=True,
    )
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
