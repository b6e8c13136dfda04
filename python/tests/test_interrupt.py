"""Ctrl-C stops a run: SIGINT during a call that would take years (2^53
paths) or most of a minute (a line camera of 40 pixels, 10^7 paths per
pixel, about a second each) raises KeyboardInterrupt within a few seconds,
on one thread and on several. A run called from a worker thread (which
Python's signals never reach) stops when its ``stop`` is set, an event or a
callable. Each run is a subprocess with a timeout, so a run that ignores the
signal fails the test instead of hanging it."""

from __future__ import annotations

import subprocess
import sys

import pytest
from conftest import SCENES

import geosens

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


# A run on a worker thread: Python runs signal handlers on its main thread
# only, so the main thread's KeyboardInterrupt (a real SIGINT sent to it:
# `_thread.interrupt_main` would not wake it from its wait on the result)
# reaches the run through `stop`. Before `stop`, the pool's shutdown waited
# for the run forever.
WORKER = r"""
import signal, sys, threading
from concurrent.futures import ThreadPoolExecutor
import geosens

{stop}
with ThreadPoolExecutor(1) as pool:
    run = pool.submit({call}, stop=stop)
    try:
        threading.Timer(
            1.0, signal.pthread_kill, (threading.main_thread().ident, signal.SIGINT)
        ).start()
        run.result()
        print("the run ended")
        sys.exit(3)
    except KeyboardInterrupt:
        {set_stop}
try:
    run.result()
except KeyboardInterrupt as e:
    print(f"the run stopped: {{e}}")
    sys.exit(0)
sys.exit(4)
"""

WORKER_CALLS = {
    "rod": 'geosens.rod, "intensity", 1.0, 2.0, 2.0, 1.0, 1, paths=2**53, threads=1',
    "flat, two threads": f'geosens.flat, {str(SCENES / "fog.toml")!r}, "transport", paths=2**53, threads=2',
    "render": f'geosens.render, {str(SCENES / "camera_line.toml")!r}, "rendering", spp=10**7, threads=1',
}

STOPS = {
    "event": ("stop = threading.Event()", "stop.set()"),
    # A callable, true to stop: here, once a list is not empty.
    "callable": ("asked = []\nstop = lambda: asked", "asked.append(True)"),
}


@pytest.mark.parametrize("stop", list(STOPS))
@pytest.mark.parametrize("name", list(WORKER_CALLS))
def test_stop_ends_a_run_on_a_worker_thread(name, stop):
    make, set_stop = STOPS[stop]
    script = WORKER.format(stop=make, call=WORKER_CALLS[name], set_stop=set_stop)
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, f"{name}, {stop}: {out.stdout} {out.stderr}"
    assert "stopped" in out.stdout, out.stdout


def test_a_raising_stop_ends_the_run_with_its_exception():
    def stop():
        raise LookupError("the stop's own")

    with pytest.raises(LookupError, match="the stop's own"):
        geosens.flat(SCENES / "fog.toml", "transport", paths=2**53, threads=1, stop=stop)


def test_stop_must_be_an_event_or_a_callable():
    with pytest.raises(ValueError, match="stop: expected a threading.Event"):
        geosens.flat(SCENES / "fog.toml", "transport", stop=True)
