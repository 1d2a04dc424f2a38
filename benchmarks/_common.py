"""Helpers shared by the benchmark scripts (run them as `python benchmarks/NAME.py`)."""

import importlib.util
from pathlib import Path

HERE = Path(__file__).resolve().parent


def load_generator():
    """The network generator in examples/ (a script, not a package module)."""
    spec = importlib.util.spec_from_file_location(
        "generate_network", HERE.parent / "examples" / "generate_network.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod
