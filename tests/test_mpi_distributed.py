"""Distributed construction and the distributed grid under MPI (yade_mpm.parallel.distribute, pkg-mpm/mpi/Decomposition.hpp,
doc/developer/scaling.md): each rank builds only the particles of its slab (add_region counts the region's lattice
per block layer first and sets the start layout from it, then generates the lattice in chunks and the core keeps
the rank's part, with the ids of 1 process) and holds only the node layers of its slab and halo; the first step's
re-cut by the particle counts keeps that layout and moves nothing. A 2D block (distribute after make_solver) and a
3D block (make_solver(…, distribute=True): no rank allocates the whole grid), elastic, with a symmetry plane, a
traction on its top face and a drifting, shearing velocity field (particles cross the slab boundaries), 200 steps
on 2 and 3 ranks: the particle fields equal 1 process's within 1e-12. (Rigid bodies and spheres with the
distributed grid: test_mpi_contact, test_mpi_spheres.)
Skipped without mpirun or the MPI core (fails when setup found MPI); every run is bounded by a timeout."""
import numpy as np
import pytest

from test_mpi import _max_rel, _merge, needs_mpi, run_child, run_script_on_2_ranks

pytestmark = needs_mpi

CHILD = r"""
import sys
import numpy as np
import yade_mpm as ym
from yade_mpm import scene
steps, out, dim = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
scene.CHUNK = 500   # small chunks: the lattice comes in many pieces, as for a large scene
l = 0.01
mat = ym.ElasticMat(young=2e9, poisson=0.25, density=2000.0)
if dim == 2:   # distribute after creating the solver (the whole grid is allocated, then narrowed)
    lo, hi = (0.0, 0.04), (0.20, 0.30)
    s = ym.make_solver((0.0, 0.0), (0.22, 0.40), l, margin=2)
    ym.parallel.distribute(s)
else:          # distributed from the start: no rank allocates the whole grid
    lo, hi = (0.0, 0.0, 0.04), (0.07, 0.06, 0.26)
    s = ym.make_solver((0.0, 0.0, 0.0), (0.09, 0.08, 0.40), l, margin=2, distribute=True)
held = len(s._nodePositions())            # node layers held before any particle exists
ids = ym.add_region(s, mat, lo, hi)
n_local = s.numParticles
first0 = list(s.mpiInfo()["firstLayers"]) if hasattr(s, "mpiInfo") else []   # the start layout from the lattice counts
s.addBoundaryPlane(0, -1, 0.0, "slip")
s.gravity = (0.0,) * (dim - 1) + (-9.81,)
s.damping = 0.02
s.sortPeriod = 5
top = ym.boundary_particles(s, dim - 1, +1)
ym.apply_traction(s, top, (1e5,) + (0.0,) * (dim - 1), l / 2)
x = np.column_stack([s.view(f"x{a}") for a in range(dim)])
for a, v in enumerate([2.0 * np.cos(np.pi * x[:, dim - 1] / 0.2)] + [0.0 * x[:, 0]] * (dim - 2) + [20.0 + 3.0 * np.sin(np.pi * x[:, 0] / 0.2)]):
    s.view(f"v{a}")[:] = v
del x
s.requestSort()
s.run(1)
info1 = s.mpiInfo() if hasattr(s, "mpiInfo") else {"migrated": 0, "firstLayers": []}
s.run(steps - 1)
names = [f"x{a}" for a in range(dim)] + [f"v{a}" for a in range(dim)] + [f"sig{k}" for k in range(4 if dim == 2 else 6)] + ["vol", "id"]
res = {n: np.array(s.view(n)) for n in names}
info = s.mpiInfo() if hasattr(s, "mpiInfo") else {"rank": 0, "size": 1, "distributedBuild": False, "firstLayers": []}
res["rank"], res["size"], res["dist"] = info["rank"], info["size"], info.get("distributedBuild", False)
res["held"], res["nodes"], res["built"], res["ids"] = held, len(s._nodePositions()), n_local, np.array([ids[0], ids[-1] + 1])
res["first"] = np.array(info["firstLayers"])
res["first0"], res["first1"], res["moved1"] = np.array(first0), np.array(info1["firstLayers"]), info1["migrated"]
np.savez(f"{out}.{info['rank']}.npz", **res)
"""


