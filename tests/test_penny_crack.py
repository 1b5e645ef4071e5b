"""Pressurised line crack (paper Sec. 3.2) on reduced set-ups that run in seconds: the elastic opening
against Sneddon (Eq. 43) and the stress ahead of the tip against Eq. 44; crack growth from both tips
with the DP–GK rock. The full-size numbers come from scripts/paper/penny_crack.py (doc/validation/penny_crack.md)."""
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import yade_mpm as ym
from yade_mpm_paper import cases
from yade_mpm_paper.validation import sneddon
from helpers import script_path

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run_script(argv):
    """scripts/paper/penny_crack.py through its command line (one thread, this checkout's package);
    returns its summary.json."""
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "py"), OMP_NUM_THREADS="1")
    r = subprocess.run([sys.executable, script_path("penny_crack.py"), *argv], env=env,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = argv[argv.index("--out") + 1]
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


@pytest.fixture(autouse=True)
def one_thread():
    # these runs are small: one thread avoids OpenMP oversubscription on a busy 2-core machine
    n = ym.getThreads()
    ym.setThreads(1)
    yield
    ym.setThreads(n)


def test_sneddon_formulas():
    E, nu, P, c = ym.rocks.GRANITE["young"], ym.rocks.GRANITE["poisson"], 15e6, cases.CRACK_HALF_LENGTH
    # Eq. 43 with a = c is the ellipse 2P(1 − ν²)/E √(c² − x²); zero at and beyond the tips
    assert sneddon.opening_displacement(0.0, P, E, nu, c) == pytest.approx(2 * P * (1 - nu ** 2) / E * c, rel=1e-14)
    assert sneddon.opening_displacement(0.2, P, E, nu, c) == 0.0
    # the crack volume of the ellipse: ∫ 2u_y dx = π c² · 2P(1 − ν²)/E
    x = np.linspace(-c, c, 200001)
    vol = np.trapz(2 * sneddon.opening_displacement(x, P, E, nu, c), x)
    assert vol == pytest.approx(math.pi * c * c * 2 * P * (1 - nu ** 2) / E, rel=1e-5)
    # Eq. 44: far field → 0, near tip ≈ K_I/√(2πr) − P
    assert sneddon.stress_ahead(100.0, P, c) == pytest.approx(P * c * c / (2 * 100.0 ** 2), rel=1e-3)
    r = 1e-6
    assert sneddon.stress_ahead(c + r, P, c) == pytest.approx(sneddon.stress_intensity(P, c) / math.sqrt(2 * math.pi * r) - P, rel=1e-4)
    assert np.isnan(sneddon.stress_ahead(0.1, P, c))
    with pytest.raises(ValueError, match="pressurised half-length"):
        sneddon.opening_displacement(0.0, P, E, nu, c, a=0.3)


def test_elastic_opening_and_tip_stress_small_block(tmp_path):
    """2.5 m block, l = 0.04 m (15.6 k particles): the finite block opens the crack a little more than
    the infinite medium of Sneddon's solution."""
    s = run_script(["--out", str(tmp_path), "--parts", "elastic", "--size", "2.5", "--spacing", "0.04",
                          "--progress", "1000", "--crack-nodes", "shared"])   # the paper's construction (Fig. 7)
    assert abs(s["uy_center_rel_error"]) < 0.10
    assert s["uy_l2_rel_error"] < 0.15
    d = np.loadtxt(tmp_path / "elastic_stress_ahead.csv", delimiter=",", skiprows=1)
    near = d[0]                                  # first particle ahead of the tip
    assert near[0] == pytest.approx(0.21, abs=1e-9)
    assert near[1] == pytest.approx(near[3], rel=0.15)   # σyy vs Eq. 44 at 0.5 particle spacing from the tip
    mid = (d[:, 0] > 0.28) & (d[:, 0] < 0.7)
    assert np.all(np.diff(d[mid, 1]) < 0)      # decays away from the tip
    assert np.sqrt(np.sum((d[mid, 1] - d[mid, 3]) ** 2) / np.sum(d[mid, 3] ** 2)) < 0.35
    for f in ("elastic_uy.csv", "elastic_profiles.png", "summary.json"):
        assert (tmp_path / f).exists()


def test_damage_grows_symmetrically_and_monotonically(tmp_path):
    """1.2 m block at the paper's l = 0.02 m (14 k particles), P = 75 MPa ramped over 4 ms."""
    s = run_script(["--out", str(tmp_path), "--parts", "damage", "--size", "1.2", "--ramp-time", "0.004",
                          "--end-time", "0.2", "--record-every", "0.005", "--laws", "benz-asphaug", "--progress", "1000"])
    rows = np.loadtxt(tmp_path / "crack_extension_benz-asphaug.csv", delimiter=",", skiprows=1)
    left, right = rows[:, 2], rows[:, 3]
    assert np.all(np.abs(left - right) <= 1)
    assert np.all(np.diff(left) >= 0) and np.all(np.diff(right) >= 0)
    assert right[-1] >= 10                       # grows well beyond the initial tip
    assert rows[0, 2] == 0                       # no crack before the load
    # nothing yields (paper: "plasticity never happens"): the rock ahead of the tip reaches the GK threshold
    # long before the DP cone, and a cracked particle (D = 1) keeps no tension that could reach the apex
    assert s["plastic_particles"] == 0


def test_a_stopped_run_is_named_and_the_others_still_run(tmp_path, monkeypatch):
    """A convergence run that the solver stops (run_elastic raises the solver's error at the coarse spacing) is named under
    "stopped" in summary.json with its message, the other spacing still runs and is reported, exit status 1; a bad
    --laws entry is refused before any run."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("penny_crack", script_path("penny_crack.py"))
    pc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(pc)
    real = pc.run_elastic

    def run_elastic(size, h, *a, **k):
        if abs(h - 0.16) < 1e-12:
            raise ym.MpmSimulationError("MPM stopped at step 3: test failure")
        return real(size, h, *a, **k)
    monkeypatch.setattr(pc, "run_elastic", run_elastic)
    argv = ["--out", str(tmp_path), "--parts", "convergence", "--size", "2.4", "--conv-spacings", "0.16,0.08",
            "--elastic-max-transits", "2", "--progress", "1000"]
    with pytest.raises(SystemExit) as e:
        pc.main(argv)
    assert e.value.code == 1
    s = json.load(open(tmp_path / "summary.json"))
    assert s["stopped"] == [dict(run="convergence l=0.16", error="MPM stopped at step 3: test failure")]
    assert [c["spacing_m"] for c in s["convergence"]] == [0.08]
    with pytest.raises(SystemExit) as e:
        pc.main(["--out", str(tmp_path / "bad"), "--parts", "damage", "--laws", "benz-asphaug,nope"])
    assert e.value.code == 2 and not (tmp_path / "bad").exists()
