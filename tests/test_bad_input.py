"""Bad input raises ValueError naming the parameter (and range) before any work is done."""
import math
import os
import re
import subprocess
import sys

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
                 ("critPlasticStrain", 0.0), ("growthLaw", 3), ("growthLaw", "fast")]:
        with pytest.raises(ValueError, match=k):
            ym.DpGkMat(**dict(base, **{k: v}))
    with pytest.raises(TypeError, match="unknown parameter"):
        ym.DpGkMat(**dict(base, friction=0.5))


def _solver():
    return ym.make_solver((0, 0), (1, 1), 0.1)


def test_empty_particle_set():
    s = _solver()
    s._setMaterial(ym.ElasticMat(young=1e9, poisson=0.2, density=2500))
    with pytest.raises(ValueError, match="particles"):
        s.run(1)
    with pytest.raises(ValueError, match="empty"):
        s._addParticles(np.zeros((0, 2)), np.zeros(0), np.zeros(0))


def test_particle_outside_grid_and_nan_position():
    s = _solver()
    with pytest.raises(ValueError, match="outside the grid"):
        s._addParticles(np.array([[0.5, 2.0]]), np.array([1e-3]), np.array([1.0]))
    with pytest.raises(ValueError, match="not finite"):
        s._addParticles(np.array([[np.nan, 0.5]]), np.array([1e-3]), np.array([1.0]))
    with pytest.raises(ValueError, match="volume"):
        s._addParticles(np.array([[0.5, 0.5]]), np.array([0.0]), np.array([1.0]))
    with pytest.raises(ValueError, match="mass"):
        s._addParticles(np.array([[0.5, 0.5]]), np.array([1e-3]), np.array([np.inf]))
    assert s.numParticles == 0                       # nothing was added by the failed calls


def test_fixed_dt_above_stable_step():
    s = _solver()
    ym.add_region(s, ym.ElasticMat(young=1e9, poisson=0.2, density=2500), (0, 0), (1, 1))
    s.autoDt = False
    s.fixedDt = 10 * s.stableDt()
    with pytest.raises(ValueError, match="dt .* exceeds the stable time step"):
        s.run(1)
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
        s.run(1)


def test_grid_parameters():
    with pytest.raises(ValueError, match="spacing"):
        ym.make_solver((0, 0), (1, 1), 0.0)
    with pytest.raises(ValueError, match=r"Solver2D: spacing = -1 \[m\] is outside the allowed range \(0, inf\)"):
        ym.Solver2D((0, 0), -1.0, (4, 4))
    with pytest.raises(ValueError, match="cells"):
        ym.Solver2D((0, 0), 1.0, (0, 4))
    with pytest.raises(ValueError, match="boundary kind"):
        _solver().addBoundaryPlane(0, -1, 0.0, "sticky")


def test_position_corrupted_through_a_view_stops_cleanly():
    # No requestSort() after the edit: the step itself must catch it (not crash, not write NaN).
    s = _solver()
    ym.add_region(s, ym.ElasticMat(young=1e9, poisson=0.2, density=2500), (0, 0), (1, 1))
    s.run(1)
    victim = int(s.view("id")[7])
    s.view("x1")[7] = np.nan
    with pytest.raises(ym.MpmSimulationError, match=f"step 1 .*particle id {victim} has a position outside the grid or not finite"):
        s.run(1)


# ---- wrong types and values at the binding: a ValueError naming the argument and its range
# (these were Boost ArgumentError/TypeError/OverflowError without the name, or silently accepted)
def _dpgk():
    return ym.rocks.granite_dpgk()


def _upd(**kw):
    a = dict(material=_dpgk(), stress=[0.0] * 4, strainInc=[1e-4, 0, 0, 0], epsP=0.0, damage=0.0, eps0=1e-4, dt=1e-6)
    a.update(kw)
    return ym.materials.dpgkPointUpdate2D(*a.values())


