"""Material that leaves the grid (Solver.outside): debris is removed and accounted for, the body reaching the
edge stops the run with a clear message; ids, fields, VTU output, checkpoints and threads keep their meaning."""
import numpy as np
import pytest

import yade_mpm as ym
from yade_mpm_paper.validation import stability_cases as sc

END = sc.debris_end_time()


def _fixed_dt(s):
    """One Δt for every speed (the stable step of the 200 m/s scene): runs with and without the fragment
    take the same steps, so the block's particles can be compared bit for bit."""
    return 0.999 * s.courant * s.spacing / (s.waveSpeed() + 200.0)


def _run(speed, fragment=True, threads=None, end=END):
    s, block, frag = sc.debris_scene(speed, fragment=fragment)
    s.autoDt, s.fixedDt = False, _fixed_dt(s)
    if threads:
        ym.setThreads(threads)
    frag_state = None
    if fragment:
        f = ym.fields(s, ["mass", "momentum", "vel"])
        m, p, v = f["mass"][frag], f["momentum"][frag], f["vel"][frag]
        frag_state = dict(mass=m.sum(), momentum=p.sum(axis=0), ke=0.5 * np.sum(m * np.sum(v * v, axis=1)))
    s.run(int(np.ceil(end / s.fixedDt)))
    return s, block, frag, frag_state


@pytest.fixture(scope="module")
def reference():
    """The block alone (no fragment), the same steps."""
    s, block, _, _ = _run(5.0, fragment=False)
    return ym.fields(s), block


@pytest.mark.parametrize("speed", sc.DEBRIS_SPEEDS)
def test_fragment_thrown_at_the_edge_is_removed_and_the_block_is_untouched(speed, reference):
    s, block, frag, f0 = _run(speed)
    assert s.time >= END * (1 - 1e-12)                            # the run reached its end time
    acc = ym.removed(s)
    assert acc["count"] == len(frag) == 16 and acc["faces"]["x+"] == 16
    # the account is the fragment's mass, momentum and kinetic energy (free flight, D = 1: no stress)
    assert acc["mass"] == pytest.approx(f0["mass"], rel=1e-14)
    assert np.allclose(acc["momentum"], f0["momentum"], rtol=1e-9, atol=1e-9 * abs(f0["momentum"][0]))
    assert acc["kinetic_energy"] == pytest.approx(f0["ke"], rel=1e-9)
    assert sorted(acc["particles"]["id"]) == sorted(frag) and set(acc["particles"]["reason"]) == {"damaged"}
    assert np.all(acc["particles"]["pos"][:, 0] >= s.origin[0] + s.cells[0] * s.spacing)
    # the block's particles, mass and stress: bit for bit those of the run without the fragment
    ref, rblock = reference
    f = ym.fields(s)
    assert np.array_equal(block, rblock)
    for name in ("pos", "vel", "mass", "volume", "stress", "damage", "plastic_strain"):
        assert np.array_equal(f[name][block], ref[name][rblock]), name
    assert s.numParticles == len(block)
    # removed ids keep their rows: NaN in the float fields, the removed flag set
    assert f["removed"][frag].all() and not f["removed"][block].any()
    assert np.isnan(f["pos"][frag]).all() and np.isnan(f["stress"][frag]).all() and np.isnan(f["mass"][frag]).all()
    assert np.array_equal(f["id"], np.arange(len(block) + len(frag)))
    # momentum: particles + removed = initial (no gravity, no walls)
    p_all = np.nansum(f["momentum"], axis=0) + np.asarray(acc["momentum"])
    p_ref = np.sum(ref["momentum"], axis=0)
    assert np.allclose(p_all, p_ref + f0["momentum"], rtol=0, atol=1e-9 * (abs(f0["momentum"][0]) + 1))


def test_intact_body_pushed_off_the_grid_stops_with_particle_face_and_position():
    s, _ = sc.case_grid_edge(True)
    assert s.outside == "remove-debris"                            # the default
    with pytest.raises(ym.MpmSimulationError) as e:
        s.run(10000)
    msg = str(e.value)
    pid = int(msg.split("particle id ")[1].split()[0])
    assert "left the grid along axis 0 through its x+ face" in msg and "intact material of the body" in msg
    x = ym.get(s, "pos")[pid]
    assert f"position ({x[0]:.6g}, {x[1]:.6g}) m" in msg
    assert s._removedAccount()["count"] == 0


def test_outside_policies_stop_and_remove():
    s, _, frag = sc.debris_scene(50.0)
    s.outside = "stop"
    with pytest.raises(ym.MpmSimulationError, match=r"particle id \d+ left the grid along axis 0 through its x\+ face .*outside = 'stop'"):
        s.run(5000)
    # 'remove' takes out anything that leaves, the body too
    s, _ = sc.case_grid_edge(True)
    s.outside = "remove"
    n = s.numParticles
    while s.time < 3e-3:               # part of the body is off the grid (400 steps at C = 0.5; at C = 1 all of it by 400)
        s.run(1)
    acc = s._removedAccount()
    assert acc["count"] > 0 and s.numParticles == n - acc["count"] and acc["faces"]["x+"] == acc["count"]
    with pytest.raises(ValueError, match="outside must be one of 'stop', 'remove' or 'remove-debris'"):
        s.outside = "ignore"


def test_detached_intact_fragment_is_debris():
    """An intact (D = 0) fragment apart from the block is detached from the body: removed."""
    s, block, frag = sc.debris_scene(50.0)
    s.view("damage")[:] = 0.0
    s.requestSort()
    s.run(1500)
    r = ym.removed(s)
    assert r["count"] == 16 and set(r["particles"]["reason"]) == {"detached"}


def test_vtu_leaves_removed_particles_out(tmp_path):
    s, _, frag, _ = _run(200.0, end=0.002)
    pos, data = ym.output.particle_fields(s)
    assert len(pos) == s.numParticles and np.all(np.isfinite(pos)) and not np.isin(data["id"], frag).any()
    path = ym.output.VtuSeries(str(tmp_path)).write(s)
    assert f'NumberOfPoints="{s.numParticles}"' in open(path).read()


def _all_bits(s):
    f = ym.fields(s)
    return {k: np.asarray(v).tobytes() for k, v in f.items()} | {"acc": repr(s._removedAccount())}


def test_one_and_two_threads_give_the_same_bits_with_a_removal():
    old = ym.getThreads()
    try:
        a = _all_bits(_run(50.0, threads=1, end=0.004)[0])     # the fragment is gone after ~2 ms
        b = _all_bits(_run(50.0, threads=2, end=0.004)[0])
    finally:
        ym.setThreads(old)
    assert a == b


def test_checkpoint_after_a_removal_resumes_bit_identical(tmp_path):
    def build():
        s, _, _ = sc.debris_scene(50.0)
        s.autoDt, s.fixedDt = False, _fixed_dt(s)
        return s
    s = build()
    while s._removedAccount()["count"] in (0, 16):                  # part of the fragment removed, part not
        s.run(20)
        assert s.steps < 5000
    k = s._removedAccount()["count"]
    path = str(tmp_path / "run.ckpt")
    ym.checkpoint.save(path, s, yade=False)
    s.run(300)
    r = build()
    ym.checkpoint.load(path, r, yade=False)
    assert r._removedAccount()["count"] == k and r.numParticles == s.numParticles + s._removedAccount()["count"] - k
    r.run(300)
    assert _all_bits(r) == _all_bits(s)
