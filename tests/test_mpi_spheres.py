"""DEM spheres under MPI (py/yade_mpm/spheres.py, doc/developer/scaling.md "Rigid bodies"): every rank runs the same
YADE scene; the broad phase of ``DemSpheres`` reads the particle box of every rank (one max-reduction of 2D
doubles per check) and the global max ‖v‖, so all ranks enable the same contact groups at the same steps
and meet in the same collectives (with the rank's own box a 2-rank run hung). A 2D elastic block with a
vertical slot (x 0.08–0.12 m, y 0.06–0.26 m): a sphere in the slot strikes its right wall across the slab
boundary y = 0.14 m, one above the block lands on its top, one further up starts far (inactive: checks at
growing rate until it comes within reach) and lands later. 400 steps on 1 process (serial core) and on 2
and 3 ranks: particle fields by id, sphere positions, velocities and spins within 1e-12 relative; the
broad-phase schedule (checks, next check, active flags after every step) and every rank's sphere states
are the same bits on every rank, and the same schedule as 1 process."""

import numpy as np
import pytest

from test_mpi import _max_rel, _merge, run_child, needs_mpi

pytestmark = needs_mpi
pytest.importorskip("yade")

CHILD = r"""
import math, sys
import numpy as np
import yade_mpm as ym
from yade import O, utils, ForceResetter, NewtonIntegrator
from yade_mpm_paper import cases
steps, out = int(sys.argv[1]), sys.argv[2]
l, W, H = 0.01, 0.2, 0.32
slot = cases.tunnel.tunnel_flaw(toe=(0.1, 0.06), length=0.2, width=0.04, angle=math.pi / 2)   # x 0.08–0.12, y 0.06–0.26
s = ym.make_solver((0.0, 0.0), (W, H + 0.1), l, margin=2)
ym.add_region(s, ym.ElasticMat(young=2e9, poisson=0.25, density=2000.0), (0.0, 0.0), (W, H), holes=[slot["polygon"]])
s.addBoundaryPlane(1, -1, 0.0, "slip")
O.reset()
ids = []
for (x, y, vx, vy) in ((0.1, 0.15, 6.0, -3.0), (0.05, 0.336, 0.0, -6.0), (0.16, 0.36, 0.0, -20.0)):
    b = utils.sphere((x, y, 0), 0.012)
    b.state.blockedDOFs = "zXY"
    b.state.vel = (vx, vy, 0.0)
    ids.append(O.bodies.append(b))
sp = ym.DemSpheres(s)
sp.add(ids, mu=0.3, law="penalty")
O.engines = [ForceResetter(), ym.MpmEngine(s, bodies=sp).runner(), NewtonIntegrator(gravity=(0, -9.81, 0))]
O.dt = s.stableDt()
sched, impulse = [], np.zeros((len(ids), 2))
for _ in range(steps):
    O.step()
    sched.append([s.steps, sp._next_check, sp.checks] + sp.active.astype(int).tolist())
    impulse += np.array([sp.force(i) for i in ids]) * O.dt
names = ["x0", "x1", "v0", "v1", "sig0", "sig1", "sig2", "sig3", "vol", "id"]
res = {n: np.array(s.view(n)) for n in names}
info = s.mpiInfo() if hasattr(s, "mpiInfo") else {"rank": 0, "size": 1, "firstLayers": []}
res["size"], res["first"] = info["size"], np.array(info["firstLayers"])
res["spheres"] = np.array([list(O.bodies[i].state.pos)[:2] + list(O.bodies[i].state.vel)[:2] + [O.bodies[i].state.angVel[2]] for i in ids])
res["sched"], res["impulse"], res["time"] = np.array(sched), impulse, np.array([O.time, s.time])
np.savez(f"{out}.{info['rank']}.npz", **res)
"""

NAMES = ["x0", "x1", "v0", "v1", "sig0", "sig1", "sig2", "sig3", "vol"]


def _run(tmp_path, tag, steps, ranks):
    parts = run_child(tmp_path, CHILD, "spheres_child.py", tag, steps, ranks, timeout=180)   # a hang fails here
    assert all(int(p["size"]) == ranks for p in parts)
    return parts


def _rel(a, b):
    """Largest |a − b| / max |a| over the columns of the sphere states (x, y | vx, vy | ω)."""
    cols = [slice(0, 2), slice(2, 4), slice(4, 5)]
    return max(float(np.abs(b[:, c] - a[:, c]).max() / np.abs(a[:, c]).max()) for c in cols)


def test_spheres_ranks_match_one(tmp_path):
    ref = _run(tmp_path, "one", 400, 1)[0]
    one = _merge([ref], NAMES)
    sched = ref["sched"]
    # the contacts are real: the slot sphere bounced off the right wall (vx 6 → < 0) and spins, the two
    # upper spheres landed (vy > 0 now); the far sphere was inactive first and checked more than once
    sph, imp = ref["spheres"], ref["impulse"]
    assert sph[0, 2] < -0.5 and abs(sph[0, 4]) > 10 and sph[1, 3] > 0.5 and sph[2, 3] > 0.5, sph
    assert imp[0, 0] < 0 and imp[1, 1] > 0 and imp[2, 1] > 0, imp
    assert sched[0, -1] == 0 and sched[-1, -1] == 1 and sched[-1, 2] >= 5, sched[[0, -1]]
    for ranks in (2, 3):
        parts = _run(tmp_path, f"r{ranks}", 400, ranks)
        first = parts[0]["first"]
        assert len(first) == ranks + 1 and first[1] == 2, first        # a slab boundary at y = −0.02 + 16 l = 0.14 m
        y, R = sph[0, 1], 0.012
        assert y - R < 0.14 < y + R, y                                   # the slot sphere straddles it
        assert all(len(p["id"]) > 100 for p in parts), [len(p["id"]) for p in parts]
        # every rank's YADE spheres, reactions and broad-phase schedule: the same bits
        for p in parts[1:]:
            for k in ("spheres", "impulse", "sched", "time"):
                assert p[k].tobytes() == parts[0][k].tobytes(), (ranks, k)
        assert np.array_equal(parts[0]["sched"], sched), "the same checks at the same steps as 1 process"
        rel = _max_rel(one, _merge(parts, NAMES))
        rel_s = _rel(sph, parts[0]["spheres"])
        rel_i = float(np.abs(parts[0]["impulse"] - imp).max() / np.abs(imp).max())
        print(f"DemSpheres {ranks} ranks vs 1: fields {rel:.2e}, spheres {rel_s:.2e}, impulses {rel_i:.2e}, "
              f"{int(sched[-1, 2])} broad-phase checks on every rank")
        assert rel <= 1e-12 and rel_s <= 1e-12 and rel_i <= 1e-12, (rel, rel_s, rel_i)
        assert float(parts[0]["time"][0]) == pytest.approx(float(ref["time"][0]), rel=1e-12)
