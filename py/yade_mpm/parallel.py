"""MPI domain decomposition (doc/developer/scaling.md): which compiled core ``import yade_mpm`` loads, and this
process's rank.

The serial module ``yade_mpm._core`` is what ``import yade_mpm`` loads by default. The MPI build of the
same sources, ``yade_mpm._core_mpi`` (compiled with -DMPM_MPI when an MPI library is found), is loaded
instead when

- ``YADE_MPM_MPI=1`` is set (``YADE_MPM_MPI=0`` forces the serial core), or
- the process was started by Open MPI's ``mpirun`` with more than one rank (``OMPI_COMM_WORLD_SIZE`` > 1).

Under ``srun`` (Slurm) set ``YADE_MPM_MPI=1``. Every rank runs the same script. By default every rank builds
the same scene and the first step keeps each rank's slab of particles (pkg-mpm/mpi/Decomposition.hpp);
``make_solver(…, distribute=True)``, or ``distribute(solver)`` right after creating the solver, makes each rank
build only its slab (a scene larger than one process can hold; doc/guide/mpi.md); the first never allocates
the whole grid on a rank.
"""
import os


def wanted(environ=os.environ):
    """True if the MPI core should be loaded (see the module docstring)."""
    v = environ.get("YADE_MPM_MPI")
    if v is not None and v.strip() != "":
        if v.strip() not in ("0", "1"):
            raise ValueError(f"YADE_MPM_MPI = {v!r} must be '0' (serial core) or '1' (MPI core)")
        return v.strip() == "1"
    try:
        return int(environ.get("OMPI_COMM_WORLD_SIZE", "1")) > 1
    except ValueError:
        return False


def load_core(package):
    """The compiled core module for this process: yade_mpm._core, or yade_mpm._core_mpi registered under
    the name yade_mpm._core (so every ``from ._core import …`` of the package gets it)."""
    import importlib
    import sys
    if not wanted():
        return importlib.import_module(package + "._core")
    try:
        core = importlib.import_module(package + "._core_mpi")
    except ImportError as e:
        raise ImportError("yade_mpm: the MPI core _core_mpi was requested (mpirun with > 1 rank or YADE_MPM_MPI=1) but is not "
                          "built: install libopenmpi-dev and rebuild (./setup.sh), or set YADE_MPM_MPI=0") from e
    sys.modules[package + "._core"] = core
    return core


def rank():
    """This process's MPI rank (0 with the serial core)."""
    from . import _core
    return _core.mpiRank() if hasattr(_core, "mpiRank") else 0


def size():
    """Number of MPI ranks (1 with the serial core)."""
    from . import _core
    return _core.mpiSize() if hasattr(_core, "mpiSize") else 1


def distribute(solver):
    """Distributed construction: call right after creating the solver, before adding particles. Each rank then
    holds only the grid layers of its slab (block layers split evenly; the scene's first add_region sets the
    slabs from its lattice counts) and keeps of every add_region / addParticles only the particles of its slab,
    with the ids 1 process would give; the first step re-cuts the slabs by the particle counts. Nothing happens
    on 1 process. The solver was created with the whole grid (freed here); make_solver(…, distribute=True)
    never allocates it on a rank. Builders that need every particle on every
    rank refuse (add_region with thin gaps excluded, d0 = 'initial' bodies); a checkpoint resumes into the scene
    built again with or without distribute (the same rank count)."""
    if size() > 1:
        solver._mpiDistribute()
    return solver