@pytest.mark.parametrize("call, msg", [
    (lambda: ym.Solver2D((0, 0), "a", (4, 4)), r"Solver2D: spacing must be a number \[m\] in \(0, inf\) \(got str"),
    (lambda: ym.Solver2D((0, 0), 0.1, (4, "a")), r"Solver2D: cells\[1\] must be an integer in \[1, 16777216\]"),
    (lambda: ym.Solver2D((0, 0), 0.1, (4.5, 4)), r"cells\[0\] must be an integer"),
    (lambda: ym.Solver2D((0, 0), 0.1, (10 ** 12, 4)), r"cells\[0\] = 1000000000000 .*outside the allowed range \[1, 16777216\]"),
    (lambda: ym.Solver2D((0, 0), 0.1, (100000, 100000)), r"cells: a grid of .* nodes needs .* GB, more than this machine's"),
    (lambda: ym.Solver2D(None, 0.1, (4, 4)), r"Solver2D: origin must be a sequence of 2 numbers \[m\]"),
    (lambda: ym.Solver3D((0, 0, math.nan), 0.1, (4, 4, 4)), r"Solver3D: origin\[2\] = nan \[m\] is outside"),
    (lambda: _solver().run("a"), r"run: steps must be an integer in \[0, "),
    (lambda: _solver().run(10 ** 20), r"run: steps = 100000000000000000000 is outside"),
    (lambda: _solver()._advance("a"), r"advance: dt must be a number \[s\] in \(0, inf\)"),
    (lambda: _solver().view(5), r"view: name must be a string \(got int"),
    (lambda: _solver().addBoundaryPlane("a", 1, 0.0, "fixed"), r"addBoundaryPlane: axis must be an integer in \[0, 1\]"),
    (lambda: _solver().addBoundaryPlane(0, 1, math.nan, "fixed"), r"addBoundaryPlane: position = nan \[m\]"),
    (lambda: _solver()._setNodeExcluded(-1, True), r"setNodeExcluded: node = -1 .*outside the allowed range \[0, "),
    (lambda: _solver()._setNodeExcluded(30, "yes"), r"setNodeExcluded: excluded must be True or False"),
    (lambda: _solver()._shapeFunctions("ab"), r"shapeFunctions: point must be a sequence of 2 numbers"),
    (lambda: _solver()._setMaterial(None), r"setMaterial: material must be an ElasticMat or a DpGkMat \(got NoneType\)"),
    (lambda: ym.setThreads(2.5), r"setThreads: threads must be an integer in \[1, \d+\]"),
    (lambda: ym.setThreads(0), r"setThreads: threads = 0 .*outside the allowed range \[1, \d+\]"),
    # dpgkPointUpdate took NaN increments (NaN state out) and negative dt
    (lambda: _upd(strainInc=[math.nan, 0, 0, 0]), r"dpgkPointUpdate2D: strainInc\[0\] = nan \[-\] is outside"),
    (lambda: _upd(stress=[0, 0, 0, math.inf]), r"dpgkPointUpdate2D: stress\[3\] = inf \[Pa\] is outside"),
    (lambda: _upd(dt=-1e-6), r"dpgkPointUpdate2D: dt = -1e-06 \[s\] is outside the allowed range \[0, inf\)"),
    (lambda: _upd(damage=1.5), r"dpgkPointUpdate2D: damage = 1.5 \[-\] is outside the allowed range \[0, 1\]"),
    (lambda: _upd(epsP=-0.1), r"dpgkPointUpdate2D: epsP .* = -0.1 \[-\] is outside the allowed range \[0, inf\)"),
    (lambda: _upd(eps0=0.0), r"dpgkPointUpdate2D: eps0 .* = 0 \[-\] is outside the allowed range \(0, inf\)"),
    (lambda: _upd(material=ym.rocks.granite()), r"dpgkPointUpdate2D: material must be a DpGkMat \(got ElasticMat\)"),
    (lambda: _upd(epsP="a"), r"dpgkPointUpdate2D: epsP .* must be a number"),
])
def test_binding_arguments_named(call, msg):
    with pytest.raises(ValueError, match=msg):
        call()


