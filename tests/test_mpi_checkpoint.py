"""Checkpoints on N MPI ranks (py/yade_mpm/checkpoint_mpi.py, doc/developer/scaling.md "Checkpoints"): a 2D elastic
block is saved on 2 ranks after 20 steps (a piece per rank and an index) and stepped 20 more, in which
particles migrate between the ranks; a second 2-rank run builds the scene afresh, loads the checkpoint and
steps 20: every
particle array of every rank is the same bits. The same checkpoint is refused with a message naming both
rank counts on 3 ranks and on 1 process."""
import os
import subprocess
import sys

import numpy as np
import pytest

from test_mpi import LAUNCH, ROOT, needs_mpi

pytestmark = needs_mpi

CHILD = r"""
import sys
import numpy as np
import yade_mpm as ym
from yade_mpm import checkpoint
mode, ck, out = sys.argv[1], sys.argv[2], sys.argv[3]
spread = len(sys.argv) > 4 and sys.argv[4] == "distribute"          # each rank builds only its slab
s = ym.make_solver((0.0, 0.0), (0.22, 0.36), 0.01, margin=2, distribute=spread)   # 40 cells along y: 5 block layers
ym.add_region(s, ym.ElasticMat(young=2e9, poisson=0.25, density=2000.0), (0.0, 0.04), (0.2, 0.24))
s.addBoundaryPlane(0, -1, 0.0, "slip")
s.gravity, s.damping, s.sortPeriod = (0.0, -9.81), 0.02, 5
s.courant = 0.5                                # the steps below are counted at it (at C = 1 every migration is before the save)
x = s.view("x0"); v = s.view("v1"); v[:] = 20.0 + 3.0 * np.sin(np.pi * x / 0.2); del x, v   # drifts across the slab boundary
s.requestSort()
rank = ym.parallel.rank()
built = s.numParticles                         # this rank's particles of the fresh scene
if mode == "save":
    s.run(32 if spread else 20)                # the first particles cross y = 0.14 m after ~28 steps: before / after the save
    checkpoint.save(ck, s)
elif mode == "resume":
    checkpoint.load(ck, s)
else:                                          # another rank count: refused, nothing changed
    try:
        checkpoint.load(ck, s)
    except checkpoint.CheckpointError as e:
        print(f"rank {rank} refused: {e}", flush=True)
        assert s.steps == 0
        sys.exit(0)
    raise AssertionError("loaded a checkpoint of another rank count")
loaded = s.numParticles                        # resume: this rank's particles of its piece
s.run(20)
names = ["x0", "x1", "v0", "v1", "C0", "C1", "C2", "C3", "sig0", "sig1", "sig2", "sig3", "vol", "mass", "id"]
np.savez(f"{out}.{rank}.npz", time=s.time, steps=s.steps, migrated=s.mpiInfo()["migrated"] if hasattr(s, "mpiInfo") else 0, built=built, loaded=loaded,
         **{n: np.array(s.view(n)) for n in names})
"""


def _launch(tmp_path, ranks, *args, timeout=600):
    """Runs CHILD with args (mode, checkpoint, out[, "distribute"]) on `ranks` ranks (1: one process)."""
    script = tmp_path / "ck_child.py"
    script.write_text(CHILD)
    env = dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=os.path.join(ROOT, "py"))
    env.pop("YADE_MPM_MPI", None)
    cmd = [sys.executable, str(script), *args] if ranks == 1 else [LAUNCH, str(ranks), "1", str(script), *args]
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout)
    assert r.returncode == 0, (r.stdout[-2000:], r.stderr[-3000:])
    return r.stdout


def test_checkpoint_resume_bitwise_and_rank_count(tmp_path):
    ck = str(tmp_path / "run.ckpt")
    _launch(tmp_path, 2, "save", ck, str(tmp_path / "straight"))
    assert os.path.exists(ck) and os.path.exists(ck + ".r0") and os.path.exists(ck + ".r1")
    _launch(tmp_path, 2, "resume", ck, str(tmp_path / "resumed"))
    for k in range(2):
        a, b = dict(np.load(tmp_path / f"straight.{k}.npz")), dict(np.load(tmp_path / f"resumed.{k}.npz"))
        assert int(a["steps"]) == 40 and int(b["steps"]) == 40
        differing = [n for n in a if n not in ("migrated", "built", "loaded") and a[n].tobytes() != b[n].tobytes()]
        assert not differing, (k, differing)
    mig = lambda tag: sum(int(np.load(tmp_path / f"{tag}.{k}.npz")["migrated"]) for k in range(2))
    assert mig("resumed") > 20 and mig("resumed") == mig("straight"), (mig("straight"), mig("resumed"))   # migrations after the resume
    out3 = _launch(tmp_path, 3, "other", ck, str(tmp_path / "three"))
    assert out3.count("written by 2 MPI rank(s); this run has 3") == 3, out3
    out1 = _launch(tmp_path, 1, "other", ck, str(tmp_path / "one"))
    assert "written by 2 MPI rank(s); this run has 1" in out1, out1


def test_checkpoint_of_a_distributed_build_resumes_bitwise(tmp_path):
    """A scene built with make_solver(…, distribute=True) (no rank ever holds all particles) is saved on 2 ranks after
    particles crossed the slab boundary and resumed into a fresh distributed build of it: each rank's arrays are
    sized to its piece (its start slab held another count: one rank's arrays grow, the other's shrink), and 20 more
    steps give the uninterrupted run's bits."""
    ck = str(tmp_path / "dist.ckpt")
    _launch(tmp_path, 2, "save", ck, str(tmp_path / "straight"), "distribute")
    _launch(tmp_path, 2, "resume", ck, str(tmp_path / "resumed"), "distribute")
    grew = []
    for k in range(2):
        a, b = dict(np.load(tmp_path / f"straight.{k}.npz")), dict(np.load(tmp_path / f"resumed.{k}.npz"))
        assert int(a["steps"]) == 52 and int(b["steps"]) == 52 and len(a["id"]) > 100
        differing = [n for n in a if n not in ("migrated", "built", "loaded") and a[n].tobytes() != b[n].tobytes()]
        assert not differing, (k, differing)
        grew.append(int(b["loaded"]) - int(b["built"]))
    assert max(grew) > 0 > min(grew), grew
