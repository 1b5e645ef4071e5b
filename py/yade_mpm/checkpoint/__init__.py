"""Checkpoint and resume of a whole simulation: the MPM solvers and the YADE scene.

    import yade_mpm as ym
    build_my_scene()                          # solver(s), MpmEngine(s), YADE bodies and engines
    if resuming:
        ym.checkpoint.load("run.ckpt")        # fills the freshly built scene with the saved state
    ...
    ym.checkpoint.save("run.ckpt")            # between O.run(n, True) calls (or Solver.run calls)

A checkpoint holds, per MPM solver, every particle array in storage order (the sort order is state),
the clock, the external work, the block schedule, the values the next step reads without recomputing
them and the solver settings (``Solver.settings()``); with YADE also the scene written by ``O.save``,
the body states once more (checked bitwise after ``O.load``) and the ``MpmEngine`` state. A resumed run
is bitwise identical to the uninterrupted one for the same thread count. The script builds the scene
as usual and ``load`` overwrites its state, after checking the whole file: a truncated or corrupted
file, another format or build of the core, or another scene (grid, particles, materials, loads, contact
parameters, YADE bodies and engines) is refused with a ``CheckpointError`` (a ``ValueError``), nothing changed. The
``MpmEngine`` registry is restored after ``O.load`` (doc/guide/checkpoints.md). The run-loop side, periodic
checkpoints and clean stops on SIGINT / SIGTERM, is ``Checkpointer`` and ``ResumableRun`` in
``yade_mpm.checkpoint.resumable``. On N > 1 MPI ranks: a piece per rank and an index, resumed by the same rank
count only (``yade_mpm.checkpoint.mpi``).

Modules: format (the file), serial (the state, save and load), mpi (pieces per rank), resumable (the run loop).
"""
from .format import FORMAT, MAGIC, CheckpointError, build_id, read
from .serial import load, save, solver_fingerprint, yade_fingerprint, _field_names  # noqa: F401
from .resumable import Checkpointer, ResumableRun
from . import resumable  # noqa: F401

__all__ = ["save", "load", "read", "CheckpointError", "Checkpointer", "ResumableRun", "build_id", "solver_fingerprint",
           "yade_fingerprint", "FORMAT", "MAGIC"]
