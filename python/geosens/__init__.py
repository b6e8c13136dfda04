"""Monte Carlo estimates of intensity and geometric sensitivities.

The Python face of the geosens command line: each function runs what its
subcommand runs and returns what ``--json`` prints, parsed::

    >>> import geosens
    >>> r = geosens.rod("expectation", 0.07, 0.1, 2.0, 1.0, 1.0, paths=100_000)
    >>> r["sensitivity"]["length"]["mean"], r["sensitivity"]["length"]["stderr"]

- :func:`rod`, :func:`flat`, :func:`mesh` return the numbers of the
  command line's JSON line (``geosens rod|flat|mesh ... --json``), identical
  bit for bit for the same seed but for ``"seconds"``, in one layout for
  all three: ``{"method", "intensity", "sensitivity": {parameter: q},
  "gradient": {axis: q} or None, "paths", "seconds"}``, each quantity ``q``
  a dict ``{"mean", "stderr", "nonzero", "reliable"}`` (the rod's one
  parameter is ``"length"``, its one axis ``"x"``);
- :func:`render` returns the JSON line of ``geosens render`` (``"intensity"``
  and ``"sensitivity"`` as above: the images' mean pixel values) with the
  images added under ``"images"`` as float64 arrays of shape (height, width);
- :func:`arrays` turns a list of results (a sweep) into arrays: each
  quantity's means and standard errors;
- :func:`rod_exact`, :func:`flat_exact` and :func:`mesh_exact` give the
  closed forms (the rod's Bellman–Wing solution along the rod, flatland's
  and 3D's occluder scenes), in the same layout, nothing sampled;
- :func:`from_json` reads a line the command line printed into the same
  layout;
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
caveats are issued as :class:`RuntimeWarning`, at the caller's line. The GIL is released while
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
import sys
import threading
import warnings
from typing import Any, Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _geosens

__all__ = [
    "rod",
    "flat",
    "mesh",
    "render",
    "merge",
    "optimize",
    "arrays",
    "Series",
    "rod_exact",
    "flat_exact",
    "mesh_exact",
    "from_json",
    "__version__",
]

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


#: The package's folder: frames of files in it are not the caller's.
_HERE = os.path.dirname(os.path.abspath(__file__))


def _warn(message: str, category: type) -> None:
    """Issues a warning at the first line outside this package up the
    stack, the user's, however deep in the package it was raised (a fixed
    ``stacklevel`` is right for one call depth only)."""
    frame: Optional[Any] = sys._getframe(1)
    level = 2  # the frame of _warn's caller
    while frame is not None and os.path.dirname(
        os.path.abspath(frame.f_code.co_filename)
    ) == _HERE:
        frame = frame.f_back
        level += 1
    warnings.warn(message, category, stacklevel=level)


#: The rod's one shape parameter and one axis, as its results name them.
_ROD_PARAMETER = "length"
_ROD_AXIS = "x"
#: The keys of a quantity, which a rod result's ``"sensitivity"`` had
#: before it became ``{"length": quantity}``.
_QUANTITY_KEYS = ("mean", "stderr", "nonzero", "reliable", "jumps", "caveat")


class _Result(dict):
    """A result: a plain dict, but for the keys of the earlier layout, which
    still read (through :meth:`_old`) with a :class:`DeprecationWarning`
    at the caller's line. Old keys are not listed, iterated or saved."""

    def _old(self, key: Any) -> Optional[Tuple[str, str, Any]]:
        """The old ``key``'s spelling, its new one and its value, or None."""
        return None

    def __missing__(self, key: Any) -> Any:
        old = self._old(key)
        if old is None:
            raise KeyError(key)
        spelling, new, value = old
        _warn(f"the earlier layout's key {spelling}: use {new}", DeprecationWarning)
        return value

    def get(self, key: Any, default: Any = None) -> Any:
        if key in self or self._old(key) is not None:
            return self[key]
        return default


class _RodResult(_Result):
    """A rod's result: ``"gradient_x"`` was ``result["gradient"]["x"]``."""

    def _old(self, key: Any) -> Optional[Tuple[str, str, Any]]:
        if key != "gradient_x":
            return None
        g = dict.get(self, "gradient")
        return ('r["gradient_x"]', 'r["gradient"]["x"]', None if g is None else g[_ROD_AXIS])


class _RodSensitivity(_Result):
    """A rod's ``"sensitivity"``: ``{"length": quantity}``, which was the
    quantity itself (``r["sensitivity"]["mean"]``)."""

    def _old(self, key: Any) -> Optional[Tuple[str, str, Any]]:
        q = dict.get(self, _ROD_PARAMETER)
        if key not in _QUANTITY_KEYS or q is None or key not in q:
            return None
        return (f'r["sensitivity"]["{key}"]', f'r["sensitivity"]["length"]["{key}"]', q[key])


class _RenderResult(_Result):
    """A rendering's result: ``"I"`` is ``"intensity"``, as elsewhere."""

    def _old(self, key: Any) -> Optional[Tuple[str, str, Any]]:
        if key != "I" or "intensity" not in self:
            return None
        return ('r["I"]', 'r["intensity"]', dict.__getitem__(self, "intensity"))


def _uniform(line: Dict[str, Any]) -> Dict[str, Any]:
    """The command line's JSON line in the package's one layout: the rod's
    ``"sensitivity"`` (a quantity, or null) becomes ``{"length": q}`` (or
    ``{}``) and its ``"gradient_x"`` ``"gradient": {"x": q}`` (or None), as
    flatland and 3D give them; a rendering's ``"I"`` becomes
    ``"intensity"``. Other dicts (a shard's state) are returned as they are."""
    if "gradient_x" in line and "gradient" not in line:
        rod = _RodResult()
        for key, value in line.items():
            if key == "sensitivity":
                rod[key] = _RodSensitivity({} if value is None else {_ROD_PARAMETER: value})
            elif key == "gradient_x":
                rod["gradient"] = None if value is None else {_ROD_AXIS: value}
            else:
                rod[key] = value
        return rod
    if "I" in line and "intensity" not in line and "width" in line:
        return _RenderResult(("intensity" if k == "I" else k, v) for k, v in line.items())
    return line


def from_json(line: Union[str, bytes, Dict[str, Any]]) -> Dict[str, Any]:
    """A line the command line printed (``geosens rod|flat|mesh ... --json``,
    ``geosens render``, ``geosens merge``), as JSON text or already parsed,
    in the layout the package's functions return (a rendering: without its
    images, which are files).

    Raises:
        ValueError: the text is not JSON.
    """
    if isinstance(line, (str, bytes)):
        line = json.loads(line)
    if not isinstance(line, dict):
        raise ValueError(f"a result line is a JSON object, not {type(line).__name__}")
    return _uniform(line)


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


def _result(outcome: Tuple[str, str, List[str], list]) -> Dict[str, Any]:
    """The Python result of a Rust call: its JSON parsed into the one
    layout, its warnings issued at the user's line, a rendering's images as
    arrays."""
    kind, text, warns, images = outcome
    for w in warns:
        _warn(w.removeprefix("warning: "), RuntimeWarning)
    result = _uniform(json.loads(text)) if kind != "state" else json.loads(text)
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
        ``{"method", "intensity", "sensitivity": {"length": q}, "gradient":
        {"x": q}, "paths", "seconds"}``, the layout of :func:`flat`'s, each
        quantity ``q`` a dict ``{"mean", "stderr", "nonzero", "reliable"}``
        (``fd``'s derivative also ``"jumps"``, a caveated one ``"caveat"``);
        ``"sensitivity"`` is ``{}`` for ``intensity``, ``"gradient"`` None
        but for ``transport`` and ``exact``. Or, with ``shard``, the shard's
        state. The keys of the earlier layout (``r["sensitivity"]["mean"]``,
        ``r["gradient_x"]``) still read, with a DeprecationWarning.

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
        )
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
        ``{"method", "intensity": q, "sensitivity": {param: q}, "gradient":
        {"x": q, "y": q} (transport's ∂I/∂x, ∂I/∂y, else None), "paths",
        "seconds"}``, each ``q`` as for :func:`rod`; or, with ``shard``, the
        shard's state.

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
        The command line's JSON line (``"method"``, ``"intensity"`` (the
        line's ``"I"``, which still reads, with a DeprecationWarning) and
        ``"sensitivity"``: the images' mean pixel values with their standard
        errors, as :func:`flat` gives them; ``"width"``, ``"height"``,
        ``"paths"``, ``"seconds"``) and
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
    items: List[Tuple[str, Optional[str], Optional[str]]] = []
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


