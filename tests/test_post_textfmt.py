"""The vectorised xyz formatting is byte-identical to printf ``%.5f`` (FibreNet's files)."""

from __future__ import annotations

import numpy as np
import pytest

from fibrelmp.translate.fibrenet.writer import _rows, xyz_frame, xyz_frame_bytes
from fibrelmp.numtext.printf import fixed_chars

EDGES = [0.0, -0.0, 0.015625, -0.015625, 5e-6, -5e-6, 1.5e-5, 2.5e-5, 1e-6, -1e-6, 1000.000005,
         99999.999995, 0.000015, 123.456785, -7.5e-6, 0.5, 2.5, 1e10, -1e10 + 0.5, 12345678.123455,
         2.0 ** 30 + 0.125, 4.4999999999999996e-06]


def _values(seed: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.concatenate([
        rng.normal(size=n) * 10 ** rng.uniform(-9, 7, n),
        np.round(rng.normal(size=n) * 1000, 6),                     # decimal ties at the 6th digit
        (rng.integers(-10 ** 9, 10 ** 9, n) + 0.5) / 1e5,
        rng.integers(-10 ** 7, 10 ** 7, n) / 64.0,                   # exact binary ties
        np.array(EDGES)])


@pytest.mark.parametrize("decimals", [0, 1, 3, 5])
def test_fixed_chars_equals_printf(decimals):
    vals = _values(decimals, 20000)
    chars = fixed_chars(vals, decimals)
    got = [row.tobytes().replace(b"\0", b"").decode() for row in chars]
    want = [f"%.{decimals}f" % v for v in vals.tolist()]
    bad = [(v, g, w) for v, g, w in zip(vals.tolist(), got, want) if g != w]
    assert not bad, bad[:5]


def test_fixed_chars_declines_what_it_cannot_do_exactly():
    assert fixed_chars(np.array([1.0, np.nan]), 5) is None
    assert fixed_chars(np.array([1e12]), 5) is None


def test_xyz_frame_is_byte_identical_to_percent_formatting():
    rng = np.random.default_rng(7)
    vals = _values(9, 3000)
    vals = vals[: len(vals) // 3 * 3].reshape(-1, 3)
    names = np.array(rng.choice(["F1", "Fibre_2", "x", "é"], len(vals)), dtype=object)
    lengths = np.array([7.0, 7.123456, 1e3])
    for v in (vals, np.where(rng.random(vals.shape) < 0.01, np.nan, vals)):   # nan: the % path
        want = (f"{len(v)}\nFRAME\t42\t{0.001:.5f}\t{lengths[0]:.5f}\t{lengths[1]:.5f}\t{lengths[2]:.5f}\n"
                + _rows("%s\t%.5f\t%.5f\t%.5f\n", names, v))
        assert xyz_frame(42, 0.001, lengths, names, v) == want
    assert xyz_frame_bytes(0, 0.0, lengths, np.zeros(0, int), [], np.zeros((0, 3))) == \
        b"0\nFRAME\t0\t0.00000\t7.00000\t7.12346\t1000.00000\n"
