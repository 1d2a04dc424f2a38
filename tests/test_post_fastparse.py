"""The optional C parser/formatter (fibrelmp.numtext.fast) against numpy / printf."""

from __future__ import annotations

import io

import numpy as np
import pytest

from fibrelmp.errors import InputError
from fibrelmp.numtext import fast as fastparse
from fibrelmp.translate.fibrenet.writer import xyz_frame_bytes
from fibrelmp.post.lammps_dump.reader import Header, parse_block

needs_c = pytest.mark.skipif(fastparse.library() is None, reason="no C compiler: fast path unavailable")


def _loadtxt(block: bytes) -> np.ndarray:
    return np.loadtxt(io.BytesIO(block), dtype=np.float64, comments=None, ndmin=2)


def _random_tokens(rng, n: int) -> list[str]:
    mags = 10.0 ** rng.integers(-330, 308, n).astype(float)
    x = np.clip(rng.standard_normal(n), -1.7, 1.7) * mags
    x[rng.random(n) < 0.1] = 0.0
    small = rng.standard_normal(n) * 10.0 ** rng.integers(-8, 8, n)
    fmts = ["%g", "%.17g", "%e", "%.3e", "%.10f", "%r", "%.6g", "%d", "%E", "%.20g"]
    out = []
    for k in range(n):
        f = fmts[k % len(fmts)]
        v = x[k] if k % 3 else small[k]
        if f == "%d":
            out.append("%d" % int(rng.integers(-10 ** 18, 10 ** 18)))
        elif f == "%r":
            out.append(repr(float(v)))
        elif f == "%.10f" and abs(v) > 1e30:
            out.append("%.10f" % small[k])
        else:
            out.append(f % v)
    return out


def _head(n: int, ncol: int) -> Header:
    return Header(0, n, np.zeros(3), np.ones(3), ("pp",) * 3, [f"c{k}" for k in range(ncol)], 1,
                  extra={"header_lines": 9})


@needs_c
@pytest.mark.parametrize("seed", range(4))
def test_random_numbers_bit_identical(seed):
    rng = np.random.default_rng(seed)
    ncol = 7
    toks = _random_tokens(rng, 7 * 3000)
    # hand-picked awkward ones
    toks[:24] = ["0", "-0", "+1", ".5", "5.", "-.5e-3", "1e22", "1e23", "9007199254740993",
                 "123456789012345678901234567890", "4.9e-324", "2.4703282292062328e-324",
                 "1.7976931348623157e308", "1e-400", "0.000000000000000000000000001234",
                 "00012.500", "1E+05", "-2.5E-05", "3.0000000000000004", "0.1", "0.30000000000000004",
                 "2.2250738585072011e-308", "1.00000000000000011102230246251565404236316680908203125",
                 "7.2057594037927933e16"]
    rows = [" ".join(toks[i:i + ncol]) for i in range(0, len(toks), ncol)]
    block = ("\n".join(rows) + "\n").encode()
    got = fastparse.parse_numbers(block, len(rows), ncol)
    ref = _loadtxt(block)
    assert got is not None
    assert got.tobytes() == ref.tobytes()
    assert np.array_equal(got.ravel().view(np.int64), np.array([float(t) for t in toks]).view(np.int64))


@needs_c
def test_digit_runs_of_every_length_at_every_place():
    """The digit runs are read eight bytes at a time where eight are readable: runs of 0-24
    digits before and after the point, followed by every kind of byte that may end them
    (separator, point, exponent, the buffer's end), one row per token so that each run also
    meets the end of the buffer, against float()."""
    rng = np.random.default_rng(3)
    toks = []
    for a in range(0, 25):
        for b in [None, *range(0, 25)]:
            if a == 0 and not b:
                continue
            whole = "".join(str(d) for d in rng.integers(0, 10, a))
            frac = None if b is None else "".join(str(d) for d in rng.integers(0, 10, b))
            tok = whole + ("" if frac is None else "." + frac)
            toks += [tok, "-" + tok, tok + "e-3", tok + "E+2"]
    for tok in toks:
        for end in (b"", b"\n", b" \n", b"\t\n"):
            block = tok.encode() + end
            got = fastparse.parse_numbers(block, 1, 1)
            want = float(tok)
            assert got is not None and got[0, 0] == want and np.signbit(got[0, 0]) == np.signbit(want), tok
    block = ("\n".join(toks) + "\n").encode()
    got = fastparse.parse_numbers(block, len(toks), 1)
    assert got is not None and got.ravel().view(np.int64).tolist() == \
        np.array([float(t) for t in toks]).view(np.int64).tolist()