def test_too_many_threads_refused_not_crashing():
    """setThreads(100000) then a step segfaulted; 1000 made libgomp abort. In a subprocess, so a
    regression shows as a failed test, not a dead test run."""
    code = ("import yade_mpm as ym\n"
            "try:\n    ym.setThreads(100000)\nexcept ValueError as e:\n    print('REFUSED', e)\n"
            "s = ym.make_solver((0, 0), (1, 1), 0.1)\n"
            "ym.add_region(s, ym.rocks.granite(), (0, 0), (1, 1))\ns.run(2)\nprint('STEPPED', s.steps)\n")
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(ym.__file__)), OMP_NUM_THREADS="1")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr[-500:]
    assert re.search(r"REFUSED setThreads: threads = 100000 .*outside the allowed range \[1, \d+\]", r.stdout)
    assert "STEPPED 2" in r.stdout


# ---- geometry and scene helpers (Python side)
@pytest.mark.parametrize("make, msg", [
    (lambda: ym.Circle((np.nan, 0.5), 0.2), r"Circle center = \(nan, 0.5\) m must be finite"),
    (lambda: ym.Circle((0.5, 0.5), np.inf), r"Circle radius = inf m is outside the allowed range \(0, inf\)"),
    (lambda: ym.Box((0, np.nan), (1, 1)), r"Box lo = \(0.0, nan\) m must be finite"),
    (lambda: ym.Polygon([(0, 0), (1, 0), (np.inf, 1)]), r"Polygon vertices must be finite"),
    (lambda: ym.Polygon([(0, 0), (1, 1), (2, 2)]), r"zero area"),
    (lambda: ym.geometry.rotated_rectangle((np.nan, 0.5), 0.4, 0.1, 0.3), r"rotated_rectangle center = \(nan, 0.5\) m must be finite"),
    (lambda: ym.geometry.rotated_rectangle((0.5, 0.5), 0.4, 0.1, np.inf), r"rotated_rectangle angle = inf rad"),
    (lambda: ym.geometry.rotated_rectangle((0.5, 0.5), -0.4, 0.1, 0.0), r"rotated_rectangle length = -0.4 m is outside the allowed range \(0, inf\)"),
])
def test_hole_with_nonfinite_geometry_refused(make, msg):
    """A NaN/inf centre, vertex or angle made a hole that silently removed nothing."""
    with pytest.raises(ValueError, match=msg):
        make()


def test_hole_dimension_must_match_region():
    """A 2D Circle in a 3D region was a NumPy broadcast error; now it names the hole."""
    with pytest.raises(ValueError, match=r"holes\[0\] is a 2D Circle but the region is 3D"):
        ym.geometry.fill_region((0, 0, 0), (1, 1, 1), 0.25, holes=[ym.Circle((0.5, 0.5), 0.2)])
    with pytest.raises(ValueError, match=r"holes\[1\] is a 3D Box but the region is 2D"):
        ym.geometry.fill_region((0, 0), (1, 1), 0.1, holes=[ym.Circle((0.5, 0.5), 0.2), ym.Box((0, 0, 0), (1, 1, 1))])
    s3 = ym.make_solver((0, 0, 0), (1, 1, 1), 0.25)
    with pytest.raises(ValueError, match=r"region lo = \(0, 0\) must have 3 components for a 3D solver"):
        ym.add_region(s3, ym.rocks.granite(), (0, 0), (1, 1))
    # a polygon is a prism along z in 3D: allowed, and it removes the prism (volume check)
    sq = ym.Polygon([(0.25, 0.25), (0.75, 0.25), (0.75, 0.75), (0.25, 0.75)])
    x, v = ym.geometry.fill_region((0, 0, 0), (1, 1, 1), 0.125, ppc=1, holes=[sq])
    assert len(x) * v == pytest.approx(1 - 0.5 * 0.5 * 1)


