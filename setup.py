"""Build step for the optional C helpers of ``fibrelmp.numtext`` (metadata is in pyproject.toml).

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
