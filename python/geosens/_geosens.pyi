# The Rust module (python/src/lib.rs); `geosens/__init__.py` wraps it.
# rod_exact: I, ∂I/∂length, ∂I/∂x at each x; scene_exact: (I, [(parameter,
# ∂I/∂π)], [(axis, ∂I/∂x)] or None in 3D).
from typing import Any, Callable, List, Optional, Tuple

# (kind, JSON text, warnings, images): kind is "report", "image" or "state";
# an image is (key, height, width, mean bytes, stderr bytes), native float64.
_Outcome = Tuple[str, str, List[str], List[Tuple[str, int, int, bytes, bytes]]]

__version__: str

def rod(
    method: str, ks: float, ke: float, length: float, x: float, omega: float,
    paths: int, seed: int, threads: int, fd_step: Optional[float],
    shard: Optional[Tuple[int, int]], stop: Optional[Callable[[], Any]],
) -> _Outcome: ...
def scene(
    mesh: bool, path: Optional[str], json: Optional[str], method: str, paths: int,
    seed: int, threads: int, fd_step: Optional[float], shard: Optional[Tuple[int, int]],
    stop: Optional[Callable[[], Any]],
) -> _Outcome: ...
def render(
    path: Optional[str], json: Optional[str], method: str, spp: int, seed: int,
    threads: int, fd_step: Optional[float], shard: Optional[Tuple[int, int]],
    stop: Optional[Callable[[], Any]],
) -> _Outcome: ...
def merge(states: List[Tuple[str, Optional[str], Optional[str]]]) -> _Outcome: ...
def optimize(
    path: Optional[str], json: Optional[str], method: str, optimizer: str,
    iterations: int, paths_per_step: int, step: float, batches: int,
    fd_step: Optional[float], tolerance: float, seed: int, threads: int,
    each: Optional[Callable[[str], Any]], stop: Optional[Callable[[], Any]],
) -> List[str]: ...
def rod_exact(
    ks: float, ke: float, length: float, xs: List[float], omega: float,
) -> Tuple[List[float], List[float], List[float]]: ...
def scene_exact(
    mesh: bool, path: Optional[str], json: Optional[str],
) -> Tuple[float, List[Tuple[str, float]], Optional[List[Tuple[str, float]]]]: ...
