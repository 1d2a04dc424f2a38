"""Registered means tested: every registered format has, for each of its roles, a subclass of
that role's base class (tests/conformance/base.py) in a test module here; and a new format
is one module plus one registry entry (the toy CSV target of tests/csv_target.py)."""

from __future__ import annotations

import importlib
import pkgutil

import numpy as np
import pytest

from fibrelmp import registry
from fibrelmp.errors import InputError
from fibrelmp.python_api import convert
from fibrelmp.registry import INPUT, TARGET

from . import __name__ as PACKAGE, __path__ as PACKAGE_PATH
from .base import BASES, Conformance, write_dump


def conformance_classes() -> list[type[Conformance]]:
    """Every concrete subclass of a role's base class in this package's test modules."""
    for module in pkgutil.iter_modules(PACKAGE_PATH):
        if module.name.startswith("test_"):
            importlib.import_module(f"{PACKAGE}.{module.name}")
    found, todo = [], list(BASES.values())
    while todo:
        cls = todo.pop()
        todo += cls.__subclasses__()
        if cls.__name__.startswith("Test") and cls.__module__.startswith(PACKAGE):
            found.append(cls)
    return found


def test_every_registered_format_and_role_has_a_conformance_subclass():
    covered = {(cls.format, cls.role) for cls in conformance_classes()}
    missing = [(f.name, role) for f in registry.formats() for role in f.roles if (f.name, role) not in covered]
    assert not missing, ("registered formats without conformance tests (subclass the role's "
                         f"class of tests/conformance/base.py in tests/conformance/test_<format>.py): {missing}")


def test_every_conformance_subclass_names_a_registered_format_and_role():
    for cls in conformance_classes():
        assert cls.role in registry.get(cls.format).roles, (cls.__name__, cls.format, cls.role)
        assert cls.role in BASES and issubclass(cls, BASES[cls.role])


def test_input_formats_in_detection_order():
    """Binary formats are detected first; cardioproof before demdf, whose magic is any JSON
    object."""
    assert registry.names(INPUT) == ["fibrenet", "musen-script", "mdem", "musen", "cardioproof", "demdf"]


def test_a_new_target_format_is_one_module_and_one_registry_entry(tmp_path):
    from ..csv_target import CSV

    dump, truth = write_dump(tmp_path)
    registry.register_format(CSV)
    try:
        files = convert(dump, "csv", tmp_path / "run")
        assert files == [tmp_path / "run.csv"]
        frames = registry.get("csv").load(TARGET).read_back(files)
        assert len(frames) == 3
        for got, want in zip(frames, truth):
            np.testing.assert_array_equal(got.positions, np.column_stack([want[c] for c in "xyz"]))
        with pytest.raises(InputError, match="output exists"):
            convert(dump, "csv", tmp_path / "run")
    finally:
        registry.unregister_format("csv")
    with pytest.raises(InputError, match="unknown format"):
        convert(dump, "csv", tmp_path / "again")
