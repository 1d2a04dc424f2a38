"""The FibreNet model reader's fast paths give the line-by-line reader's model, bit for bit.

``fast_reader`` parses the BEAD / SPRING / ANGLE blocks with the C helper of
``numtext.fast`` (``fp_parse_tagged``), or with np.loadtxt without it; anything unusual falls
back to the line-by-line reader.  All three must produce identical arrays, for clean files and
for the layouts the C helper declines or tolerates (CRLF, mixed blanks and tabs, trailing blank
lines, no final newline, number spellings)."""

from __future__ import annotations

import importlib.util
import shutil
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.numtext import fast
from fibrelmp.translate.fibrenet import fast_reader
from fibrelmp.translate.fibrenet.reader import read

from .conftest import REPO

EXAMPLE = REPO / "examples" / "fibre_network"


def _arrays(model) -> dict[str, np.ndarray]:
    out = {}
    for part in ("particles", "bonds", "angles"):
        obj = getattr(model, part)
        for f in fields(obj):
            value = getattr(obj, f.name)
            if isinstance(value, np.ndarray):
                out[f"{part}.{f.name}"] = value
    return out


def _read_three_ways(inp: Path, monkeypatch) -> dict[str, dict]:
    """{'C' | 'loadtxt' | 'slow': arrays of the model} and which path the fast reader took."""
    out = {}
    calls = {"tagged": 0, "loadtxt": 0}
    real_tagged, real_loadtxt = fast.parse_tagged, fast_reader._loadtxt

    def tagged(*args, **kw):
        result = real_tagged(*args, **kw)
        calls["tagged"] += result is not None
        return result

    def loadtxt(*args, **kw):
        calls["loadtxt"] += 1
        return real_loadtxt(*args, **kw)

    with monkeypatch.context() as m:
        m.setattr(fast, "parse_tagged", tagged)
        m.setattr(fast_reader, "_loadtxt", loadtxt)
        out["C"] = _arrays(read(inp))
    out["calls"] = calls
    with monkeypatch.context() as m:
        m.setattr(fast, "library", lambda: None)
        out["loadtxt"] = _arrays(read(inp))
    with monkeypatch.context() as m:
        m.setattr(fast_reader, "fast_read_model", lambda *a, **k: None)
        out["slow"] = _arrays(read(inp))
    return out


def _assert_same(found: dict) -> None:
    slow = found["slow"]
    for path in ("C", "loadtxt"):
        assert found[path].keys() == slow.keys()
        for name, ref in slow.items():
            got = found[path][name]
            assert got.dtype == ref.dtype and got.shape == ref.shape, (path, name)
            assert got.tobytes() == ref.tobytes(), (path, name)


def _case(tmp_path: Path, model_text: bytes | None = None) -> Path:
    folder = tmp_path / "case"
    folder.mkdir()
    shutil.copy(EXAMPLE / "input.txt", folder)
    (folder / "model.txt").write_bytes(model_text if model_text is not None
                                       else (EXAMPLE / "model.txt").read_bytes())
    return folder / "input.txt"


def test_example_network_three_ways(tmp_path, monkeypatch):
    if fast.library() is None:
        pytest.skip(f"no C helper: {fast.active_path()}")
    found = _read_three_ways(_case(tmp_path), monkeypatch)
    assert found["calls"] == {"tagged": 3, "loadtxt": 0}       # the C path did the work
    _assert_same(found)


def test_generated_network_three_ways(tmp_path, monkeypatch):
    """A large generated network (two threads per block in the C path)."""
    if fast.library() is None:
        pytest.skip(f"no C helper: {fast.active_path()}")
    spec = importlib.util.spec_from_file_location("generate_network", REPO / "examples" / "generate_network.py")
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    gen.generate(gen.parse_args(["--beads", "30000", "--out", str(tmp_path / "net")]))
    assert (tmp_path / "net" / "model.txt").stat().st_size > fast.SPLIT_BYTES
    found = _read_three_ways(tmp_path / "net" / "input.txt", monkeypatch)
    assert found["calls"] == {"tagged": 3, "loadtxt": 0}
    _assert_same(found)


