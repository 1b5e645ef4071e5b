"""Material that leaves the grid under MPI: a fragment thrown off the grid (the stability suite's debris
scene) on 2 ranks gives the one-process result — the same particles removed, the removed account and every
remaining particle within 1e-12 — both for a fully damaged fragment and for an intact one, which is debris
because it is detached from the body (the cluster map of intact material is combined over the ranks)."""
import numpy as np
import pytest

from test_mpi import run_child, needs_mpi

pytestmark = needs_mpi

CHILD = r"""
import sys
import numpy as np
import yade_mpm as ym
from yade_mpm_paper.validation import stability_cases as sc
damage, steps, out = float(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
s, block, frag = sc.debris_scene(50.0)
s.view("damage")[np.isin(s.view("id"), frag)] = damage
s.requestSort()
s.autoDt, s.fixedDt = False, 0.999 * s.courant * s.spacing / (s.waveSpeed() + 200.0)
s.sortPeriod = 10
s.run(steps)
acc = s._removedAccount()                      # a collective under MPI: over every rank
rank = s.mpiInfo()["rank"] if hasattr(s, "mpiInfo") else 0
res = {n: np.array(s.view(n)) for n in ("x0", "x1", "v0", "v1", "sig0", "sig1", "sig2", "sig3", "vol", "id")}
res["acc"] = np.array([acc["count"], acc["mass"], acc["kinetic_energy"], *acc["momentum"], acc["faces"]["x+"]])
res["removed_ids"] = np.array(s._removedParticles()["id"])
res["reason"] = np.array(s._removedParticles()["reason"])
np.savez(f"{out}.{rank}.npz", **res)
"""


@pytest.mark.parametrize("damage,reason", [(1.0, 1), (0.0, 2)])
def test_removal_on_two_ranks_equals_one_process(tmp_path, damage, reason):
    child = CHILD.replace("float(sys.argv[1]), int(sys.argv[2]), sys.argv[3]", f"{damage}, int(sys.argv[1]), sys.argv[2]")
    one = run_child(tmp_path, child, "child.py", "one", 1200, 1, 300)[0]
    two = run_child(tmp_path, child, "child.py", "two", 1200, 2, 300)
    assert one["acc"][0] == 16 and set(one["reason"]) == {reason}
    for r in two:                                  # the account is global on every rank
        assert np.allclose(r["acc"], one["acc"], rtol=1e-12, atol=1e-12 * abs(one["acc"][3]))
    assert sorted(np.concatenate([r["removed_ids"] for r in two])) == sorted(one["removed_ids"])
    assert all(len(r["id"]) > 0 for r in two)       # both ranks hold particles
    ids = np.concatenate([r["id"] for r in two])
    assert sorted(ids) == sorted(one["id"])
    o1, o2 = np.argsort(one["id"]), np.argsort(ids)
    for n in ("x0", "x1", "v0", "v1", "sig0", "sig1", "sig2", "sig3", "vol"):
        a, b = one[n][o1], np.concatenate([r[n] for r in two])[o2]
        assert np.max(np.abs(a - b)) <= 1e-12 * max(np.max(np.abs(a)), 1e-300), n