@needs_c
def test_split_across_threads_matches(monkeypatch):
    monkeypatch.setattr(fastparse, "SPLIT_BYTES", 64)
    rng = np.random.default_rng(9)
    x = rng.standard_normal((5000, 4)) * 1e3
    block = "".join("%d %g %.17g %e\n" % (k, a, b, c) for k, (a, b, c, _) in enumerate(x)).encode()
    got = fastparse.parse_numbers(block, 5000, 4)
    assert got is not None and got.tobytes() == _loadtxt(block).tobytes()
    assert fastparse.parse_numbers(block, 5001, 4) is None          # one row short
    assert fastparse.parse_numbers(block + b"1 2 3 4\n", 5000, 4) is None


@needs_c
@pytest.mark.parametrize("block", [
    b"1 2 3\n4 5 6\n",                 # plain
    b"1 2 3\r\n4 5 6\r\n",             # CRLF
    b"1\t2 3\n 4  5 6",                # tabs, no final newline
])
def test_accepted_layouts(block):
    got = fastparse.parse_numbers(block, 2, 3)
    assert got is not None and got.tobytes() == _loadtxt(block).tobytes()


@needs_c
@pytest.mark.parametrize("block", [
    b"1 2 3\n4 5\n", b"1 2 3\n4 5 6 7\n", b"1 2 3\n\n4 5 6\n", b"1 2 x\n4 5 6\n", b"1 2 nan\n4 5 6\n",
    b"1 2 inf\n4 5 6\n", b"1 2 0x10\n4 5 6\n", b"1 2 1e\n4 5 6\n", b"1 2 --1\n4 5 6\n", b"1 2 .\n4 5 6\n",
    b"1 2 1_0\n4 5 6\n", b"1 2 3\r4 5 6\n", b"1 2 3\n4 5 6\nITEM: TIMESTEP\n", b"1 2 3\n", b"1 2 +\n4 5 6\n",
    b"1 2 1.5.5\n4 5 6\n", b"1 2 3\x0b\n4 5 6\n",
])
def test_declines_the_unusual(block):
    assert fastparse.parse_numbers(block, 2, 3) is None


@pytest.mark.parametrize("block", [
    b"1 2 3\n4 5\n", b"1 2 3\n4 5 x\n", b"1 2 3\nITEM: TIMESTEP\n", b"1 2 3\n4 5 6 7\n",
])
def test_malformed_blocks_same_error_with_and_without_c(block, monkeypatch):
    head = _head(2, 3)
    with pytest.raises(InputError) as fast:
        parse_block(block, head, "d.lammpstrj")
    monkeypatch.setattr(fastparse, "library", lambda: None)
    with pytest.raises(InputError) as slow:
        parse_block(block, head, "d.lammpstrj")
    assert str(fast.value) == str(slow.value)
    assert fast.value.line == slow.value.line


def test_special_values_same_with_and_without_c(monkeypatch):
    block = b"1 2 nan\n4 -inf 6\n7 8 1e999\n"
    head = _head(3, 3)
    fast = parse_block(block, head, None)
    monkeypatch.setattr(fastparse, "library", lambda: None)
    slow = parse_block(block, head, None)
    for c in head.names:
        assert fast[c].tobytes() == slow[c].tobytes()


