"""The MPM engine inside YADE's loop: O.run gives exactly the particles of direct stepping, the
clock (O.time, O.iter) follows the MPM steps, O.dt is lowered to the stable step, the engine is
found by label, and a headless `yade -n -x` script works."""
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import yade_mpm as ym

yade = pytest.importorskip("yade")


def _scene():
    s = ym.make_solver((0, 0), (1, 0.25), 1 / 32)
    ym.add_region(s, ym.ElasticMat(young=1e8, poisson=0.25, density=1000.0), (0, 0), (1, 0.25),
                  holes=[ym.Circle((0.5, 0.12), 0.05)])
    s.gravity = (0, -9.81)
    s.addBoundaryPlane(1, -1, 0.0, "fixed")
    return s


def test_o_run_matches_direct_stepping():
    from yade import O
    from yade.wrapper import ForceResetter, NewtonIntegrator
    a, b = _scene(), _scene()
    O.reset()
    e = ym.MpmEngine(a, label="mpmHook")
    O.engines = [ForceResetter(), e.runner(), NewtonIntegrator()]
    O.dt = 1.0                                    # far above the MPM stable step: must be lowered
    O.run(150, True)
    for _ in range(150):
        b.run(1)
    assert O.iter == a.steps == 150
    assert O.time == pytest.approx(a.time, rel=1e-12)
    assert O.dt == a.lastDt < 1e-3                 # lowered to the MPM step used last
    for name in ("pos", "vel", "stress"):
        np.testing.assert_array_equal(ym.get(a, name), ym.get(b, name))
    assert ym.engine.by_label("mpmHook") is e


def test_user_dt_below_stable_is_kept():
    from yade import O
    from yade.wrapper import ForceResetter, NewtonIntegrator
    s = _scene()
    O.reset()
    O.engines = [ForceResetter(), ym.MpmEngine(s, label="mpmSmallDt").runner(), NewtonIntegrator()]
    small = 0.25 * s.stableDt()
    O.dt = small
    O.run(10, True)
    assert O.dt == small and s.lastDt == small and s.steps == 10


def test_headless_yade_script(tmp_path):
    script = tmp_path / "scene.py"
    script.write_text(textwrap.dedent("""
        import yade_mpm as ym
        from yade import O
        from yade.wrapper import ForceResetter, NewtonIntegrator
        s = ym.make_solver((0, 0), (0.5, 0.25), 1 / 16)
        ym.add_region(s, ym.ElasticMat(young=1e8, poisson=0.25, density=1000.0), (0, 0), (0.5, 0.25))
        s.gravity = (0, -9.81)
        s.addBoundaryPlane(1, -1, 0.0, "fixed")
        O.engines = [ForceResetter(), ym.MpmEngine(s, label="mpm").runner(), NewtonIntegrator()]
        O.dt = 1.0
        O.run(20, True)
        print("RESULT", O.iter, s.steps, mpm.label)
    """))
    # YADE must import the package under test, not whatever yade_mpm the global path points to.
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(ym.__file__)))
    r = subprocess.run(["yade", "-n", "-x", str(script)], capture_output=True, text=True, timeout=300,
                       cwd=str(tmp_path), env=env)
    assert "RESULT 20 20 mpm" in r.stdout, r.stdout + r.stderr
