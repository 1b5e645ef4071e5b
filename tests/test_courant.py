"""The Courant number C: one declaration (pkg-mpm/core/SolverSettings.hpp) that the scripts' --courant reads,
and the measurements of the time-step study (yade_mpm_paper.fidelity.courant) on constructed files with known answers."""
import os
import subprocess
import sys

import numpy as np
import pytest

import yade_mpm as ym
from yade_mpm import output
from yade_mpm_paper.fidelity import courant as fidelity_courant
from helpers import script_path

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_setting_default_is_the_solver_default():
    s = ym.make_solver((0.0, 0.0), (1.0, 1.0), 0.1)
    assert ym.scene.setting_default("courant") == s.courant
    assert ym.scene.check_courant(None) == s.courant
    assert ym.scene.check_courant(0.25) == 0.25


@pytest.mark.parametrize("bad", [0.0, -0.5, 1.5])
def test_check_courant_names_the_option_and_range(bad):
    with pytest.raises(ValueError, match=r"--courant = .*\(0, 1\]"):
        ym.scene.check_courant(bad)


def test_velocity_update_choices_read_from_the_declaration():
    """--velocity-update's choices are the declared words of Solver.velocityUpdate (settingsTable), not a second list."""
    s = ym.make_solver((0.0, 0.0), (1.0, 1.0), 0.1)
    row = next(p for p in s.settingsTable() if p["name"] == "velocityUpdate")
    assert ym.scene.setting_choices("velocityUpdate") == tuple(row["choices"]) == ("pic", "flip")
    assert row["default"] == s.velocityUpdate
    for w in ym.scene.setting_choices("velocityUpdate"):
        s.velocityUpdate = w                      # every listed word is accepted
    with pytest.raises(ValueError, match="'courant' is not a choice setting"):
        ym.scene.setting_choices("courant")


def test_unknown_setting_named():
    with pytest.raises(ValueError, match="unknown solver setting 'courantt'"):
        ym.scene.setting_default("courantt")


@pytest.mark.parametrize("script", ["tunnel_spalling.py", "uniaxial_flaw.py", "circular_opening.py", "penny_crack.py"])
def test_scripts_read_the_solver_default(script):
    """--help shows the solver's C (not a second declaration); a value out of range is refused before any work."""
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "py"))
    h = subprocess.run([sys.executable, script_path(script), "--help"], capture_output=True, text=True, env=env)
    assert h.returncode == 0, h.stderr
    assert f"(default: the solver's, {ym.scene.setting_default('courant'):g})" in " ".join(h.stdout.split())
    r = subprocess.run([sys.executable, script_path(script), "--out", "/nonexistent/x", "--courant", "1.5"],
                       capture_output=True, text=True, env=env)
    assert r.returncode != 0 and "--courant = 1.5" in r.stderr + r.stdout
    assert not os.path.exists("/nonexistent/x")


def test_read_vtu_round_trip(tmp_path):
    rng = np.random.default_rng(3)
    pts = rng.random((17, 2))
    v, i = rng.random((17, 2)), np.arange(17)
    path = str(tmp_path / "a.vtu")
    output.write_vtu(path, pts, {"velocity": v, "id": i})
    p, d = fidelity_courant.read_vtu(path)
    assert np.array_equal(p[:, :2], pts) and np.all(p[:, 2] == 0)
    assert np.array_equal(d["velocity"], v) and np.array_equal(d["id"], i)


def test_platen_penetration_known_row(tmp_path):
    """A top row whose centres sit 3 µm and 5 µm closer to the moved platen face than d0 = dp/2."""
    dp, top, disp = 1e-3, 0.15, 0.4e-3
    face = top - disp
    x = np.arange(10) * dp + dp / 2
    row_y = face - dp / 2 + np.where(np.arange(10) % 2, 5e-6, 3e-6)
    below = np.column_stack([x, np.full(10, face - 1.5 * dp)])
    pts = np.vstack([np.column_stack([x, row_y]), below])
    path = str(tmp_path / "b.vtu")
    output.write_vtu(path, pts, {"id": np.arange(20)})
    pen = fidelity_courant.platen_penetration(path, top, disp, dp)
    assert pen["particles"] == 10
    assert pen["mean_m"] == pytest.approx(4e-6, rel=1e-9) and pen["max_m"] == pytest.approx(5e-6, rel=1e-9)
