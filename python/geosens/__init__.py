"""Monte Carlo estimates of intensity and geometric sensitivities.

The Python face of the geosens command line: each function runs what its
subcommand runs and returns what ``--json`` prints, parsed::

    >>> import geosens
    >>> r = geosens.rod("expectation", 0.07, 0.1, 2.0, 1.0, 1.0, paths=100_000)
    >>> r["sensitivity"]["mean"], r["sensitivity"]["stderr"]

- :func:`rod`, :func:`flat`, :func:`mesh` return the dict of the command
  line's JSON line (``geosens rod|flat|mesh ... --json``), identical bit for
  bit for the same seed but for ``"seconds"``;
- :func:`render` returns the JSON line of ``geosens render`` with the images
  added under ``"images"`` as float64 arrays of shape (height, width);
- :func:`optimize` runs ``geosens optimize --json`` on a scene with
  ``measurements`` and an ``objective`` and returns its records, one dict
  per iteration;
- with ``shard=(i, n)`` each returns shard ``i`` of ``n`` of the run instead:
  its exact state, a dict (``--shard i/n --state FILE``), and :func:`merge`
  turns the states of all ``n`` shards into what the single run returns.

A scene is a file (TOML or JSON, a ``str`` or ``os.PathLike``) or a dict with
the file's schema, so that a notebook can sweep a parameter by editing it
(OBJ paths in a dict are relative to the current directory). Bad input
raises :class:`ValueError` with the command line's message; the estimator's
caveats are issued as :class:`RuntimeWarning`. The GIL is released while
paths are sampled, so other Python threads run meanwhile.

Ctrl-C stops a run called from Python's main thread (``KeyboardInterrupt``).
Python delivers signals to its main thread only, so a run called from
another thread (a ``threading.Thread``, a ``ThreadPoolExecutor``) is
stopped through its ``stop``: a :class:`threading.Event` (or anything with
``is_set()``) or a callable, looked at every 50 ms, that the main thread
sets when it gets the ``KeyboardInterrupt``::

    stop = threading.Event()
    with ThreadPoolExecutor() as pool:
        runs = [pool.submit(geosens.flat, s, "transport", stop=stop) for s in scenes]
        try:
            results = [r.result() for r in runs]
        except KeyboardInterrupt:
            stop.set()  # every run ends at its next chunk
            raise

A stopped run raises ``KeyboardInterrupt`` (or what the callable raised).
"""

from __future__ import annotations

import json
import operator
import os
import threading
import warnings
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _geosens

__all__ = ["rod", "flat", "mesh", "render", "merge", "optimize", "__version__"]

__version__: str = _geosens.__version__

#: A scene: a TOML or JSON file, or a dict of the file's schema.
Scene = Union[str, "os.PathLike[str]", Dict[str, Any]]
#: A shard of a run: ``(i, n)``, 1 ≤ i ≤ n.
ShardSpec = Tuple[int, int]
#: A shard's state: its dict, its JSON text, or the file the command line's
#: ``--state`` wrote.
StateLike = Union[Dict[str, Any], str, "os.PathLike[str]"]
#: What stops a run: a :class:`threading.Event` (anything with ``is_set()``)
#: or a callable of no argument, true to stop.
Stop = Union[threading.Event, Callable[[], Any]]


def _uint(name: str, value: Any) -> int:
    """``value`` as an ``int`` if it is an integer from 0 to 2⁶⁴ − 1, else
    ValueError. An integer is anything with ``__index__`` (numpy's
    ``np.int64``, what a sweep over ``np.arange`` or ``np.logspace(...)
    .astype(int)`` hands over), but not a bool: ``paths=True`` is a mistake.
    Rust takes u64; past it, pyo3 raised an OverflowError naming nothing."""
    bad = ValueError(
        f"invalid value {value!r} for {name}: expected an integer from 0 to 2^64 - 1"
    )
    if isinstance(value, (bool, np.bool_)):
        raise bad
    try:
        n = operator.index(value)
    except TypeError:
        raise bad from None
    if not 0 <= n < 2**64:
        raise bad
    return n


def _real(name: str, value: Any) -> float:
    """``value`` as a float if it is a number (numpy's too), else ValueError:
    ``float("2.1")`` would take a string silently."""
    if isinstance(value, (str, bytes, bool)):
        raise ValueError(f"invalid value {value!r} for {name}: expected a number")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ValueError(f"invalid value {value!r} for {name}: expected a number") from None


