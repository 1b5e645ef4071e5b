"""scripts/paper/tunnel_spalling.py end to end on the coarsest grid and a few hundredths of a millisecond:
the output files and summary.json keys the issue names; a run stopped half-way and continued with
--resume ends in exactly the state of the run made in one go (particles and platen, from the
checkpoints)."""
import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest
from helpers import script_path

pytest.importorskip("yade")
pytest.importorskip("yade_mpm.bodies")   # rigid-body contact (platen, filler)
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
KEYS = {"case", "grid_spacing_m", "particles", "steps", "wall_time_s", "particle_steps_per_s", "final_displacement_mm",
        "axial_stress_MPa_at", "symmetry_damage", "first_damage_location", "removed"}


def run(out, *args):
    env = dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=os.path.join(ROOT, "py"))
    r = subprocess.run([sys.executable, script_path("tunnel_spalling.py"), "--out", str(out), "--spacing", "0.0025",
                        "--checkpoint-every", "0", "--vtu-every", "1e-5", *args], capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-3000:]
    return r.stdout


def test_outputs_and_resume_equals_one_go(tmp_path):
    from yade_mpm import checkpoint
    run(tmp_path / "a", "--cases", "filled_flaw", "--end-time", "2e-5")
    run(tmp_path / "b", "--cases", "filled_flaw", "--end-time", "1e-5")
    log = run(tmp_path / "b", "--cases", "filled_flaw", "--end-time", "2e-5", "--resume")
    t = float(re.search(r"resumed at t = ([0-9.]+) ms", log).group(1))
    assert 0.010 <= t < 0.0115                           # at the step that passed the first run's 10 µs end
    s = json.load(open(tmp_path / "a" / "summary.json"))
    assert set(s) == {"cases"} and len(s["cases"]) == 1
    e = s["cases"][0]
    assert set(e) == KEYS and e["case"] == "filled_flaw" and e["grid_spacing_m"] == 0.0025
    assert e["removed"]["count"] == 0                    # nothing left the grid
    assert e["final_displacement_mm"] == pytest.approx(0.002, rel=0.03)      # 0.1 m/s × 20 µs
    assert [p["displacement_mm"] for p in e["axial_stress_MPa_at"]] == [0.0]
    d = tmp_path / "a" / "filled_flaw"
    for f in ("axial_stress.csv", "particles.pvd", "case.json", "checkpoint.ckpt"):
        assert (d / f).exists(), f
    assert (tmp_path / "a" / "axial_stress.png").exists() and (tmp_path / "a" / "summary.txt").exists()
    assert len(list(d.glob("fields_*ms.png"))) == 1 and len(list(d.glob("particles_*.vtu"))) >= 2
    ha, aa = checkpoint.read(d / "checkpoint.ckpt")
    hb, ab = checkpoint.read(tmp_path / "b" / "filled_flaw" / "checkpoint.ckpt")
    sb = json.load(open(tmp_path / "b" / "summary.json"))["cases"][0]
    assert sb["steps"] == e["steps"]
    for k in aa:
        if k.startswith("solver/") or k in ("yade/bodies", "yade/clock"):
            np.testing.assert_array_equal(aa[k], ab[k], err_msg=k)
    pvd = open(tmp_path / "b" / "filled_flaw" / "particles.pvd").read()
    assert pvd.count("<DataSet") == len(list((tmp_path / "b" / "filled_flaw").glob("particles_*.vtu")))
