"""Hazards of the core API (issue 7 item 5), each checked against what happened before the fix:
live NumPy views and a second addParticles, the clock and energy account, positions/masses written
through views without requestSort(), vmax after lowering velocities, the state after a failed step,
and the solver settings declared once (name, unit, range, doc)."""
import numpy as np
import pytest
import yade_mpm as ym

ROCK = ym.ElasticMat(young=1e9, poisson=0.25, density=2000.0)


def _scene(hi=(0.4, 0.4), l=0.02):
    s = ym.make_solver((0, 0), hi, l)
    ym.add_region(s, ROCK, (0, 0), (hi[0], hi[1] / 2))
    return s


def _more(s):
    x = np.array([[0.1, 0.3], [0.2, 0.3]])
    return x, np.full(2, 1e-4), np.full(2, 0.2)


def test_second_add_particles_refused_while_views_alive_unless_reserved():
    s = _scene()
    v = s.view("x0")
    with pytest.raises(ValueError, match=r"addParticles: 1 NumPy view\(s\) .* would move the arrays"):
        s._addParticles(*_more(s))
    n = s.numParticles
    assert s.numParticles == n and v[0] == s.view("x0")[0]
    del v                                             # no view left: the arrays may move
    s._addParticles(*_more(s))
    assert s.numParticles == n + 2
    # reserve first: views taken afterwards stay on the same memory while adding
    s.reserve(n + 10)
    v = s.view("x1")
    before = v.__array_interface__["data"][0]
    s._addParticles(*_more(s))
    assert s.view("x1").__array_interface__["data"][0] == before
    assert np.array_equal(v, s.view("x1")[:len(v)])


def test_clock_and_energy_only_through_checked_setters():
    s = _scene()
    for name, bad in (("time", -1.0), ("time", np.nan), ("time", np.inf), ("steps", -3), ("externalWork", np.nan)):
        with pytest.raises(ValueError, match=name):
            setattr(s, name, bad)
    assert (s.time, s.steps, s.externalWork) == (0.0, 0, 0.0)
    s.tractionRampTime = 1.0
    assert s._loadScale(s.time) == 0.0                 # time = -1 used to give a ramp factor of −1 (reversed load)
    s.steps, s.time, s.externalWork = 7, 0.5, 2.0     # a resumed run sets its clock
    s.run(1)
    assert s.steps == 8 and s.time == pytest.approx(0.5 + s.lastDt, rel=1e-15)


def test_position_moved_past_block_reach_without_request_sort():
    s = _scene(hi=(0.8, 0.4))
    s.run(1)                                          # sorted into blocks of 8 cells
    x0 = s.view("x0")
    p = int(np.argmin(x0))                            # a particle of the leftmost blocks
    pid = int(s.view("id")[p])
    x0[p] = 0.7                                       # 35 cells to the right, still on the grid
    with pytest.raises(ym.MpmSimulationError, match=f"particle id {pid} at .* beyond the cells its block may reach .*requestSort"):
        s.run(1)
    s.requestSort()                                   # the documented way: re-sort, then step
    s.run(1)
    assert s.steps == 2


def test_position_written_through_a_view_already_deleted_is_still_checked():
    """P2G checks reach, mass and volume only while a view is alive or was taken since the last accepted
    step (a step without views pays nothing): a view deleted before the step still counts, and a refused
    step does not clear that."""
    s = _scene(hi=(0.8, 0.4))
    s.run(1)
    p = int(np.argmin(s.view("x0")))
    pid = int(s.view("id")[p])
    s.view("x0")[p] = 0.7                             # a temporary view: gone before the step
    for _ in range(2):                                # refused again: the particle is still out of reach
        with pytest.raises(ym.MpmSimulationError, match=f"particle id {pid} at .* beyond the cells its block may reach"):
            s.run(1)
    assert s.steps == 1
    s.requestSort()
    s.run(1)
    s.run(1)                                          # no view since the last step: the plain P2G
    assert s.steps == 3


def test_bad_mass_through_a_view_names_particle_and_quantity():
    s = _scene()
    s.run(1)
    p = 17
    pid = int(s.view("id")[p])
    s.view("mass")[p] = -1.0
    with pytest.raises(ym.MpmSimulationError, match=f"in P2G: particle id {pid} has mass m = -1 kg"):
        s.run(1)                                      # was reported as another particle's "non-finite stress"
    s.requestSort()
    with pytest.raises(ValueError, match=f"mass of particle id {pid} = -1 kg must be finite and > 0"):
        s.run(1)
    s.view("mass")[p] = s.view("mass")[p + 1]         # the particles were untouched: fixing the mass is enough
    s.run(1)


def test_max_speed_refreshed_when_velocities_lowered_through_views():
    s = _scene()
    c = np.sqrt((ROCK.bulk() + 4 * ROCK.shear() / 3) / ROCK.density)
    s.view("v0")[:] = 200.0
    s.requestSort()
    assert s.stableDt() == pytest.approx(s.courant * s.spacing / (c + 200.0), rel=1e-12)
    s.view("v0")[:] = 0.0
    s.requestSort()
    assert s.maxSpeed == 0.0                          # was kept at 200 m/s: Δt stayed 1.5 × too small
    assert s.stableDt() == pytest.approx(s.courant * s.spacing / c, rel=1e-12)


def test_failed_step_with_particles_partly_updated_refuses_to_continue():
    s = ym.make_solver((0, 0), (0.4, 0.4), 0.02, margin=0)
    ym.add_region(s, ROCK, (0, 0), (0.4, 0.4))
    s.view("v0")[:] = 500.0                           # the block drifts off the grid's right edge
    s.requestSort()
    with pytest.raises(ym.MpmSimulationError, match="in position update: .* left the grid along axis 0"):
        s.run(10)
    steps, t = s.steps, s.time                        # the clock did not advance, the particles partly did
    with pytest.raises(ym.MpmSimulationError, match="cannot step: the last step failed .*restore a checkpoint"):
        s.run(1)
    assert (s.steps, s.time) == (steps, t)


def test_solver_settings_declared_once_with_unit_range_and_doc():
    """Settings are generated from one declaration (SolverSettings.hpp): each property's docstring
    carries its unit and range, and bad values are refused with the name and the range."""
    names = set(_scene().settings())
    assert names == {"gravity", "damping", "courant", "autoDt", "fixedDt", "tractionRampTime", "sortPeriod", "mpiRebalance", "trackEnergy", "outside", "velocityUpdate"}
    for n in names | {"time", "externalWork"}:
        doc = getattr(ym.Solver2D, n).__doc__
        assert "[" in doc and ("range" in doc or "True or False" in doc or "one of" in doc), n
    s = _scene()
    for name, bad, msg in (("sortPeriod", 0, r"Solver2D.sortPeriod = 0 \[steps\] is outside the allowed range \[1, 1000000000\]"),
                           ("courant", 1.5, r"Solver2D.courant = 1.5 \[-\] is outside the allowed range \(0, 1\]"),
                           ("damping", 1.0, r"\[0, 1\)"), ("gravity", (0, np.nan), r"gravity\[1\]"),
                           ("autoDt", "yes", "True or False"), ("tractionRampTime", -1, r"\[0, inf\)")):
        with pytest.raises(ValueError, match=msg):
            setattr(s, name, bad)
    s.autoDt = False                                  # fixedDt left at 0 (not set): refused, not a 0-length step
    with pytest.raises(ValueError, match="fixedDt = 0 s is not set"):
        s.run(1)