def _shard(shard: Optional[ShardSpec]) -> Optional[Tuple[int, int]]:
    if shard is None:
        return None
    try:
        i, n = shard
    except (TypeError, ValueError):
        raise ValueError(
            f"shard {shard!r}: expected (i, n) with 1 ≤ i ≤ n"
        ) from None
    return (_uint("shard index", i), _uint("shard count", n))


def _stop(stop: Optional[Stop]) -> Optional[Callable[[], Any]]:
    """The callable the run calls every 50 ms: an event's ``is_set``, or
    ``stop`` itself."""
    if stop is None:
        return None
    is_set = getattr(stop, "is_set", None)
    if callable(is_set):
        return is_set
    if callable(stop):
        return stop
    raise ValueError(
        f"stop: expected a threading.Event (anything with is_set()) or a callable, "
        f"not {type(stop).__name__}"
    )


def _fd_step(fd_step: Optional[float]) -> Optional[float]:
    return None if fd_step is None else _real("fd_step", fd_step)


def _plain(value: Any) -> Any:
    """numpy arrays and scalars, a sweep's usual values, as the lists and
    numbers JSON has."""
    if isinstance(value, (np.ndarray, np.generic)):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not a scene value")


def _scene(scene: Scene) -> Tuple[Optional[str], Optional[str]]:
    """The scene as (file, None) or (None, JSON text)."""
    if isinstance(scene, dict):
        try:
            return None, json.dumps(scene, default=_plain, allow_nan=False)
        except ValueError as e:
            # json's "Out of range float values are not JSON compliant".
            raise ValueError(
                f"invalid scene: a value is not finite (NaN or infinity): {e}"
            ) from None
        except TypeError as e:
            raise ValueError(f"invalid scene: {e}") from None
    if isinstance(scene, (str, os.PathLike)):
        return os.fspath(scene), None
    raise ValueError(
        f"a scene is a file path or a dict, not {type(scene).__name__}"
    )


def _result(outcome: Tuple[str, str, List[str], list], stacklevel: int = 3) -> Dict[str, Any]:
    """The Python result of a Rust call: its JSON parsed, its warnings
    issued (``stacklevel``: at the line of the user's code, which called the
    public function that called this one, 3, or the helper that did, 4),
    a rendering's images as arrays."""
    kind, text, warns, images = outcome
    for w in warns:
        warnings.warn(w.removeprefix("warning: "), RuntimeWarning, stacklevel=stacklevel)
    result = json.loads(text)
    if kind == "image":
        result["images"] = {
            key: {
                "mean": np.frombuffer(mean, dtype=np.float64).reshape(h, w),
                "stderr": np.frombuffer(stderr, dtype=np.float64).reshape(h, w),
            }
            for key, h, w, mean, stderr in images
        }
    return result


def rod(
    method: str,
    ks: float,
    ke: float,
    length: float,
    x: float,
    omega: float,
    *,
    paths: int = 1_000_000,
    seed: int = 1,
    threads: int = 0,
    fd_step: Optional[float] = None,
    shard: Optional[ShardSpec] = None,
    stop: Optional[Stop] = None,
) -> Dict[str, Any]:
    """``geosens rod --json``: I, ∂I/∂length (and ∂I/∂x) at a probe on a rod.

    Args:
        method: ``"exact"`` (the Bellman–Wing solution, nothing sampled) or
            one of intensity, expectation, rendering, transport, fd.
        ks: scattering coefficient κs ≥ 0.
        ke: extinction coefficient κe ≥ κs.
        length: the rod's length π̃ > 0, the shape parameter.
        x: probe position, 0 ≤ x ≤ length.
        omega: probe direction, 1 (right) or -1 (left).
        paths: paths of the run (at least 2, checked for ``exact`` too).
        seed: seed of the random streams.
        threads: worker threads, 0 = all cores (results do not depend on it).
            ``paths``, ``seed``, ``threads`` and ``shard``'s numbers take any
            integer (numpy's too: anything with ``__index__``), not a bool
            or a float.
        fd_step: half step of ``fd`` (relative to the length).
        shard: ``(i, n)``: run shard i of n and return its state.
        stop: a :class:`threading.Event` or a callable, looked at every
            50 ms: once set (true), the run ends at its next chunk and
            raises ``KeyboardInterrupt``. Ctrl-C reaches runs called from
            the main thread only; ``stop`` stops one called from another.

    Returns:
        ``{"method", "intensity", "sensitivity", "gradient_x", "paths",
        "seconds"}``, each quantity ``{"mean", "stderr", "nonzero",
        "reliable"}`` (``fd``'s derivative also ``"jumps"``) or None if the
        method does not estimate it; or, with
        ``shard``, the shard's state.

    Raises:
        ValueError: bad input, with the command line's message.
    """
    return _result(
        _geosens.rod(
            method,
            _real("ks", ks),
            _real("ke", ke),
            _real("length", length),
            _real("x", x),
            _real("omega", omega),
            _uint("paths", paths),
            _uint("seed", seed),
            _uint("threads", threads),
            _fd_step(fd_step),
            _shard(shard),
            _stop(stop),
        )
    )