class Series(NamedTuple):
    """One quantity over a list of results: its means and standard errors,
    float64 arrays with one entry per result (a rendering's images: one
    image per result, shape (n, height, width)). Unpacks as ``mean, stderr
    = series``."""

    mean: np.ndarray
    stderr: np.ndarray


#: A value missing from a result (None is a value: "not estimated").
_MISSING = object()


def _is_quantity(value: Any) -> bool:
    return isinstance(value, dict) and "mean" in value and "stderr" in value


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float, np.number)) and not isinstance(value, (bool, np.bool_))


def _kind(value: Any) -> str:
    """What :func:`arrays` makes of a value: a quantity, a dict to walk, a
    number, None, or something else (text, flags, lists: left out)."""
    if value is None:
        return "None (not estimated)"
    if _is_quantity(value):
        return "a quantity"
    if isinstance(value, dict):
        return "a dict"
    if _is_number(value):
        return "a number"
    return "other"


def _stack(items: List[Dict[str, Any]], where: str) -> Dict[str, Any]:
    """:func:`arrays` on dicts found at the same place ``where`` of each
    result."""
    out: Dict[str, Any] = {}
    for key in items[0]:
        values = [dict.get(item, key, _MISSING) for item in items]
        at = f"{where}[{key!r}]"
        kinds = [None if v is _MISSING else _kind(v) for v in values]
        if kinds[0] == "other":
            continue
        for k, kind in enumerate(kinds):
            if kind is None:
                raise ValueError(f"arrays: results[{k}] has no {at}, results[0] has")
            if kind != kinds[0]:
                raise ValueError(
                    f"arrays: results[{k}]{at} is {kind} where results[0]'s is {kinds[0]}"
                )
        if kinds[0] == "a quantity":
            out[key] = Series(
                np.array([v["mean"] for v in values], dtype=np.float64),
                np.array([v["stderr"] for v in values], dtype=np.float64),
            )
        elif kinds[0] == "a dict":
            out[key] = _stack(values, at)
        elif kinds[0] == "a number":
            out[key] = np.array(values)
        else:
            out[key] = None
    return out


def arrays(results: Union[Dict[str, Any], Sequence[Dict[str, Any]]]) -> Dict[str, Any]:
    """A list of results (a sweep: one result per point) as arrays, in the
    layout of one result: where a result holds a quantity (a dict with
    ``"mean"`` and ``"stderr"``), a :class:`Series` of its means and
    standard errors; where it holds a number (``"paths"``, ``"seconds"``,
    an optimisation record's ``"parameters"``), an array of them; None
    where no result estimates the quantity. Text and flags are left out.
    Works on what :func:`rod`, :func:`flat`, :func:`mesh`, :func:`render`
    and :func:`merge` return and on :func:`optimize`'s records::

        rs = [geosens.rod("expectation", 2.1, 3.0, 2.0, x, -1, seed=i)
              for i, x in enumerate(xs)]
        s, err = geosens.arrays(rs)["sensitivity"]["length"]
        plt.errorbar(xs, s, err)

    A single result gives arrays of one entry.

    Raises:
        ValueError: the results do not hold the same quantities (another
            scene's parameters, a method that does not estimate one of
            them); the message names the first that differs.
    """
    items = [results] if isinstance(results, dict) else list(results)
    if not items:
        raise ValueError("arrays: no results")
    for k, r in enumerate(items):
        if not isinstance(r, dict):
            raise ValueError(f"arrays: results[{k}] is not a result dict ({type(r).__name__})")
    return _stack(items, "")