def test_face_traction_on_a_face_without_particles_refused():
    """apply_face_traction on a face that is not the lattice edge used to apply nothing, silently."""
    s = _solver()
    ym.add_region(s, ym.rocks.granite(), (0, 0), (1, 1))
    with pytest.raises(ValueError, match=r"face x1 = 5.0 m \(side \+1\) has no particles in row 0.*span \[0.025, 0.975\] m"):
        ym.apply_face_traction(s, 1, 1, 5.0, (0, -1e6))
    with pytest.raises(ValueError, match=r"face = nan m"):
        ym.apply_face_traction(s, 1, 1, np.nan, (0, -1e6))
    with pytest.raises(ValueError, match=r"traction must have shape \(2,\) \[Pa\] for a 2D solver \(got \(3,\)\)"):
        ym.apply_face_traction(s, 1, 1, 1.0, (0, -1e6, 0))
    with pytest.raises(ValueError, match=r"indices is empty"):
        ym.apply_traction(s, [], (0, 1e6), 0.05)
    with pytest.raises(ValueError, match=r"indices must be a 1-D array of integer"):
        ym.apply_traction(s, [0.5], (0, 1e6), 0.05)      # was truncated to slot 0
    # the accepted face load is the traction times the face area, whatever the row split (Σβ = 1)
    ym.apply_face_traction(s, 1, 1, 1.0, (0, -1e6))
    fy = s.view("trac1")
    assert fy.sum() == pytest.approx(-1e6 * 1.0 * 1.0, rel=1e-12)   # t · (1 m face × 1 m thickness)


@pytest.mark.parametrize("call, msg", [
    (lambda: ym.make_solver((0, 0), (1, np.nan), 0.1), r"make_solver hi = \(1.0, nan\) m must be finite"),
    (lambda: ym.make_solver((0, 0), (1, 1), "a"), r"spacing must be a number \[m\]"),
    (lambda: ym.geometry.fill_region((0, 0), (1, np.inf), 0.1), r"region hi = \(1.0, inf\) m must be finite"),
    (lambda: ym.geometry.fill_region((0, 0), (1, 1), 0.1, keep=lambda x: np.ones(3, bool)), r"keep returned shape \(3,\)"),
    (lambda: ym.boundary_particles(_solver(), 0, 1), r"the solver has no particles"),
    (lambda: ym.boundary_particles(_solver(), 5, 1), r"axis = 5 must be an integer in \[0, 1\]"),
    (lambda: ym.set_initial_stress(_solver(), "abcd"), r"initial stress must be 4 numbers"),
    (lambda: ym.scene.consistent_row_weights(10 ** 6), r"ppc .* = 1000000 must be an integer in \[2, 16\]"),
    (lambda: ym.scene.consistent_row_weights(2, 1.0), r"offset = 1.0 cells must lie in \[0, 1\)"),
    (lambda: ym.add_region(None, ym.rocks.granite(), (0, 0), (1, 1)), r"solver must be a Solver2D or Solver3D \(got NoneType\)"),
])
def test_scene_helpers_name_the_parameter(call, msg):
    with pytest.raises(ValueError, match=msg):
        call()


# ---- DP–GK state written through the views: checked at the next step after requestSort()
def _dpgk_block():
    s = _solver()
    ym.add_region(s, ym.rocks.granite_dpgk(), (0, 0), (1, 1))
    s.run(2)
    return s


@pytest.mark.parametrize("field, value, msg", [
    ("damage", 1.5, r"damage D of particle id {pid} = 1.5 is outside the allowed range \[0, 1\]"),
    ("damage", -0.1, r"damage D of particle id {pid} = -0.1 is outside the allowed range \[0, 1\]"),
    ("damage", np.nan, r"damage D of particle id {pid} = nan is outside"),
    ("epsP", -1e-3, r"plastic strain epsP of particle id {pid} = -0.001 is outside the allowed range \[0, inf\)"),
    ("epsP", np.inf, r"plastic strain epsP of particle id {pid} = inf is outside"),
    ("eps0", 0.0, r"damage threshold eps0 of particle id {pid} = 0 is outside the allowed range \(0, 1\)"),
    ("eps0", 2.0, r"damage threshold eps0 of particle id {pid} = 2 is outside the allowed range \(0, 1\)"),
])
def test_damage_state_out_of_range_through_views_refused(field, value, msg):
    """These values were used as they were (D = 1.5 flips the sign of the tensile stress, eps0 = 0
    damages at any tension)."""
    s = _dpgk_block()
    steps, t = s.steps, s.time
    s.view(field)[11] = value
    s.requestSort()
    pid = int(s.view("id")[11])
    with pytest.raises(ValueError, match=msg.format(pid=pid)):
        s.run(1)
    assert (s.steps, s.time) == (steps, t)            # refused before any work


