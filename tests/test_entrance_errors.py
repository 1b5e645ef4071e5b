"""Bad input at the Python entrance (issue 20, item 6): each case gets a clear error naming the
parameter before any work, and NumPy scalars are numbers wherever a Python number is."""
import json
import math
import os
import struct
import subprocess
import sys

import numpy as np
import pytest
import yade_mpm as ym
from yade_mpm.fields import views
from yade_mpm import checkpoint
from yade_mpm_paper import cases
from yade_mpm.checkpoint import resumable

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROCK = dict(young=1e9, poisson=0.2, density=2500)


def block():
    s = ym.make_solver((0, 0), (1, 1), 0.1)
    ym.add_region(s, ym.ElasticMat(**ROCK), (0, 0), (1, 1))
    return s


def test_id_view_is_read_only():
    s = block()
    for v in (s.view("id"), views(s)["id"]):
        with pytest.raises(ValueError, match="read-only"):
            v[:] = 0                                     # duplicates would silently scramble every id-ordered field
    assert sorted(ym.get(s, "id")) == list(range(s.numParticles))
    s.run(1)                                            # the views still follow the solver's arrays
    assert sorted(s.view("id")) == list(range(s.numParticles))


@pytest.mark.parametrize("kw, name", [(dict(width=0.03), "width"), (dict(width=0.041), "width"), (dict(floor=0.14), "floor"),
                                      (dict(floor=0.12), "floor"), (dict(floor=-0.01), "floor"), (dict(width=math.nan), "width"),
                                      (dict(floor=math.nan), "floor")])
def test_arch_tunnel_specimen_opening_inside(kw, name):
    with pytest.raises(ValueError, match=name) as e:
        cases.arch_tunnel_specimen(0.005, **kw)
    assert "box" not in str(e.value).lower() and "make_solver" not in str(e.value)


def test_nan_geometry_is_named():
    with pytest.raises(ValueError, match=r"make_solver hi = \(nan, 1.0\) m must be finite$"):
        ym.make_solver((0, 0), (math.nan, 1), 0.1)
    with pytest.raises(ValueError, match="removes nothing"):          # a hole: the hint applies
        ym.Circle((math.nan, 0.5), 0.1)


@pytest.mark.parametrize("variant, spacing", [("intact", 0.06), ("intact", 0.0051), ("open", 0.005), ("filled", 0.03)])
def test_uniaxial_spacing_larger_than_the_specimen(variant, spacing):
    with pytest.raises(ValueError, match="spacing"):
        cases.uniaxial_flaw(variant, spacing)


@pytest.mark.parametrize("blocked", ["abc", "zz", "zXYW", 3, None])
def test_filler_blocked_dofs(blocked):
    with pytest.raises(ValueError, match="filler_blocked"):
        cases.uniaxial_flaw("filled", 0.004, filler_blocked=blocked)
    with pytest.raises(ValueError, match="blocked"):
        cases.blocked_dofs(blocked, "blocked")
    assert cases.blocked_dofs("zXYZ") == "zXYZ" and cases.blocked_dofs("") == ""


def test_numpy_scalars_are_numbers():
    s = ym.make_solver((0, 0), (1, 1), np.float32(0.1))
    assert s.spacing == 0.1                                           # the decimal the float32 prints as
    ym.add_region(s, ym.ElasticMat(**ROCK), (0, 0), (1, 1), ppc=np.int64(2))
    t = cases.arch_tunnel_specimen(np.float32(0.005), ppc=np.int64(2))
    assert t.spacing == 0.005 and t.numParticles > 0
    pytest.importorskip("yade")
    u, sc = cases.uniaxial_flaw("open", np.float32(0.002), platen_speed=np.float32(0.1), end_cap_cells=np.int64(1),
                                ramp_time=np.float64(0.0), side_room=np.float32(0.01), with_bodies=False)
    assert u.spacing == 0.002 and u.numParticles > 0


def test_checkpoint_header_that_is_not_an_object(tmp_path):
    p = tmp_path / "list.ckpt"
    hb = json.dumps([1, 2, 3]).encode()
    p.write_bytes(checkpoint.MAGIC + struct.pack("<Q", len(hb)) + hb)
    with pytest.raises(checkpoint.CheckpointError, match="not a JSON object"):
        checkpoint.read(p)


def test_checkpoint_save_onto_a_directory(tmp_path):
    s = block()
    d = tmp_path / "existing"
    d.mkdir()
    with pytest.raises(ValueError, match="is a directory"):
        checkpoint.save(str(d), solvers=s)
    assert os.listdir(tmp_path) == ["existing"] and os.listdir(d) == []   # no <path>.tmp-<pid> left behind


@pytest.mark.parametrize("kw, name", [(dict(every_steps=math.nan), "every_steps"), (dict(every_steps=1.5), "every_steps"),
                                      (dict(every_steps="10"), "every_steps"), (dict(every_minutes="10min"), "every_minutes"),
                                      (dict(every_minutes=math.nan), "every_minutes"), (dict(every_minutes=0), "every_minutes"),
                                      (dict(every_steps=True), "every_steps")])
def test_checkpointer_periods(kw, name):
    with pytest.raises(ValueError, match=name):
        checkpoint.Checkpointer("x.ckpt", **kw)


def test_checkpointer_accepts_numpy_and_parses_the_command_line():
    ck = checkpoint.Checkpointer("x.ckpt", every_steps=np.int64(100), every_minutes=np.float32(2.5))
    assert (ck.every_steps, ck.every_minutes) == (100, 2.5)
    assert resumable.parse_every("10min") == (None, 10.0) and resumable.parse_every("200") == (200, None)
    assert resumable.parse_every("0") == (None, None)
    for bad in ("10 minutes", "-5", "nanmin", "0min", "1e3"):
        with pytest.raises(ValueError, match="checkpoint-every"):
            resumable.parse_every(bad)


@pytest.mark.parametrize("n", [4e9, 4_000_000_000, np.int64(4_000_000_000)])
def test_reserve_beyond_the_memory(n):
    s = ym.make_solver((0, 0), (1, 1), 0.1)
    with pytest.raises(ValueError, match="4,000,000,000"):
        s.reserve(n)
    s.reserve(100)                                      # a sane count still works


@pytest.mark.parametrize("threads", ["1000", "100000", "100000,2"])
def test_oversized_omp_num_threads_is_capped(threads):
    code = ("import yade_mpm as ym, numpy as np\n"
            "s = ym.make_solver((0, 0), (1, 1), 0.1)\n"
            f"ym.add_region(s, ym.ElasticMat(**{ROCK!r}), (0, 0), (1, 1))\n"
            "s.run(3)\nprint('threads', ym.getThreads())\n")
    env = dict(os.environ, OMP_NUM_THREADS=threads, PYTHONPATH=os.path.join(ROOT, "py"))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    cap = max(16, 4 * (os.cpu_count() or 1))
    assert r.returncode == 0, r.stderr[-1500:]
    assert f"threads {cap}" in r.stdout and "OMP_NUM_THREADS" in r.stderr and "cap" in r.stderr