def _closed(closed: Tuple[float, List[Tuple[str, float]], Optional[List[Tuple[str, float]]]]) -> Dict[str, Any]:
    intensity, sensitivity, gradient = closed
    return {
        "intensity": intensity,
        "sensitivity": dict(sensitivity),
        "gradient": None if gradient is None else dict(gradient),
    }


def rod_exact(
    ks: float, ke: float, length: float, x: Any, omega: float
) -> Dict[str, Any]:
    """The rod's exact (Bellman–Wing) solution at ``x``: a position, or a
    sequence or array of them (the curve along the rod), in the layout of
    :func:`rod`'s result with numbers for quantities::

        {"intensity": I, "sensitivity": {"length": ∂I/∂length},
         "gradient": {"x": ∂I/∂x}}

    each a float, or for a sequence ``x`` a float64 array of its shape.
    ``ks``, ``ke``, ``length``, ``omega`` as for :func:`rod`. The numbers
    are those of ``rod("exact", …)`` and of ``geosens rod --method exact``.

    Raises:
        ValueError: bad input (an ``x`` off the rod, ``omega`` not ±1), with
            the command line's message.
    """
    scalar = np.ndim(x) == 0
    if scalar:
        xs = [_real("x", x)]
        shape: Tuple[int, ...] = ()
    else:
        try:
            grid = np.asarray(x, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"invalid value {x!r} for x: expected numbers") from None
        xs, shape = grid.ravel().tolist(), grid.shape
    i, s, g = _geosens.rod_exact(
        _real("ks", ks), _real("ke", ke), _real("length", length), xs, _real("omega", omega)
    )
    pick = (lambda v: v[0]) if scalar else (lambda v: np.array(v, dtype=np.float64).reshape(shape))
    return {
        "intensity": pick(i),
        "sensitivity": {_ROD_PARAMETER: pick(s)},
        "gradient": {_ROD_AXIS: pick(g)},
    }


def flat_exact(scene: Scene) -> Dict[str, Any]:
    """The closed form of a flatland scene (a file or a dict, as for
    :func:`flat`), where one exists: an irradiance sensor, one emitter
    segment, black absorbers and at most one purely absorbing medium,
    nothing else (the medium's by quadrature to ~1e-8). In the layout of
    :func:`flat`'s result with numbers for quantities::

        {"intensity": E, "sensitivity": {param: ∂E/∂π},
         "gradient": {"x": ∂E/∂x, "y": ∂E/∂y}}

    Raises:
        ValueError: bad input, or a scene without a closed form (the message
            says why: a reflector, a scattering medium, a radiance sensor…).
    """
    path, text = _scene(scene)
    return _closed(_geosens.scene_exact(False, path, text))


def mesh_exact(scene: Scene) -> Dict[str, Any]:
    """The closed form of a 3D scene (a file or a dict, as for
    :func:`mesh`), where one exists: an irradiance sensor, one emitter that
    is a flat convex polygon, and at most one black occluder, convex (a flat
    polygon, or a closed body such as a box) and lying strictly between the
    sensor and the emitter's plane; parameters move the occluder (or the
    emitter, when there is no occluder). As :func:`flat_exact`, but
    ``"gradient"`` is None (the closed form does not give ∂E/∂x).

    Raises:
        ValueError: bad input, or a scene without a closed form, saying why.
    """
    path, text = _scene(scene)
    return _closed(_geosens.scene_exact(True, path, text))


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
