"""Counts, seeds, thread counts and shards take any integer: numpy's
(``np.int64``, what a sweep over ``np.arange`` hands over) and anything with
``__index__``, giving the result of the same plain ``int`` bit for bit. A
bool, a float (numpy's too, even ``3.0``) and an integer outside 0 to
2^64 - 1 are still refused with a ValueError naming the argument."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import SCENES, assert_same, image_bytes

import geosens

OCC = SCENES / "occluder.toml"
LINE = SCENES / "camera_line.toml"


class Count:
    """An integer-like object that is not an int: only ``__index__``."""

    def __init__(self, n: int) -> None:
        self.n = n

    def __index__(self) -> int:
        return self.n


@pytest.mark.parametrize("kind", [np.int64, np.uint32, np.int16, Count])
def test_integer_likes_are_their_ints(kind):
    plain = geosens.flat(OCC, "expectation", paths=20_000, seed=7, threads=2)
    given = geosens.flat(
        OCC, "expectation", paths=kind(20_000), seed=kind(7), threads=kind(2)
    )
    assert_same(plain, given)
    plain = geosens.rod("exact", 0.07, 0.1, 2, 1, 1, paths=1000, seed=3)
    given = geosens.rod(
        "exact", 0.07, 0.1, 2, 1, 1, paths=kind(1000), seed=kind(3), threads=kind(1)
    )
    assert_same(plain, given)


def test_numpy_counts_in_render_and_shards():
    a = geosens.render(LINE, "rendering", spp=16, seed=5, threads=1)
    b = geosens.render(LINE, "rendering", spp=np.int64(16), seed=np.uint64(5), threads=np.int32(1))
    assert_same(a, b)
    assert image_bytes(a) == image_bytes(b)
    shards = [
        geosens.flat(OCC, "expectation", paths=np.int64(200_000), shard=(np.int64(i), np.int64(2)))
        for i in np.arange(1, 3)
    ]
    whole = geosens.flat(OCC, "expectation", paths=200_000)
    assert_same(geosens.merge(shards), whole)


@pytest.mark.parametrize(
    "value", [True, np.True_, 3.0, np.float64(3.0), "3", np.int64(-1), -1, 2**64, None]
)
def test_what_is_not_a_count_is_refused(value):
    with pytest.raises(ValueError, match=r"for paths: expected an integer from 0 to 2\^64 - 1"):
        geosens.flat(OCC, "expectation", paths=value)