def _rewrite(text: bytes, how: str) -> bytes:
    lines = text.split(b"\n")
    if how == "crlf":
        return b"\r\n".join(lines)
    if how == "tabs_and_blanks":
        return b"\n".join(ln.replace(b"\t", b" \t ") + b" \t" if ln else ln for ln in lines)
    if how == "trailing_blank_lines":
        return text.rstrip(b"\n") + b"\n\n  \n\t\n"
    if how == "no_final_newline":
        return text.rstrip(b"\n")
    if how == "number_spellings":       # same values, other spellings strtod reads alike
        out = []
        for ln in lines:
            if ln.startswith(b"BEAD"):
                t = ln.split(b"\t")
                t[4] = b"+" + t[4]                                     # radius "+0.42"
                t[9] = b"%.6e" % float(t[9])                           # vx in e-notation
                t[12] = b"-0" if float(t[12]) == 0 else t[12]          # fx "-0"
                ln = b"\t".join(t)
            out.append(ln)
        return b"\n".join(out)
    raise AssertionError(how)


@pytest.mark.parametrize("how", ["crlf", "tabs_and_blanks", "trailing_blank_lines",
                                 "no_final_newline", "number_spellings"])
def test_layout_variants_three_ways(tmp_path, monkeypatch, how):
    if fast.library() is None:
        pytest.skip(f"no C helper: {fast.active_path()}")
    text = _rewrite((EXAMPLE / "model.txt").read_bytes(), how)
    found = _read_three_ways(_case(tmp_path, text), monkeypatch)
    assert found["calls"]["tagged"] == 3, found["calls"]
    _assert_same(found)


@pytest.mark.parametrize("how", ["blank_line_inside", "huge_integer", "hex_number"])
def test_declined_layouts_still_read_identically(tmp_path, monkeypatch, how):
    """What the C helper declines (a blank line inside a block, a tag beyond 2^53 digits,
    a number strtod reads but the helper does not) goes to loadtxt or the slow reader."""
    if fast.library() is None:
        pytest.skip(f"no C helper: {fast.active_path()}")
    lines = (EXAMPLE / "model.txt").read_bytes().split(b"\n")
    if how == "blank_line_inside":
        lines.insert(5, b"")
    elif how == "huge_integer":
        t = lines[3].split(b"\t")
        t[2] = b"1" + b"0" * 25 + b".0"              # tag 1e25: not an exact integer
        lines[3] = b"\t".join(t)
    else:
        t = lines[3].split(b"\t")
        t[4] = b"0x1.ae147ae147ae1p-2"               # 0.42 in hex: loadtxt and the slow reader refuse
        lines[3] = b"\t".join(t)
    inp = _case(tmp_path, b"\n".join(lines))
    if how in ("huge_integer", "hex_number"):
        # the fast paths decline, the slow reader names the line
        from fibrelmp.errors import InputError

        with pytest.raises(InputError) as err:
            read(inp)
        assert err.value.line == 4
        return
    found = _read_three_ways(inp, monkeypatch)
    assert found["calls"]["loadtxt"] >= 1
    _assert_same(found)


def test_data_file_rows_c_and_numpy_identical(monkeypatch):
    """The C row formatter of data files (fp_format_fixed_rows) writes the numpy path's bytes:
    ints, fixed-point floats with 0..8 decimals, negative values, zeros, literal columns."""
    from fibrelmp.numtext import shortest

    if fast.library() is None:
        pytest.skip(f"no C helper: {fast.active_path()}")
    rng = np.random.default_rng(11)
    compared = 0
    for trial in range(150):
        n = 40000 if trial % 10 == 0 else int(rng.integers(1, 80))     # both thread layouts
        cols: list = [rng.integers(0, 10 ** int(rng.integers(1, 8)), size=n)]
        for _ in range(int(rng.integers(0, 7))):
            kind = int(rng.integers(0, 5))
            if kind == 0:
                cols.append(rng.integers(-10 ** int(rng.integers(1, 12)), 10 ** int(rng.integers(1, 12)), size=n))
            elif kind == 1:
                cols.append(np.round(rng.normal(0, 10.0 ** int(rng.integers(-3, 6)), size=n), int(rng.integers(0, 9))))
            elif kind == 2:
                cols.append(np.zeros(n) * -1.0)
            elif kind == 3:
                cols.append(-np.abs(np.round(rng.normal(0, 1, size=n), 3)))
            else:
                cols.append("0")
        c_text = shortest._rows_text_c(cols)
        with monkeypatch.context() as m:
            m.setattr(shortest, "_rows_text_c", lambda columns: None)
            numpy_text = shortest.rows_text(cols)
        assert c_text == numpy_text, trial
        compared += c_text is not None
    assert compared == 150


