"""Checkpoints of a run on N MPI ranks (doc/developer/scaling.md "Checkpoints"; used by ``yade_mpm.checkpoint``).

``checkpoint.save(path)`` on N > 1 ranks writes one piece per rank, ``path.rK`` (K = 0 … N − 1: the rank's
particles in storage order, its block schedule, the slab layout, the replicated YADE scene and the clock,
in the one-process format), then — after every rank has written — rank 0 writes ``path`` itself, an index
naming the rank count and the pieces. ``checkpoint.load(path)`` reads the index: the same rank count
resumes bitwise (each rank loads its piece into the freshly built, replicated scene: the slab layout and
the rank's particles are restored, the other particles dropped); another rank count — also 1 process
against an N-rank checkpoint, or N ranks against a 1-process checkpoint — is refused with a
``CheckpointError`` naming both counts (re-partitioning is not supported). Every check agrees over the
ranks before any rank changes its state (a problem on one rank refuses on all)."""
from .. import parallel
from .format import CheckpointError, read


def active():
    """True when this process is one of N > 1 ranks (a decomposed run)."""
    return parallel.size() > 1


def piece(path, rank):
    return f"{path}.r{rank}"


def agree(ok):
    """True on every rank iff `ok` on every rank (a collective)."""
    from .. import _core
    return _core.mpiSum(0.0 if ok else 1.0) == 0.0


def barrier():
    from .. import _core
    _core.mpiSum(0.0)


def header_of(solver):
    """What a piece records about the decomposition: rank, rank count, slab layout, the rank's and all
    ranks' particle counts (a collective). Before the first step the ranks hold the whole replicated scene
    and no layout: refused (save after a step, or before splitting on 1 process)."""
    from .. import _core
    info = solver.mpiInfo()
    total = int(round(_core.mpiSum(float(solver.numParticles) if info["decomposed"] else 0.0)))
    if not agree(info["decomposed"]):
        raise ValueError(f"checkpoint: under MPI ({info['size']} ranks) save after the first step (before it every rank holds the "
                         "whole scene and no slab layout exists yet)")
    return dict(rank=info["rank"], size=info["size"], firstLayers=list(info["firstLayers"]), particles=int(solver.numParticles), total=total)


def saved_size(path, header):
    """Rank count of the run that wrote the checkpoint whose (index) header is `header`."""
    return int(header["mpi_index"]["size"]) if header.get("mpi_index") else 1


def refuse_other_count(path, header):
    """CheckpointError unless the checkpoint was written by as many ranks as this run has."""
    saved, here = saved_size(path, header), parallel.size()
    if saved != here:
        raise CheckpointError(f"checkpoint {path} was written by {saved} MPI rank(s); this run has {here}: resume with the same "
                              f"rank count (mpirun -np {saved}); re-partitioning a checkpoint to another rank count is not supported")


def save_pieces(path, header, arrays, solvers, write):
    """This rank's piece, then (rank 0, after every rank wrote) the index. Returns the bytes this rank wrote."""
    import os
    from ..parallel import rank, size
    n = write(piece(path, rank()), header, arrays)
    barrier()                                     # every piece is on disk before the index names them
    if rank() == 0:
        n += write(path, {k: header[k] for k in ("format", "build", "written", "meta")} | {"mpi_index": dict(
            size=size(), pieces=[os.path.basename(piece(path, r)) for r in range(size())],
            steps={name: int(s.steps) for name, s in solvers.items()})}, {})
    barrier()
    return n


def load_piece(path, index, solvers, yade, meta, load_checked):
    """MPI: this rank's piece; a refusal on any rank refuses on every rank. load_checked: serial's
    check-then-restore of one piece (passed in, so this module never imports serial)."""
    from ..parallel import rank
    problem = None
    try:
        header, arrays = read(piece(path, rank()))
        mp = header.get("mpi") or {}
        if any(h["rank"] != rank() or h["size"] != parallel.size() for h in mp.values()) or not mp:
            raise CheckpointError(f"checkpoint {piece(path, rank())}: not the piece of rank {rank()} of {parallel.size()}")
        if any(int(arrays[f"solver/{n}/scalars"][0]) != st for n, st in index["mpi_index"]["steps"].items()):
            raise CheckpointError(f"checkpoint {path}: the pieces were written at different steps (an interrupted save?)")
    except CheckpointError as e:
        problem = e
    if not agree(problem is None):
        raise problem or CheckpointError(f"checkpoint {path}: another rank refused its piece (its message names the problem)")
    return load_checked(path, header, arrays, solvers, yade, meta, mpi=mp)
