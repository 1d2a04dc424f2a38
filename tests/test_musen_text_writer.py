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