def test_damage_threshold_outside_unit_interval_refused():
    """ε_D⁰ = (V k)^(−1/m) (Eq. 37) must lie in (0, 1): V·k < 1 means fewer than one flaw per particle and
    a threshold strain above 100 % (damage can never start) — it was accepted silently."""
    m = ym.rocks.granite_dpgk(weibullK=1e3, thresholdVolume="particle")   # literal V: V k = (0.05 m)²·1 m · 1e3 = 2.5
    assert 0 < m.activationStrain(2.5e-3) < 1
    s = _solver()
    ym.add_region(s, m, (0, 0), (1, 1))                # accepted: ε_D⁰ = 2.5^(−1/7.5) ≈ 0.885
    assert s.view("eps0")[0] == pytest.approx(2.5 ** (-1 / 7.5), rel=1e-12)
    low = ym.rocks.granite_dpgk(weibullK=100.0, thresholdVolume="particle")   # V k = 0.25: ε_D⁰ = 0.25^(−1/7.5) ≈ 1.2
    with pytest.raises(ValueError, match=r"damage threshold eps0 = .* = 1.2.* for V = 0.0025 m³ \(particle volume 0.0025 m³, "
                                         r"thresholdVolume = 'particle'\) is outside the allowed range \(0, 1\) .*V·weibullK = 0.25 must exceed 1"):
        s._setMaterial(low)
    assert s.material(0).weibullK == 1e3          # refused before anything changed
    s2 = _solver()
    s2._setMaterial(low)                                # no particles yet: nothing to check
    with pytest.raises(ValueError, match=r"V·weibullK = 0.25 must exceed 1"):
        s2._addParticles(np.array([[0.5, 0.5]]), np.array([2.5e-3]), np.array([6.0]))
    assert s2.numParticles == 0


def test_set_particle_forces_is_all_or_nothing():
    """A bad index or a NaN force later in the list used to be refused only after the forces before it
    had been applied (a half-applied load)."""
    s = _solver()
    ym.add_region(s, ym.rocks.granite(), (0, 0), (1, 1))
    s._setParticleForces([0], [[1.0, 2.0]])
    n = s.numParticles
    for idx, f, msg in (([0, n + 5], [[3.0, 4.0], [5.0, 6.0]], rf"particle index {n + 5} is outside the allowed range \[0, {n}\)"),
                        ([0, 1], [[3.0, 4.0], [np.nan, 6.0]], "particle surface force must be a finite number")):
        with pytest.raises(ValueError, match=msg):
            s._setParticleForces(idx, f)
        assert (s.view("trac0")[0], s.view("trac1")[0]) == (1.0, 2.0)


@pytest.mark.parametrize("call, msg", [
    (lambda: _solver()._setParticleForces(np.zeros(1), [[0.0, 1.0]]), r"setParticleForces: indices must be a 1-D array of integer"),
    (lambda: _solver()._setParticleForces(10 ** 20, [[0.0, 1.0]]), r"setParticleForces: indices must be a 1-D array of integer"),
    (lambda: _solver()._setParticleForces([], []), r"forces must be an \(N, 2\) array"),
    (lambda: ym.make_solver((0, 0), (1, 1), True), r"spacing must be a number \[m\] \(got bool True\)"),
    (lambda: ym.get(None, "pos"), r"solver must be a Solver2D or Solver3D \(got NoneType\)"),
    (lambda: ym.fields(_solver(), exclude=("velocity",)), r"exclude: unknown field\(s\) \['velocity'\]; known: id, pos, vel"),
    (lambda: ym.MpmEngine(None), r"solver must be a Solver2D or Solver3D \(got NoneType\)"),
    (lambda: ym.progress.Progress(np.nan), r"Progress end_time = nan s is outside"),
    (lambda: ym.progress.Progress(-1.0), r"Progress end_time = -1.0 s is outside the allowed range \[0, inf\)"),
    (lambda: ym.progress.Progress(1.0, interval=-1), r"Progress interval = -1 s is outside the allowed range \[0, inf\)"),
])
def test_more_public_calls_name_the_parameter(call, msg):
    """Found by calling every public function with wrong types/NaN/inf/negatives/empty arrays/wrong
    shapes: these were an OverflowError/AttributeError, or accepted (bool spacing 1 m, NaN end time)."""
    with pytest.raises(ValueError, match=msg):
        call()
