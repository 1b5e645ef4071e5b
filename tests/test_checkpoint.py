"""Checkpoint / resume (yade_mpm.checkpoint): a run stopped half-way, saved, rebuilt and resumed gives
the particle arrays, body states and clock of the uninterrupted run bit for bit; truncated, corrupted,
other-version and other-scene checkpoints are refused before anything changes; SIGINT during a run
leaves a loadable checkpoint that resumes (in another process) onto the uninterrupted run."""
import json
import os
import signal
import struct
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import yade_mpm as ym
from yade_mpm.fields import views
from yade_mpm import checkpoint

yade = pytest.importorskip("yade")

SCENE = textwrap.dedent("""
    import yade_mpm as ym
    from yade import O, utils
    from yade.wrapper import ForceResetter, NewtonIntegrator

    def build(radius=0.03):
        # DP–GK block with a hole, squeezed (plastic + damaged particles, re-sorts every 7 steps),
        # plus a free YADE sphere under gravity: MPM state and body state both evolve.
        O.reset()
        mat = ym.rocks.granite_dpgk()
        s = ym.make_solver((0, 0), (0.3, 0.15), 0.01, margin=1)
        ym.add_region(s, mat, (0, 0), (0.3, 0.15), holes=[ym.Circle((0.15, 0.07), radius)])
        s.gravity = (0, -9.81)
        s.addBoundaryPlane(1, -1, 0.0, "fixed")
        s.damping, s.sortPeriod = 0.05, 7
        s.view("v0")[:] = 40 * (s.view("x0") - 0.15)
        s.view("v1")[:] = -150 * s.view("x1")   # strong enough vertical squeeze that intact rock yields
        s.requestSort()
        O.bodies.append(utils.sphere((1, 1, 0), 0.1))
        O.bodies[0].state.vel = (0.3, 1.1, 0)
        O.engines = [ForceResetter(), ym.MpmEngine(s, label="mpmCk").runner(), NewtonIntegrator(gravity=(0, -9.81, 0))]
        O.dt = 1.0
        return s
""")
exec(SCENE)   # defines build() here; the subprocess below runs the same text


def _state(s):
    from yade import O
    arrays = {k: np.array(v) for k, v in views(s).items()}      # storage order: the order is state too
    b = O.bodies[0].state
    return arrays, (tuple(b.pos), tuple(b.vel), tuple(b.angVel), tuple(b.ori)), (O.time, O.iter, O.dt, s.time, s.steps)


def _assert_same(a, b):
    assert a[0].keys() == b[0].keys()
    for k in a[0]:
        np.testing.assert_array_equal(a[0][k], b[0][k], err_msg=k)
    assert a[1] == b[1] and a[2] == b[2]