def _scene_run(
    mesh: bool,
    scene: Scene,
    method: str,
    paths: int,
    seed: int,
    threads: int,
    fd_step: Optional[float],
    shard: Optional[ShardSpec],
    stop: Optional[Stop],
) -> Dict[str, Any]:
    path, text = _scene(scene)
    return _result(
        _geosens.scene(
            mesh,
            path,
            text,
            method,
            _uint("paths", paths),
            _uint("seed", seed),
            _uint("threads", threads),
            _fd_step(fd_step),
            _shard(shard),
            _stop(stop),
        ),
        # user → flat/mesh → _scene_run → _result
        stacklevel=4,
    )


def flat(
    scene: Scene,
    method: str,
    *,
    paths: int = 1_000_000,
    seed: int = 1,
    threads: int = 0,
    fd_step: Optional[float] = None,
    shard: Optional[ShardSpec] = None,
    stop: Optional[Stop] = None,
) -> Dict[str, Any]:
    """``geosens flat --json``: I and every ∂I/∂π of a flatland scene.

    Args:
        scene: a scene file (TOML or JSON) or a dict of its schema.
        method: intensity, expectation, rendering, transport or fd.
        paths, seed, threads, fd_step, shard, stop: as for :func:`rod`.

    Returns:
        ``{"method", "intensity", "sensitivity": {param: …}, "gradient"
        (transport's ∂I/∂x, ∂I/∂y, else None), "paths", "seconds"}``; or,
        with ``shard``, the shard's state.

    Raises:
        ValueError: bad input, with the command line's message.
    """
    return _scene_run(False, scene, method, paths, seed, threads, fd_step, shard, stop)


def mesh(
    scene: Scene,
    method: str,
    *,
    paths: int = 1_000_000,
    seed: int = 1,
    threads: int = 0,
    fd_step: Optional[float] = None,
    shard: Optional[ShardSpec] = None,
    stop: Optional[Stop] = None,
) -> Dict[str, Any]:
    """``geosens mesh --json``: I and every ∂I/∂π of a 3D scene.

    As :func:`flat`; transport's gradient has the axes x, y, z.
    """
    return _scene_run(True, scene, method, paths, seed, threads, fd_step, shard, stop)


def render(
    scene: Scene,
    method: str,
    *,
    spp: int = 64,
    seed: int = 1,
    threads: int = 0,
    fd_step: Optional[float] = None,
    shard: Optional[ShardSpec] = None,
    stop: Optional[Stop] = None,
) -> Dict[str, Any]:
    """``geosens render``: every pixel of a camera scene (3D, or flatland's
    line camera), ``spp`` paths per pixel; ``seed``, ``threads``,
    ``fd_step``, ``shard`` and ``stop`` as for :func:`rod` (a stopped
    rendering ends at its next pixel).

    Returns:
        The command line's JSON line (``"method"``, ``"I"``,
        ``"sensitivity"``: the images' mean pixel values with their standard
        errors, ``"width"``, ``"height"``, ``"paths"``, ``"seconds"``) and
        ``"images"``: ``{"I": {"mean": array, "stderr": array}, param: {…},
        …}``, float64 arrays of shape (height, width), row 0 at the top (the
        command line's ``I.npy``, ``I_stderr.npy``, ``d_<param>.npy``, …);
        or, with ``shard`` (a share of the pixels, row by row from the top:
        a single row splits too), the shard's state.

    Raises:
        ValueError: bad input, with the command line's message.
    """
    path, text = _scene(scene)
    return _result(
        _geosens.render(
            path,
            text,
            method,
            _uint("spp", spp),
            _uint("seed", seed),
            _uint("threads", threads),
            _fd_step(fd_step),
            _shard(shard),
            _stop(stop),
        )
    )


