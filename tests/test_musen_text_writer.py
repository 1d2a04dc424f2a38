"""The one MUSEN text writer's formatting (translate/musen/text_writer.py), which the result
writer from frames and the .mdem text export share: lines written out by hand from MUSEN's
ExportAsText.cpp layout."""

import numpy as np

from fibrelmp.translate.musen.text_writer import (export_selectors, object_header, scene_line,
                                                  time_point_lines)

FIELDS = (("coord", 12, 3), ("forceAmpl", 18, 1))


def test_object_lines_with_every_time_point():
    const = export_selectors()["constProps"]
    head = object_header(const, 7, 1, "0.5 0.5", "KEY", "0", "1e+300")
    spool = np.array([[[1.0, 2.0, 3.0, 0.25], [1.5, 2.0, 3.0, 1.0 / 3.0]]])   # (objects, saves, columns)
    lines = time_point_lines([head], FIELDS, {"coord": True, "forceAmpl": True}, [0.0, 0.001], 6,
                             lambda cols: spool[:, :, cols])
    assert lines == ["0 7 1 1 5 0.5 0.5 23 KEY 24 0 1e+300 "
                     "2 0 12 1 2 3 18 0.25 2 0.001 12 1.5 2 3 18 0.333333 \n"]


def test_selectors_leave_out_parts_and_fields():
    const = export_selectors({"constProps": {"geometry": False, "material": False}})["constProps"]
    head = object_header(const, 3, 14, "", "KEY", "0", "1")
    spool = np.array([[[1.0, 2.0, 3.0, 0.5]]])
    lines = time_point_lines([head], FIELDS, {"coord": False, "forceAmpl": True}, [2.0], 3,
                             lambda cols: spool[:, :, cols])
    assert lines == ["0 3 1 14 24 0 1 2 2 18 0.5 \n"]
    assert time_point_lines([head], FIELDS, {"coord": True, "forceAmpl": True}, [], 6,
                            lambda cols: spool[:, :0, cols]) == ["0 3 1 14 24 0 1 \n"]


def test_scene_line_puts_a_space_after_every_value():
    assert scene_line(27, 0, "") == "27 0  \n"
    assert scene_line(29, 1) == "29 1 \n"


def test_time_points_c_and_python_formatting_agree(monkeypatch):
    """precision 6 goes through the C formatter (fast.format_g_template), other precisions
    and a missing library through Python's %: the same lines, for values across 60 decades,
    signed zeros and exact binary ties at the 6th digit, with a field switched off between two
    that are on, split over two threads or not."""
    from concurrent.futures import ThreadPoolExecutor

    from fibrelmp.numtext import fast

    if fast.library() is None:
        import pytest
        pytest.skip(f"no C helper: {fast.active_path()}")
    rng = np.random.default_rng(5)
    objects, saves = 2000, 7            # 70,000 values: large enough to split
    fields = (("coord", 12, 3), ("force", 20, 3), ("forceAmpl", 18, 1))
    flags = {"coord": True, "force": False, "forceAmpl": True}
    spool = rng.standard_normal((objects, saves, 7)) * 10.0 ** rng.integers(-30, 30, (objects, saves, 7))
    spool[:20, :, 0] = rng.integers(100000, 1000000, (20, saves)) + 0.5      # exact ties: 123456.5
    spool[20:40] = -0.0
    heads = [f"0 {k} " for k in range(objects)]
    times = np.linspace(0.0, 1e-5, saves)

    def lines():
        return time_point_lines(heads, fields, flags, times, 6, lambda cols: spool[:, :, cols])
    template = "2 %g 12 %g %g %g 18 %g "
    want = [h + "".join(template % (t, *spool[k, j, [0, 1, 2, 6]]) for j, t in enumerate(times)) + "\n"
            for k, h in enumerate(heads)]
    assert (spool[:20, :, 0] % 1 == 0.5).all()                                # ties, rounded to even
    used = []
    real = fast.format_g_template

    def counted(*args):
        got = real(*args)
        used.append(got is not None)
        return got
    monkeypatch.setattr("fibrelmp.translate.musen.text_writer.format_g_template", counted)
    monkeypatch.setattr(fast, "_helper", lambda: None)
    assert lines() == want and used == [True]
    submitted = []

    class Pool(ThreadPoolExecutor):
        def submit(self, *args, **kwargs):
            submitted.append(args[0])
            return super().submit(*args, **kwargs)
    with Pool(1) as pool:                                      # the two-thread path
        monkeypatch.setattr(fast, "_helper", lambda: pool)
        assert lines() == want and used == [True, True] and len(submitted) == 1
    monkeypatch.setattr(fast, "library", lambda: None)       # Python's % alone
    assert lines() == want and used == [True, True, False]


def test_c_time_point_formatter_declines_non_finite_values():
    from fibrelmp.numtext import fast

    if fast.library() is None:
        import pytest
        pytest.skip(f"no C helper: {fast.active_path()}")
    assert fast.format_g_template(np.array([[1.0, 2.5]]), ["2 ", "18 "], 1) == b"2 1 18 2.5 \n"
    for bad in (np.nan, np.inf, -np.inf):
        assert fast.format_g_template(np.array([[1.0, bad]]), ["2 ", ""], 1) is None
    # Python's % writes them as MUSEN's ostream does not; the caller falls back to it
    lines = time_point_lines(["h "], FIELDS[1:], {"forceAmpl": True}, [0.0], 6,
                             lambda cols: np.array([[[np.inf]]]))
    assert lines == ["h 2 0 18 inf \n"]


def test_headers_formatted_in_bulk_keep_one_entry_per_object():
    """text_writer.bulk_format: one % for all rows, row by row when a value (a material key read from a
    .mdem) holds a newline, which would shift every later object's header."""
    from fibrelmp.translate.musen.text_writer import bulk_format as _bulk

    assert _bulk("%d %.16g %s", np.array([1, 2]), np.array([0.1, 1e300]), ["a", "b"]) == \
        ["1 0.1 a", "2 1e+300 b"]
    assert _bulk("%d %s", np.array([1, 2]), ["a\nx", "b"]) == ["1 a\nx", "2 b"]
    assert _bulk("%g", np.array([])) == []