def test_resume_is_bitwise(tmp_path):
    from yade import O
    N = 40
    s = build()
    O.run(N, True)
    ref = _state(s)
    assert np.count_nonzero(s.view("damage")) > 0 and np.count_nonzero(s.view("epsP")) > 0   # a loaded scene
    s = build()
    O.run(N // 2 + 1, True)                        # an odd split: the sort phase (steps % 7) is mid-period
    checkpoint.save(tmp_path / "c.ckpt")
    O.run(3, True)                                 # the scene moves on after saving
    s = build()                                    # as a new process would: rebuild, then load
    checkpoint.load(tmp_path / "c.ckpt")
    assert s.steps == O.iter == N // 2 + 1
    O.run(N - N // 2 - 1, True)
    _assert_same(ref, _state(s))
    assert ym.engine.by_label("mpmCk").solver is s


@pytest.mark.parametrize("update", ["pic", "flip"])
def test_solver_only_resume_is_bitwise(tmp_path, update):
    def make():
        s = ym.make_solver((0, 0), (0.2, 0.1), 0.01)
        s.velocityUpdate = update                 # FLIP: v_p is state, Σ ψ_i v_i is recomputed each step
        ym.add_region(s, ym.rocks.granite(), (0, 0), (0.2, 0.1))
        s.addBoundaryPlane(1, -1, 0.0, "fixed")
        s.gravity, s.sortPeriod = (0, -9.81), 5
        s.view("v0")[:] = 3 * np.sin(20 * s.view("x1"))
        s.requestSort()
        return s
    _assert_resume_bitwise(make, 30, 13, tmp_path / "s.ckpt")


def _assert_resume_bitwise(make, n, split, path, before_load=lambda b, c: None):
    """make() run n steps in one go vs split steps, saved (solver only), a fresh make() loaded (after
    before_load(saved solver, fresh solver)) and the rest: every particle array and the clock bitwise."""
    a = make()
    a.run(n)
    b = make()
    b.run(split)
    checkpoint.save(path, solvers=b, yade=False)
    c = make()
    before_load(b, c)
    checkpoint.load(path, solvers=c)
    c.run(n - split)
    for k, v in views(a).items():
        np.testing.assert_array_equal(v, views(c)[k], err_msg=k)
    assert (a.time, a.steps, a.lastDt) == (c.time, c.steps, c.lastDt) and a.settings() == c.settings()
    return c


def test_two_material_resume_is_bitwise_and_restores_every_setting(tmp_path):
    """Rock with a grout inclusion: the storage order after the sorts differs from the fresh build, so the
    material index (a read-only view) is restored through setParticleMaterial with the saved thresholds.
    Every setting of Solver.settings() (the one declaration) comes back from the checkpoint."""
    def make():
        s = ym.make_solver((0, 0), (0.2, 0.1), 0.01)
        ym.add_region(s, ym.rocks.granite_dpgk(), (0, 0), (0.2, 0.1), holes=[ym.Circle((0.1, 0.05), 0.02)])
        ym.add_region(s, ym.rocks.cement_grout(), (0.08, 0.03), (0.12, 0.07), keep=lambda x: np.hypot(x[:, 0] - 0.1, x[:, 1] - 0.05) < 0.02)
        s.addBoundaryPlane(1, -1, 0.0, "fixed")
        s.gravity, s.sortPeriod, s.damping = (0, -9.81), 5, 0.02
        s.view("v0")[:] = 30 * (s.view("x0") - 0.1)
        s.requestSort()
        return s
    def other_settings(b, c):
        assert not np.array_equal(c.view("material"), b.view("material"))   # the sorts moved the grout particles
        c.gravity, c.damping, c.courant, c.autoDt, c.fixedDt = (1.0, 2.0), 0.3, 0.2, False, 1e-9
        c.tractionRampTime, c.sortPeriod, c.trackEnergy = 0.5, 3, True
    _assert_resume_bitwise(make, 24, 11, tmp_path / "m.ckpt", other_settings)


def test_old_format_and_other_settings_are_refused(saved, tmp_path):
    s = build()
    before = _state(s)
    old = tmp_path / "old.ckpt"                     # format 1: the settings as a hand-written list
    _rewrite(saved, old, edit_header=lambda h: h.update(format=1))
    with pytest.raises(checkpoint.CheckpointError, match=rf"format version 1, this yade_mpm reads version {checkpoint.FORMAT} only .*rerun from the start"):
        checkpoint.load(old)
    other = tmp_path / "other.ckpt"
    _rewrite(saved, other, edit_header=lambda h: h["settings"]["mpmCk"].update(oldSetting=1.0))
    with pytest.raises(checkpoint.CheckpointError, match=r"another scene: solver mpmCk: settings \[.*'oldSetting'"):
        checkpoint.load(other)
    _assert_same(before, _state(s))


def _rewrite(src, dst, edit_header=None, payload=lambda p: p, raw=lambda r: r):
    data = open(src, "rb").read()
    p = len(checkpoint.MAGIC)
    (hl,) = struct.unpack("<Q", data[p:p + 8])
    header = json.loads(data[p + 8:p + 8 + hl])
    body = payload(data[p + 8 + hl:])
    if edit_header:
        edit_header(header)
    hb = json.dumps(header).encode()
    open(dst, "wb").write(raw(checkpoint.MAGIC + struct.pack("<Q", len(hb)) + hb + body))


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    from yade import O
    path = tmp_path_factory.mktemp("ck") / "good.ckpt"
    build()
    O.run(10, True)
    checkpoint.save(path, meta={"case": "block", "spacing": 0.01})
    return path


@pytest.mark.parametrize("kind, message", [
    ("truncated", "truncated"), ("flipped", "corrupted"), ("format", "format version"),
    ("build", "another build"), ("not", "not a yade-mpm checkpoint"), ("header", "truncated")])
def test_bad_checkpoint_is_refused_and_nothing_changes(saved, tmp_path, kind, message):
    from yade import O
    bad = tmp_path / "bad.ckpt"
    if kind == "truncated":
        _rewrite(saved, bad, raw=lambda r: r[:-1000])
    elif kind == "flipped":
        _rewrite(saved, bad, payload=lambda p: p[:500] + bytes([p[500] ^ 1]) + p[501:])
    elif kind == "format":
        _rewrite(saved, bad, edit_header=lambda h: h.update(format=checkpoint.FORMAT + 1))
    elif kind == "build":
        _rewrite(saved, bad, edit_header=lambda h: h.update(build="0123456789abcdef"))
    elif kind == "not":
        bad.write_bytes(b"PK\x03\x04 some zip file")
    else:
        bad.write_bytes(open(saved, "rb").read()[:len(checkpoint.MAGIC) + 20])
    s = build()
    before = _state(s)
    with pytest.raises(checkpoint.CheckpointError, match=message):
        checkpoint.load(bad)
    _assert_same(before, _state(s))                 # never half-loaded


def test_other_scene_is_refused(saved):
    s = build(radius=0.04)                          # another hole: other particles
    before = _state(s)
    with pytest.raises(checkpoint.CheckpointError, match=r"another scene: solver .*particles"):
        checkpoint.load(saved)
    _assert_same(before, _state(s))
    build()
    with pytest.raises(checkpoint.CheckpointError, match=r"another scene: meta.case"):
        checkpoint.load(saved, meta={"case": "tunnel", "spacing": 0.01})
    from yade import O, utils
    O.bodies.append(utils.sphere((2, 1, 0), 0.1))   # same MPM scene, another YADE scene
    with pytest.raises(checkpoint.CheckpointError, match="YADE bodies"):
        checkpoint.load(saved)


CHILD = SCENE + textwrap.dedent("""
    import sys
    from yade_mpm import checkpoint
    path, out = sys.argv[1], sys.argv[2]
    s = build()
    ck = checkpoint.Checkpointer(path)
    with ck.signals():
        for chunk in range(100000):
            O.run(5, True)
            if chunk == 2:
                print("running", flush=True)
            if ck.stop_requested:
                ck.save(O.iter)
                open(out, "w").write(f"{O.iter}\\n")        # the outputs so far
                break
    print("stopped cleanly at", O.iter, flush=True)
""")


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_signal_leaves_a_checkpoint_that_resumes_bitwise(tmp_path, sig):
    from yade import O
    script = tmp_path / "child.py"
    script.write_text(CHILD)
    ckpt, out = tmp_path / "run.ckpt", tmp_path / "out.txt"
    env = dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=os.pathsep.join(sys.path))
    p = subprocess.Popen([sys.executable, str(script), str(ckpt), str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, env=env)
    for line in p.stdout:
        if line.startswith("running"):
            break
    p.send_signal(sig)
    rest, err = p.communicate(timeout=120)
    assert p.returncode == 0, err
    assert "stopped cleanly" in rest
    k = int(out.read_text())
    assert k >= 15 and k % 5 == 0
    n = ym.getThreads()
    ym.setThreads(1)                                # the child ran with one thread
    try:
        s = build()
        checkpoint.load(ckpt)                       # written by another process
        assert s.steps == O.iter == k
        O.run(5, True)
        resumed = _state(s)
        s = build()
        O.run(k + 5, True)
        _assert_same(_state(s), resumed)
    finally:
        ym.setThreads(n)


def test_contact_scene_resume_is_bitwise(tmp_path):
    """The uniaxial specimen with its rigid platen (prescribed) and free rigid filler, both under the default
    kinematic contact law: saved mid-run and resumed into a fresh build, the particle arrays and every body's
    state equal the uninterrupted run's bits (the contact keeps no state between steps but what the scene
    rebuilds: detection, exclusions and impulses are made anew each step)."""
    from yade import O
    from yade_mpm_paper import cases

    scene = {}

    def build():
        s, scene["sc"] = cases.uniaxial_flaw("filled", 0.002, mu_con=0.4, label="mpmCkContact")
        return s

    def state(s):
        bodies = [(tuple(b.state.pos), tuple(b.state.vel), tuple(b.state.angVel), tuple(b.state.ori)) for b in O.bodies]
        return {k: np.array(v) for k, v in views(s).items()}, bodies, (O.time, O.iter, s.time, s.steps)

    N, split = 60, 31
    s = build()
    O.run(N, True)
    ref = state(s)
    assert abs(scene["sc"]["axial_stress"]()) > 1e5, scene["sc"]["axial_stress"]()   # the platen presses the rock
    s = build()
    O.run(split, True)
    checkpoint.save(tmp_path / "contact.ckpt")
    s = build()
    checkpoint.load(tmp_path / "contact.ckpt")
    O.run(N - split, True)
    got = state(s)
    for k in ref[0]:
        np.testing.assert_array_equal(ref[0][k], got[0][k], err_msg=k)
    assert ref[1] == got[1] and ref[2] == got[2]