def merge(states: Sequence[StateLike]) -> Dict[str, Any]:
    """``geosens merge``: the states of every shard of one run, in any
    order, merged into what the single run returns, bit for bit (for a
    rendering, with its images); ``"seconds"`` is the sum of the shards'.

    Args:
        states: each a state dict (what a function returns with
            ``shard``), its JSON text, or a state file written by the command
            line's ``--state``. A ``str`` that does not start with ``{`` is a
            file.

    Raises:
        ValueError: the states are not every shard of one run, each once
            (the message names them: a file by its path, others as
            ``states[k]``).
    """
    if isinstance(states, (str, dict, os.PathLike)):
        raise ValueError("merge takes a list of states")
    items = []
    for k, s in enumerate(states):
        if isinstance(s, dict):
            items.append((f"states[{k}]", None, json.dumps(s)))
        elif isinstance(s, str) and s.lstrip().startswith("{"):
            items.append((f"states[{k}]", None, s))
        elif isinstance(s, (str, os.PathLike)):
            items.append((os.fspath(s), os.fspath(s), None))
        else:
            raise ValueError(
                f"states[{k}]: a state is a dict, JSON text or a file, "
                f"not {type(s).__name__}"
            )
    return _result(_geosens.merge(items))


def optimize(
    scene: Scene,
    method: str,
    *,
    optimizer: str = "adam",
    iterations: int = 100,
    paths_per_step: int = 16384,
    step: float = 0.02,
    batches: int = 8,
    fd_step: Optional[float] = None,
    tolerance: float = 0.0,
    seed: int = 1,
    threads: int = 0,
    progress: Optional[Callable[[Dict[str, Any]], Any]] = None,
    stop: Optional[Stop] = None,
) -> List[Dict[str, Any]]:
    """``geosens optimize --json``: an inverse problem or a design by
    stochastic gradient descent on a scene's parameters, from the scene's
    pose; one record per iteration, the command line's JSON lines parsed
    (identical for the same seed but for the ``"seconds"`` keys).

    Args:
        scene: a scene file (TOML or JSON) or a dict of its schema, flatland
            or 3D (by its points), with ``measurements`` (a list of dicts:
            a sensor with ``target``, ``weight`` or ``sigma``), an
            ``objective`` (``{"kind": "least_squares"}``, ``"maximize"`` or
            ``"minimize"``) and parameters, optionally with ``bounds``
            (offsets from the pose).
        method: the method that estimates the gradient: expectation,
            rendering, transport or fd (intensity: the loss only).
        optimizer: ``"adam"`` or ``"sgd"`` (gradient descent with a
            decreasing step).
        iterations: iterations at most (records: one more, iteration 0 is
            the start).
        paths_per_step: paths per measurement (a camera's: per pixel) and
            iteration.
        step: the first step: Adam's in parameter units (scene units,
            radians), gradient descent's multiplier of the gradient.
        batches: independent batches the paths split into (at least 2:
            the gradient's products are taken between them, so it is
            unbiased).
        fd_step: the finite differences' half step (``method="fd"``).
        tolerance: stop once no parameter moves more than this in a step
            (0: never).
        seed, threads: as for :func:`rod`; the records do not depend on
            ``threads``.
        progress: called with each record as it is made, on the calling
            thread (a notebook's live plot); returning ``False`` (not
            merely a false value) ends the run after that record, and an
            exception it raises ends it and propagates.
        stop: as for :func:`rod`; Ctrl-C and ``stop`` end the run after
            the iteration under way, and the ``KeyboardInterrupt`` raised
            carries the records made before as its ``records`` attribute.

    Returns:
        The records: ``{"iteration", "parameters": {name: offset},
        "average": {name: offset}`` (the mean iterate over the last half of
        the run so far, the answer to report), ``"loss": {"mean",
        "stderr"}, "gradient": {name: {"mean", "stderr"}},
        "paths", "seconds", "sampling_seconds"}`` and ``"notes"`` (what a
        step did beyond the rule: clamped to bounds, shortened to keep the
        scene valid) when there are any.

    Raises:
        ValueError: bad input, with the command line's message (a missing
            ``target``, reversed ``bounds``, …).
    """
    path, text = _scene(scene)
    records: List[Dict[str, Any]] = []

    def each(line: str) -> bool:
        record = json.loads(line)
        records.append(record)
        return progress is None or progress(record) is not False

    try:
        _geosens.optimize(
            path,
            text,
            method,
            optimizer,
            _uint("iterations", iterations),
            _uint("paths_per_step", paths_per_step),
            _real("step", step),
            _uint("batches", batches),
            _fd_step(fd_step),
            _real("tolerance", tolerance),
            _uint("seed", seed),
            _uint("threads", threads),
            each,
            _stop(stop),
        )
    except KeyboardInterrupt as e:
        e.records = records  # type: ignore[attr-defined]
        raise
    return records
