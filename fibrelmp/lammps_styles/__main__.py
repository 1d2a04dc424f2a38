"""``python -m fibrelmp.lammps_styles [OUT_DIR]``: build the plugin (see build.py)."""

import sys

from fibrelmp.lammps_styles.build import LIB_DIR, BuildError, build

try:
    print(build(sys.argv[1] if len(sys.argv) > 1 else LIB_DIR))
except BuildError as exc:
    sys.exit(f"fibrelmp: LAMMPS styles not built: {exc}")