def test_restart_rows_c_and_python_identical():
    """FibreNet restart rows (\\t%g) from the C helper equal Python's % formatting, including
    zeros, -0, tiny and tie-like values; a non-finite value makes the C path decline."""
    from fibrelmp.translate.fibrenet import writer

    if fast.library() is None:
        pytest.skip(f"no C helper: {fast.active_path()}")
    rng = np.random.default_rng(2)
    for trial in range(60):
        n = 20000 if trial % 10 == 0 else int(rng.integers(1, 50))
        cols = [rng.normal(0, 10.0 ** int(rng.integers(-8, 9)), (n, 3)) for _ in range(4)]
        if trial % 3 == 0:
            cols[0] = np.round(cols[0], 5)
        if trial % 4 == 0:
            cols[1][: n // 2] = 0.0
            cols[2][:1] = -0.0
            cols[3][:1] = 1e-300
            cols[3][-1:] = 123456.5
        codes = rng.integers(0, 3, n)
        table = ["F1", "Fibre_B", "x"]
        state = writer.RestartState(int(rng.integers(0, 10 ** 6)), 0.0005, np.array([63.1, 7.0, 1e3]),
                                    codes, table, *cols)
        names = np.array(table, dtype=object)[codes]
        assert writer.restart_bytes(state) == writer.restart_text(
            state.step, state.dt, state.lengths, names, *cols).encode(), trial
    cols[3][0, 0] = np.nan
    assert fast.format_g_rows(codes, table, np.hstack(cols)) is None


def test_seventeen_digit_numbers_parse_exactly():
    """The C parser's extended-precision path (17-19 significant digits, as %.17g dumps hold
    them) gives float()'s double for every token, including 19-digit decimals next to the
    halfway point between two doubles, where rounding twice would go wrong (the parser then
    hands the token to strtod)."""
    from decimal import Decimal, localcontext

    if fast.library() is None:
        pytest.skip(f"no C helper: {fast.active_path()}")
    rng = np.random.default_rng(5)
    tokens = []
    for e in range(-28, 29, 3):
        x = rng.uniform(1, 10, 2000) * 10.0 ** e * rng.choice([-1, 1], 2000)
        tokens += ["%.17g" % v for v in x] + ["%.19g" % v for v in x]
    with localcontext() as ctx:
        ctx.prec = 60
        for v in rng.uniform(1, 1e6, 8000):
            a = float(v)
            mid = (Decimal(a) + Decimal(float(np.nextafter(a, np.inf)))) / 2
            tokens += [format(mid, ".19g"), format(mid * (1 + Decimal("1e-18")), ".19g")]
    for a in rng.integers(2 ** 52, 2 ** 53, 4000):
        s = int(rng.integers(1, 10))
        m = (int(a) << s) | (1 << (s - 1))         # exactly halfway between two doubles
        tokens += [str(m - 1), str(m), str(m + 1), f"{m}e-3"]
    ref = np.array([float(t) for t in tokens])
    for i in range(0, len(tokens), 20000):
        chunk = tokens[i:i + 20000]
        got = fast.parse_numbers((" ".join(chunk) + "\n").encode(), 1, len(chunk))
        assert got is not None
        bad = np.flatnonzero(got.ravel().view(np.int64) != ref[i:i + 20000].view(np.int64))
        assert not len(bad), [chunk[j] for j in bad[:5]]


def test_g_format_is_printf_exact():
    """fp_format_g_rows' own %g (6 significant digits, rounded on the exact binary value)
    against Python's % over 40 decades, at and next to 6-digit rounding boundaries, exact
    binary ties (decided to even), switch points between fixed and exponent notation, and
    the printf fallback outside [1e-17, 1e28)."""
    if fast.library() is None:
        pytest.skip(f"no C helper: {fast.active_path()}")
    rng = np.random.default_rng(3)
    vals = [rng.uniform(1, 10, 2000) * 10.0 ** e * rng.choice([-1, 1], 2000) for e in range(-22, 32, 2)]
    for j in range(-10, 10, 3):
        ties = (rng.integers(100000, 1000000, 2000) + 0.5) * 10.0 ** j
        vals += [ties, np.nextafter(ties, np.inf), np.nextafter(ties, -np.inf)]
    vals += [(rng.integers(100000, 1000000, 2000) + 0.5) * 2.0 ** k for k in range(-12, 13, 4)]
    special = [0.0, -0.0, 1e-4, 9.99995e-5, 9.999995e-5, 1e-5, 999999.5, 9.999995, 99999.95, 100000.5,
               1e5, 1e6, 999999.0, 1234567.0, 1e-17, 1e-18, 1e27, 1e28, 1e300, 5e-324, 2.5, 0.5]
    vals.append(np.array(special + [-v for v in special]))
    x = np.concatenate(vals).reshape(-1, 1)
    got = fast.format_g_rows(np.zeros(len(x), np.int64), ["F"], x)
    assert got == "".join("\tF\t%g\n" % v for v in x[:, 0]).encode()


def test_block_search_finds_the_first_line_with_the_keyword():
    """_line_start (single-byte searches, then the general one) against a plain search."""
    import random

    def plain(raw: bytes, key: bytes, start: int) -> int:
        if raw.startswith(key, start) and (start == 0 or raw[start - 1] == 10):
            return start
        i = raw.find(b"\n" + key, max(start - 1, 0))
        return -1 if i < 0 else i + 1

    rnd = random.Random(1)
    pieces = [b"S", b"SPRING", b"\n", b"x", b"A", b"ANGLE", b" ", b"SP", b"P", b"BEAD"]
    for _ in range(20000):
        raw = b"".join(rnd.choice(pieces) for _ in range(rnd.randint(0, 60)))
        for key, probe in ((b"SPRING", b"P"), (b"ANGLE", b"A"), (b"SPRING", b"S")):
            start = rnd.randint(0, len(raw))
            assert fast_reader._line_start(raw, key, probe, start) == plain(raw, key, start), (raw, key, start)


def test_translation_shortcuts_equal_the_plain_computations():
    """_unique_rows (sample-based factorizing) equals np.unique over rows, and scaled()
    (sample first) finds the same decimals as trying every count from 0."""
    from fibrelmp.numtext import shortest
    from fibrelmp.translate import lammps_job

    rng = np.random.default_rng(0)
    for trial in range(200):
        n = int(rng.integers(1, 30000))
        cols = [rng.integers(0, int(rng.integers(1, 5)), n).astype(float) * rng.choice([0.5, 1.0, -0.0])
                for _ in range(int(rng.integers(1, 4)))]
        if trial % 7 == 0:
            cols[0][int(rng.integers(0, n))] = 123.456                # a value the sample misses
        if trial % 9 == 0:
            cols = [rng.normal(size=n)]                                # all distinct
        rows, inverse = lammps_job._unique_rows(*cols)
        ref, ref_inv = np.unique(np.column_stack(cols), axis=0, return_inverse=True)
        assert np.array_equal(rows, ref) and np.array_equal(inverse, ref_inv.reshape(-1)), trial
        x = np.round(rng.normal(0, 10, n), int(rng.integers(0, 10)))
        if trial % 5 == 0:
            x[int(rng.integers(0, n))] = 0.1234567891                  # needs 10 decimals: None
        found = shortest.scaled(x)
        ref_k = next((k for k in range(10) if (np.round(x * 10.0 ** k) / 10.0 ** k == x).all()), None)
        assert (found is None) == (ref_k is None), trial
        if found is not None:
            assert found[1] == ref_k and np.array_equal(found[0], np.round(x * 10.0 ** ref_k).astype(np.int64))
