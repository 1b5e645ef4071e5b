"""Dynamic load balance under MPI (pkg-mpm/mpi/Decomposition.hpp `rebalance`, doc/developer/scaling.md): a 2D elastic
block (`yade_mpm_paper.cases.drifting_block`) drifting at 35 m/s along the slab axis through a tall empty grid (about 20 cells in 100 steps) moves
its particles out of the start slabs. With the default `mpiRebalance = 1.1` the slabs are cut again from the
particle counts per block layer; with `inf` they are not and one rank ends up holding every particle
(max/mean = 2 on 2 ranks). Either way the particle fields equal one process's within 1e-12 (shared-node sums
added in another order), on 2 and on 3 ranks (after a re-cut on 3 ranks a particle can be two slabs away
from its new owner: it hops one rank per pass). Skipped without mpirun or the MPI core; runs are bounded."""
import os
import subprocess
import sys

import numpy as np
import pytest

from test_mpi import LAUNCH, ROOT, _max_rel, _merge, needs_mpi

pytestmark = needs_mpi

CHILD = r"""
import sys
import numpy as np
import yade_mpm as ym
from yade_mpm_paper import cases
threshold, steps, out = float(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
s = cases.drifting_block(0.01, rebalance=threshold)   # 68 cells along y: 9 block layers
s.courant = 0.5                                        # the grid holds the drift of `steps` steps at it (not at C = 1)
s.run(steps)
res = {n: np.array(s.view(n)) for n in ["x0", "x1", "v0", "v1", "sig0", "sig1", "sig2", "sig3", "vol", "id"]}
info = s.mpiInfo() if hasattr(s, "mpiInfo") else {"rank": 0, "size": 1, "firstLayers": [], "rebalances": 0, "imbalance": 1.0}
res["first"], res["rebalances"], res["imbalance"] = np.array(info["firstLayers"]), info["rebalances"], info["imbalance"]
np.savez(f"{out}.{info['rank']}.npz", **res)
"""
NAMES = ["x0", "x1", "v0", "v1", "sig0", "sig1", "sig2", "sig3", "vol"]


def _run(tmp_path, tag, ranks, threshold, steps=100):
    script = tmp_path / "child.py"
    script.write_text(CHILD)
    out = str(tmp_path / tag)
    env = dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=os.path.join(ROOT, "py"))
    env.pop("YADE_MPM_MPI", None)
    args = [str(script), threshold, str(steps), out]
    cmd = [sys.executable] + args if ranks == 1 else [LAUNCH, str(ranks), "1"] + args
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, (r.stdout[-2000:], r.stderr[-3000:])
    return [dict(np.load(f"{out}.{k}.npz")) for k in range(ranks)]


def test_rebalance_follows_moving_material(tmp_path):
    one = _merge(_run(tmp_path, "one", 1, "1.1"), NAMES)
    assert np.max(np.abs(one["sig1"])) > 1e3 and np.min(one["x1"]) > 0.1   # stressed, and moved ≥ 10 cells up
    never = _run(tmp_path, "never", 2, "inf")
    assert all(int(p["rebalances"]) == 0 for p in never)
    assert sorted(len(p["id"]) for p in never) == [0, len(one["x0"])]         # one rank holds everything
    assert float(never[0]["imbalance"]) == 2.0
    for ranks in (2, 3):
        parts = _run(tmp_path, f"r{ranks}", ranks, "1.1")
        f = _merge(parts, NAMES)                                                # every particle exactly once
        rel = _max_rel(one, f)
        first = parts[0]["first"]
        counts = [len(p["id"]) for p in parts]
        print(f"{ranks} ranks: slabs {list(first)}, {int(parts[0]['rebalances'])} re-cuts, counts {counts}, "
              f"max/mean {float(parts[0]['imbalance']):.3f} (never: 2.000), max relative difference to 1 process {rel:.2e}")
        assert rel <= 1e-12, rel
        assert int(parts[0]["rebalances"]) >= 1 and all(np.array_equal(p["first"], first) for p in parts)
        assert max(counts) * ranks / sum(counts) < 1.5                           # shared, not one rank holding all
        layer = lambda y: np.floor((y + 2 * 0.01) / 0.01).astype(int) // 8      # grid origin at −2 cells
        for k, p in enumerate(parts):                                          # each rank holds its slab's particles
            assert np.all((layer(p["x1"]) >= first[k] - 1) & (layer(p["x1"]) <= first[k + 1]))   # ± the drift since the re-sort


def test_rebalance_threshold_checked():
    import yade_mpm as ym
    s = ym.make_solver((0.0, 0.0), (0.1, 0.1), 0.01, margin=2)
    assert s.mpiRebalance == pytest.approx(1.1)
    s.mpiRebalance = float("inf")                                              # never: allowed
    for bad in (0.5, float("nan"), -float("inf")):
        with pytest.raises(ValueError, match=r"mpiRebalance.*\[1, inf\]"):
            s.mpiRebalance = bad
