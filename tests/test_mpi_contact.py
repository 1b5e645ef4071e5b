"""Rigid YADE bodies under MPI (pkg-mpm/mpi/MpiExchange.hpp, doc/developer/scaling.md "Rigid bodies"): every rank runs the
same YADE scene; the contact of each rank's nodes is reduced over the ranks in rank order before YADE
integrates the bodies. A 2D elastic block falling at 5 m/s (particles cross the slab boundary) is pushed by a rigid top platen (only the upper rank touches it) and a right platen (both ranks),
and holds a free rigid filler in a vertical slot across the slab boundary (its stick step, bodyResponse,
sums nodes of both ranks). On 2 ranks against 1 process (serial core), 150 steps: the particle fields by id,
the three bodies' impulses (Σ reaction · Δt) and the filler's motion agree within 1e-10 relative (roundoff: the sums are
added in another order), and both ranks' YADE scenes hold the same bits."""

import numpy as np
import pytest

from test_mpi import _max_rel, _merge, run_child, needs_mpi

pytestmark = needs_mpi
pytest.importorskip("yade")

CHILD = r"""
import math, sys
import numpy as np
import yade_mpm as ym
from yade import O, utils
from yade_mpm_paper import cases
from yade_mpm.bodies import RigidBodies
from yade_mpm_paper.cases.loading import yade_engines, yade_filler, yade_platen
steps, out = int(sys.argv[1]), sys.argv[2]
l, W, H = 0.01, 0.2, 0.32                      # 36 cells along y with the margins: 2 ranks split at y = 0.14
slot = cases.tunnel.tunnel_flaw(toe=(0.1, 0.06), length=0.2, width=0.02, angle=math.pi / 2)   # x 0.09–0.11, y 0.06–0.26
s = ym.make_solver((0.0, 0.0), (W, H), l, margin=2)
ym.add_region(s, ym.ElasticMat(young=2e9, poisson=0.25, density=2000.0), (0.0, 0.0), (W, H), holes=[slot["polygon"]])
s.addBoundaryPlane(0, -1, 0.0, "slip")          # a symmetry plane normal to x; no floor: the block falls freely
O.reset()
rb = RigidBodies(s)
top = yade_platen(rb, W / 2, H, W, l, 6.0, 0.3, law="penalty")               # down at 6 m/s, μ = 0.3
hp = 5 * l                                                       # right platen: left at 0.5 m/s, μ = 0.2, full height
right = O.bodies.append(utils.box((W + hp, H / 2, 0), (hp, 0.6 * H, 0.5), fixed=False))
O.bodies[right].state.blockedDOFs = "xyzXYZ"
O.bodies[right].state.vel = (-0.5, 0, 0)
rb.add(right, mu=0.2, law="penalty")
filler = yade_filler(rb, slot, 0.6, density=2000.0, law="penalty")            # free in the plane, d0 = "initial"
eng = yade_engines(s, rb, "mpm")
v = s.view("v1"); v[:] = -5.0; del v                             # falling: particles cross y = 0.14
s.requestSort()
react = lambda: np.array([list(rb.force(b)) + list(np.atleast_1d(rb.torque(b))) for b in (top, right, filler)])
res = {"impulse": 0.0}
for _ in range(steps):                                           # Σ reactions over the steps (Δt is global)
    O.step()
    res["impulse"] = res["impulse"] + react() * O.dt
names = ["x0", "x1", "v0", "v1", "sig0", "sig1", "sig2", "sig3", "vol", "id"]
res.update({n: np.array(s.view(n)) for n in names})
info = s.mpiInfo() if hasattr(s, "mpiInfo") else {"rank": 0, "size": 1, "migrated": 0, "firstLayers": []}
res["rank"], res["size"], res["migrated"], res["first"] = info["rank"], info["size"], info["migrated"], np.array(info["firstLayers"])
res["forces"] = react()
st = O.bodies[filler].state
res["filler"] = np.array(list(st.pos) + list(st.vel) + list(st.angVel) + [st.ori[k] for k in range(4)])
res["time"] = np.array([s.time, O.time])
np.savez(f"{out}.{info['rank']}.npz", **res)
"""

NAMES = ["x0", "x1", "v0", "v1", "sig0", "sig1", "sig2", "sig3", "vol"]