def test_fallback_without_library(monkeypatch):
    monkeypatch.setattr(fastparse, "library", lambda: None)
    block = b"1 2 3.5\n4 5 6e-3\n"
    assert fastparse.parse_numbers(block, 2, 3) is None
    assert fastparse.format_xyz(np.zeros(2, np.int64), ["A"], np.zeros((2, 3))) is None
    cols = parse_block(block, _head(2, 3), None)
    assert cols["c2"].tolist() == [3.5, 6e-3]
    text = xyz_frame_bytes(5, 0.001, np.ones(3), np.array([0, 1]), ["A", "BB"],
                           np.array([[1.0, -0.0, 2.5e-6], [1e6, -3.25, 7.0]]))
    assert text == (b"2\nFRAME\t5\t0.00100\t1.00000\t1.00000\t1.00000\n"
                    b"A\t1.00000\t-0.00000\t0.00000\nBB\t1000000.00000\t-3.25000\t7.00000\n")


def test_build_failure_is_silent(monkeypatch, tmp_path):
    monkeypatch.setattr(fastparse, "_lib", None)
    monkeypatch.setattr(fastparse, "_tried", False)
    monkeypatch.setattr(fastparse, "_path", fastparse._path)
    monkeypatch.setattr(fastparse, "_INSTALLED", tmp_path / "not-installed.so")   # as in a checkout
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    assert fastparse.library() is None
    assert fastparse.parse_numbers(b"1 2\n", 1, 2) is None
    assert parse_block(b"1 2\n", _head(1, 2), None)["c1"].tolist() == [2.0]


@needs_c
@pytest.mark.parametrize("seed", range(3))
def test_format_matches_printf(seed, monkeypatch):
    rng = np.random.default_rng(seed)
    n = 20000
    x = rng.standard_normal((n, 3)) * 10.0 ** rng.integers(-9, 10, (n, 3))
    # exact ties and near-ties at the 5th decimal, signed zeros, tiny negatives
    x[:8] = [[0.000005, 0.000015, 0.000025], [1.000005, -2.500005, 0.125],
             [-0.0, 0.0, -1e-9], [0.5e-5, 1.5e-5, -2.5e-5], [123.456785, 99999.999995, -0.000004999],
             [2.0 ** 30 + 0.5, -(2.0 ** 33), 1e10 + 0.000005], [3.0e5, 1.0 / 3.0, 2.0 / 3.0],
             [0.1, 0.7, 1e-5]]
    x[8:1000] = np.round(x[8:1000] * 2e5) / 2e5       # many binary-exact halves
    codes = rng.integers(0, 3, n)
    table = ["A", "bead", "Zz9"]
    ref = "".join("%s\t%.5f\t%.5f\t%.5f\n" % (table[c], *r) for c, r in zip(codes, x)).encode()
    monkeypatch.setattr(fastparse, "SPLIT_BYTES", 1 << 10)           # two-thread path
    assert fastparse.format_xyz(codes, table, x) == ref
    monkeypatch.setattr(fastparse, "SPLIT_BYTES", 1 << 40)
    assert fastparse.format_xyz(codes, table, x) == ref


@needs_c
def test_format_declines_what_it_cannot_do():
    codes = np.zeros(2, np.int64)
    for bad in (np.nan, np.inf, -np.inf, 1e17, -3e11):
        assert fastparse.format_xyz(codes, ["A"], np.array([[1.0, 2.0, 3.0], [bad, 0.0, 0.0]])) is None
    x = np.array([[np.nan, 1e20, -np.inf], [1.0, 2.0, 3.0]])
    got = xyz_frame_bytes(1, 0.5, np.ones(3), np.zeros(2, np.int64), ["A"], x)
    assert got.endswith(b"A\tnan\t100000000000000000000.00000\t-inf\nA\t1.00000\t2.00000\t3.00000\n")


@needs_c
def test_helper_thread_recreated_after_fork(monkeypatch):
    monkeypatch.setattr(fastparse, "SPLIT_BYTES", 64)
    monkeypatch.setattr(fastparse, "_pool_pid", -1)        # as seen by a forked child
    block = b"".join(b"%d 2.5 -3e-2\n" % k for k in range(1000))
    got = fastparse.parse_numbers(block, 1000, 3)
    assert got is not None and got.tobytes() == _loadtxt(block).tobytes()
    assert fastparse._pool_pid == __import__("os").getpid()
