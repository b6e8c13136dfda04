"""Ctrl-C stops a run: SIGINT during a call that would take years (2^53
paths) or most of a minute (a line camera of 40 pixels, 10^7 paths per
pixel, about a second each) raises KeyboardInterrupt within a few seconds,
on one thread and on several. Each run is a
subprocess with a timeout, so a run that ignores the signal fails the test
instead of hanging it."""

from __future__ import annotations

import subprocess
import sys

import pytest
from conftest import SCENES

SCRIPT = r"""
import os, signal, sys, threading, time
import geosens

def fire():
    time.sleep(1.0)
    os.kill(os.getpid(), signal.SIGINT)

threading.Thread(target=fire, daemon=True).start()
start = time.monotonic()
try:
    {call}
except KeyboardInterrupt:
    print(f"interrupted after {{time.monotonic() - start:.2f}} s")
    sys.exit(0)
print("the run ended")
sys.exit(3)
"""

CALLS = {
    "rod, one thread": 'geosens.rod("intensity", 1.0, 2.0, 2.0, 1.0, 1, paths=2**53, threads=1)',
    "rod, two threads": 'geosens.rod("expectation", 1.0, 2.0, 2.0, 1.0, 1, paths=2**53, threads=2)',
    "flat": f'geosens.flat({str(SCENES / "fog.toml")!r}, "transport", paths=2**53, threads=1)',
    "render": f'geosens.render({str(SCENES / "camera_line.toml")!r}, "rendering", spp=10**7, threads=1)',
}


@pytest.mark.parametrize("name", list(CALLS))
def test_ctrl_c_stops_a_run(name):
    script = SCRIPT.format(call=CALLS[name])
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 0, f"{name}: {out.stdout} {out.stderr}"
    seconds = float(out.stdout.split()[2])
    # The signal at 1 s; the run stops after the chunk (or pixel) under way.
    assert seconds < 10, f"{name}: {out.stdout}"