def _run(tmp_path, tag, steps, ranks):
    parts = run_child(tmp_path, CHILD, "contact_child.py", tag, steps, ranks, timeout=900)   # a hang fails here
    return parts


def test_bodies_two_ranks_match_one(tmp_path):
    ref = _run(tmp_path, "one", 150, 1)
    parts = _run(tmp_path, "two", 150, 2)
    one, two = _merge(ref, NAMES), _merge(parts, NAMES)
    first = parts[0]["first"]
    assert list(first) == [0, 2, 5], first   # 36 cells (2 of margin each side): split at 16 cells from y = −0.02, y = 0.14 m
    assert sum(int(p["migrated"]) for p in parts) > 20
    # both ranks' YADE scenes are the same bits: reactions and the free filler's state
    for k in ("forces", "impulse", "filler", "time"):
        assert parts[0][k].tobytes() == parts[1][k].tobytes(), (k, parts[0][k], parts[1][k])
    f1, f2 = ref[0]["impulse"], parts[0]["impulse"]
    # the contacts are real: the platens push (the rock pushes the top platen up, the right platen right),
    # the filler is squeezed and moves
    assert f1[0, 1] > 1.0 and f1[1, 0] > 1.0 and np.abs(f1[2, :2]).max() > 0.1 and np.abs(ref[0]["filler"][2:4]).max() > 1e-2, (f1, ref[0]["filler"])
    rel_f = np.abs(f2 - f1).max(axis=1) / np.abs(f1).max(axis=1)
    fill1, fill2 = ref[0]["filler"], parts[0]["filler"]
    rel_fill = np.abs(fill2[2:6] - fill1[2:6]).max() / np.abs(fill1[2:6]).max()       # velocity and spin
    rel = _max_rel(one, two)
    print(f"bodies under MPI: fields {rel:.2e}, impulses {rel_f}, filler velocity {rel_fill:.2e}, "
          f"filler position {np.abs(fill2[:2] - fill1[:2]).max():.2e} m")
    assert rel <= 1e-10 and rel_f.max() <= 1e-10 and rel_fill <= 1e-10
    assert np.abs(fill2[:3] - fill1[:3]).max() <= 1e-13
    assert float(parts[0]["time"][0]) == pytest.approx(float(ref[0]["time"][0]), rel=1e-12)


REFUSE = r"""
import sys
import numpy as np
import yade_mpm as ym
import yade_mpm.parallel
from yade import O, utils
from yade_mpm.bodies import RigidBodies
steps, out = int(sys.argv[1]), sys.argv[2]
s = ym.make_solver((0.0, 0.0), (0.2, 0.32), 0.01, margin=2)
ym.add_region(s, ym.ElasticMat(young=2e9, poisson=0.25, density=2000.0), (0.0, 0.0), (0.2, 0.2))
O.reset()
rb = RigidBodies(s)
box = O.bodies.append(utils.box((0.1, 0.25, 0), (0.1, 0.02, 0.5), fixed=True))
try:
    rb.add(box, mu=0.3)                         # the default law: kinematic
    msg = "accepted"
except ValueError as e:
    msg = str(e)
box2 = O.bodies.append(utils.box((0.1, 0.29, 0), (0.1, 0.01, 0.5), fixed=True))
rb.add(box2, mu=0.3, law="penalty")             # the named option runs
np.savez(f"{out}.{ym.parallel.rank()}.npz", msg=msg, active=s._contactActive, groups=s._numContactGroups)
"""


def test_kinematic_law_is_refused_at_registration_on_several_ranks(tmp_path):
    """Several MPI ranks do not run the kinematic law yet: registering a body with it is refused before anything is
    added, naming the parameter and the option that runs (law='penalty'); one process accepts it."""
    parts = run_child(tmp_path, REFUSE, "refuse.py", "mpi", 1, 2, 300)
    for p in parts:
        assert "law" in str(p["msg"]) and "penalty" in str(p["msg"]) and "kinematic" in str(p["msg"])
        assert int(p["groups"]) == 1 and bool(p["active"])
    one = run_child(tmp_path, REFUSE, "refuse.py", "one", 1, 1, 300)
    assert str(one[0]["msg"]) == "accepted" and int(one[0]["groups"]) == 2