@pytest.mark.parametrize("dim,ranks", [(2, 2), (3, 3)])
def test_distributed_build_matches_one(tmp_path, dim, ranks):
    child = CHILD.replace("int(sys.argv[3])", str(dim))
    ref = run_child(tmp_path, child, "child.py", "one", 200, 1, 600)
    parts = run_child(tmp_path, child, "child.py", "dist", 200, ranks, 900)
    names = [f"x{a}" for a in range(dim)] + [f"v{a}" for a in range(dim)] + [f"sig{k}" for k in range(4 if dim == 2 else 6)] + ["vol"]
    one, many = _merge(ref, names), _merge(parts, names)
    n = len(one["x0"])
    assert all(bool(p["dist"]) for p in parts) and all(int(p["size"]) == ranks for p in parts)
    # each rank built only its slab: no rank ever held every particle or the whole grid
    assert all(int(p["built"]) < 0.8 * n for p in parts), [int(p["built"]) for p in parts]
    assert sum(int(p["built"]) for p in parts) == n
    assert all(list(p["ids"]) == [0, n] for p in parts)             # add_region returns the global ids, as on 1 process
    # the start layout came from the region's lattice counts: the first step's re-cut keeps it and moves nothing
    assert all(list(p["first0"]) == list(p["first1"]) and int(p["moved1"]) == 0 for p in parts), \
        [(list(p["first0"]), list(p["first1"]), int(p["moved1"])) for p in parts]
    total = int(ref[0]["nodes"])
    assert all(int(p["held"]) < 0.8 * total and int(p["nodes"]) < 0.8 * total for p in parts), (total, [(int(p["held"]), int(p["nodes"])) for p in parts])
    assert np.max(np.abs(one[f"sig{1 if dim == 2 else 2}"])) > 1e5
    rel = _max_rel(one, many)
    print(f"{dim}D distributed build on {ranks} ranks: {n} particles, built {[int(p['built']) for p in parts]}, "
          f"nodes {[int(p['nodes']) for p in parts]} of {total}, max relative difference = {rel:.3e}")
    assert rel <= 1e-12, rel


REFUSALS = r"""
import sys
import numpy as np
import yade_mpm as ym
rank = ym.parallel.rank()
mat = ym.ElasticMat(young=2e9, poisson=0.25, density=2000.0)
s = ym.make_solver((0.0, 0.0), (0.2, 0.3), 0.01, margin=2)
ym.add_region(s, mat, (0.0, 0.0), (0.1, 0.1))
try:
    ym.parallel.distribute(s)
    raise AssertionError("distribute after adding particles was not refused")
except ValueError as e:
    assert "before adding particles" in str(e), str(e)
s = ym.parallel.distribute(ym.make_solver((0.0, 0.0), (0.2, 0.3), 0.01, margin=2))
try:
    ym.add_region(s, mat, (0.0, 0.0), (0.2, 0.3), holes=[ym.geometry.Box((0.05, 0.15), (0.15, 0.155))])
    raise AssertionError("a thin gap under distributed construction was not refused")
except ValueError as e:
    assert "gap_nodes" in str(e), str(e)
try:
    ym.make_solver((0.0, 0.0), (0.2, 0.3), 0.01, distribute="yes")
    raise AssertionError("make_solver(distribute='yes') was not refused")
except ValueError as e:
    assert "distribute" in str(e), str(e)
s = ym.make_solver((0.0, 0.0), (0.2, 0.3), 0.01, margin=2, distribute=True)
for counts, words in (([1.0], "counts has 1 entries"), ([-1.0] * 5, "counts[0] = -1")):
    try:
        s._mpiPlan(counts)
        raise AssertionError(f"_mpiPlan({counts}) was not refused")
    except ValueError as e:
        assert words in str(e), str(e)
ym.add_region(s, mat, (0.0, 0.0), (0.2, 0.1))
v = s.view("x0") if rank == 0 else None           # a view alive on rank 0 only: every rank refuses, none hangs
try:
    ym.add_region(s, mat, (0.0, 0.1), (0.2, 0.2))
    raise AssertionError("add_region with a live view on rank 0 was not refused")
except ValueError as e:
    assert "del v" in str(e), str(e)
del v
print(f"rank {rank} OK", flush=True)
"""


def test_distributed_build_refusals(tmp_path):
    """What distributed construction refuses (thin gaps with excluded nodes, ...): a ValueError on both ranks, no hang."""
    run_script_on_2_ranks(tmp_path, REFUSALS)
