"""Bad input raises ValueError naming the parameter (and range) before any work is done."""
import math

import numpy as np
import pytest
import yade_mpm as ym


@pytest.mark.parametrize("kw, name", [
    (dict(young=0.0, poisson=0.2, density=2500), "young"),
    (dict(young=-1e9, poisson=0.2, density=2500), "young"),
    (dict(young=1e9, poisson=0.5, density=2500), "poisson"),
    (dict(young=1e9, poisson=-1.0, density=2500), "poisson"),
    (dict(young=1e9, poisson=0.2, density=0.0), "density"),
    (dict(young=float("nan"), poisson=0.2, density=2500), "young"),
    (dict(young=1e9, poisson=float("nan"), density=2500), "poisson"),
])
def test_elastic_parameters(kw, name):
    with pytest.raises(ValueError, match=name):
        ym.ElasticMat(**kw)


def test_dpgk_parameters():
    base = dict(young=1e9, poisson=0.2, density=2500, frictionAngle=math.radians(30), dilatancyAngle=0.1,
                cohesion=1e6, weibullK=1e30, weibullM=8)
    ym.DpGkMat(**base)
    for k, v in [("frictionAngle", math.pi), ("dilatancyAngle", 1.0), ("cohesion", -1.0), ("weibullM", 0.0),
                 ("critPlasticStrain", 0.0), ("growthLaw", 3)]:
        with pytest.raises(ValueError, match=k):
            ym.DpGkMat(**dict(base, **{k: v}))
    with pytest.raises(TypeError, match="unknown parameter"):
        ym.DpGkMat(**dict(base, friction=0.5))


def _solver():
    return ym.make_solver((0, 0), (1, 1), 0.1)


def test_empty_particle_set():
    s = _solver()
    s.setMaterial(ym.ElasticMat(young=1e9, poisson=0.2, density=2500))
    with pytest.raises(ValueError, match="particles"):
        s.step()
    with pytest.raises(ValueError, match="empty"):
        s.addParticles(np.zeros((0, 2)), np.zeros(0), np.zeros(0))


def test_particle_outside_grid_and_nan_position():
    s = _solver()
    with pytest.raises(ValueError, match="outside the grid"):
        s.addParticles(np.array([[0.5, 2.0]]), np.array([1e-3]), np.array([1.0]))
    with pytest.raises(ValueError, match="not finite"):
        s.addParticles(np.array([[np.nan, 0.5]]), np.array([1e-3]), np.array([1.0]))
    with pytest.raises(ValueError, match="volume"):
        s.addParticles(np.array([[0.5, 0.5]]), np.array([0.0]), np.array([1.0]))
    with pytest.raises(ValueError, match="mass"):
        s.addParticles(np.array([[0.5, 0.5]]), np.array([1e-3]), np.array([np.inf]))
    assert s.numParticles == 0                       # nothing was added by the failed calls


def test_fixed_dt_above_stable_step():
    s = _solver()
    ym.add_region(s, ym.ElasticMat(young=1e9, poisson=0.2, density=2500), (0, 0), (1, 1))
    s.autoDt = False
    s.fixedDt = 10 * s.stableDt()
    with pytest.raises(ValueError, match="dt .* exceeds the stable time step"):
        s.step()
    assert s.steps == 0 and s.time == 0
    with pytest.raises(ValueError, match="fixedDt"):
        s.fixedDt = -1.0


def test_nan_in_state_and_settings():
    s = _solver()
    ym.add_region(s, ym.ElasticMat(young=1e9, poisson=0.2, density=2500), (0, 0), (1, 1))
    with pytest.raises(ValueError, match="initial stress"):
        ym.set_initial_stress(s, (np.nan, 0, 0, 0))
    with pytest.raises(ValueError, match="gravity"):
        s.gravity = (0, np.nan)
    with pytest.raises(ValueError, match="damping"):
        s.damping = 1.5
    with pytest.raises(ValueError, match="courant"):
        s.courant = 0.0
    s.view("v0")[3] = np.nan                         # NaN written straight into a live view
    s.requestSort()
    with pytest.raises(ValueError, match="velocity of particle id"):
        s.step()


def test_grid_parameters():
    with pytest.raises(ValueError, match="spacing"):
        ym.make_solver((0, 0), (1, 1), 0.0)
    with pytest.raises(ValueError, match="grid spacing"):
        ym.Solver2D((0, 0), -1.0, (4, 4))
    with pytest.raises(ValueError, match="cells"):
        ym.Solver2D((0, 0), 1.0, (0, 4))
    with pytest.raises(ValueError, match="boundary kind"):
        _solver().addBoundaryPlane(0, -1, 0.0, "sticky")


def test_position_corrupted_through_a_view_stops_cleanly():
    # No requestSort() after the edit: the step itself must catch it (not crash, not write NaN).
    s = _solver()
    ym.add_region(s, ym.ElasticMat(young=1e9, poisson=0.2, density=2500), (0, 0), (1, 1))
    s.step()
    victim = int(s.view("id")[7])
    s.view("x1")[7] = np.nan
    with pytest.raises(ym.MpmSimulationError, match=f"step 1 .*particle id {victim} has a position outside the grid or not finite"):
        s.step()
