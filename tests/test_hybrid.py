"""DEM spheres (and clumps of spheres) in two-way PTS contact with MPM particles (yade_mpm.DemSpheres):
a dropped sphere rebounds, the impulse on the sphere is minus the momentum the MPM particles gained,
a resting sphere comes to rest under its weight, a clump acts like a sphere, and spheres far from the
particles are not examined every step and change nothing."""

import numpy as np
import pytest
import yade_mpm as ym

yade = pytest.importorskip("yade")

R = 0.03                     # sphere radius [m]
BLOCK = ((0.0, 0.0), (0.2, 0.1))


def _block(floor):
    s = ym.make_solver(*BLOCK, 0.01)
    ym.add_region(s, ym.ElasticMat(young=1e8, poisson=0.25, density=2000.0), *BLOCK, ppc=2)
    if floor:
        s.addBoundaryPlane(1, -1, 0.0, "fixed")
        s.gravity = (0.0, -9.81)
    return s


def _sphere(x, y, vy, radius=R):
    from yade import utils
    from yade.wrapper import FrictMat
    b = utils.sphere((x, y, 0.0), radius, material=FrictMat(density=2000.0))
    b.state.blockedDOFs = "zXY"
    b.state.vel = (0.0, vy, 0.0)
    return b


def _run(s, bodies, gravity=0.0, damping=0.0):
    from yade import O
    from yade.wrapper import ForceResetter, NewtonIntegrator
    O.engines = [ForceResetter(), ym.MpmEngine(s, label="mpmHybrid", bodies=bodies).runner(),
                 NewtonIntegrator(damping=damping, gravity=(0.0, gravity, 0.0))]
    O.dt = 1.0


def _momentum(s):
    return ym.get(s, "momentum").sum(axis=0)          # exact total (vel is the material points' velocity)


def _collide(s, sp, bid, max_steps=2000):
    """Step until the body has touched the block and left it again; returns the steps taken."""
    from yade import O
    touched = False
    for k in range(max_steps):
        O.step()
        f = sp.force(bid)
        touched = touched or f[1] != 0
        if touched and f[1] == 0 and O.bodies[bid].state.vel[1] > 0:
            return k + 1
    raise AssertionError("the body did not leave the block")


def test_dropped_sphere_rebounds():
    from yade import O
    O.reset()
    s = _block(floor=True)
    bid = O.bodies.append(_sphere(0.1, 0.1 + R + 0.005, -1.0))
    sp = ym.DemSpheres(s)
    sp.add("all", mu=0.0)                        # frictionless (the tests were written with mu = 0)
    _run(s, sp, gravity=-9.81)
    _collide(s, sp, bid)
    v = O.bodies[bid].state.vel[1]
    assert v > 0.1                                   # bounced back up (impact at ≈ 1 m/s)
    y0 = O.bodies[bid].state.pos[1]
    O.run(200, True)
    assert O.bodies[bid].state.pos[1] > y0           # and rises


def test_impulse_on_sphere_is_minus_impulse_on_particles():
    """Free-floating block, no gravity: the sphere's momentum change (YADE mass × Δv) equals minus the
    MPM particles' momentum change × the sphere's thickness (2R), within 1 %."""
    from yade import O
    O.reset()
    s = _block(floor=False)
    bid = O.bodies.append(_sphere(0.1, 0.1 + R + 0.002, -1.0))
    sp = ym.DemSpheres(s)
    sp.add("all", mu=0.0)                        # frictionless (the tests were written with mu = 0)
    _run(s, sp)
    p0, v0 = _momentum(s), np.array(O.bodies[bid].state.vel)[:2]
    _collide(s, sp, bid)
    J_sphere = O.bodies[bid].state.mass * (np.array(O.bodies[bid].state.vel)[:2] - v0)
    J_mpm = sp.thickness(bid) * (_momentum(s) - p0)
    assert sp.thickness(bid) == pytest.approx(2 * R)
    assert J_sphere[1] > 0.3 * O.bodies[bid].state.mass     # a real collision (≥ 0.3 m/s change)
    assert np.abs(J_sphere + J_mpm).max() <= 0.01 * abs(J_sphere[1])


def test_3d_sphere_impulse_balance_and_rebound():
    """3D: a sphere (no thickness mapping, t = 1) hits a free elastic block and bounces; its impulse is
    minus the particles' momentum change within 1 %."""
    from yade import O
    from yade.wrapper import FrictMat
    from yade import utils
    O.reset()
    s = ym.make_solver((0, 0, 0), (0.12, 0.06, 0.12), 0.01)
    ym.add_region(s, ym.ElasticMat(young=1e8, poisson=0.25, density=2000.0), (0, 0, 0), (0.12, 0.06, 0.12), ppc=2)
    bid = O.bodies.append(utils.sphere((0.05, 0.06 + R + 0.002, 0.06), R, material=FrictMat(density=2000.0)))
    O.bodies[bid].state.vel = (0.0, -1.0, 0.0)
    sp = ym.DemSpheres(s)
    sp.add("all", mu=0.0)                        # frictionless (the tests were written with mu = 0)
    _run(s, sp)
    p0, v0 = _momentum(s), np.array(O.bodies[bid].state.vel)
    _collide(s, sp, bid)
    J = O.bodies[bid].state.mass * (np.array(O.bodies[bid].state.vel) - v0)
    assert sp.thickness(bid) == 1.0 and O.bodies[bid].state.vel[1] > 0.1
    assert np.abs(J + (_momentum(s) - p0)).max() <= 0.01 * abs(J[1])


def test_sphere_resting_on_block_comes_to_rest():
    """Placed on the block under gravity (damping on the MPM side only): the sphere stops, and the
    contact force averaged over two steps (the penalty κ = 2m/Δt² leaves a period-2 ripple of a few
    µm/s) carries its weight within 1 %."""
    from yade import O
    O.reset()
    s = _block(floor=True)
    s.damping = 0.3
    bid = O.bodies.append(_sphere(0.1, 0.1 + R, 0.0))
    sp = ym.DemSpheres(s)
    sp.add("all", mu=0.0)                        # frictionless (the tests were written with mu = 0)
    _run(s, sp, gravity=-9.81)
    O.run(2000, True)
    b = O.bodies[bid]
    f = []
    for _ in range(2):
        O.step()
        assert abs(b.state.vel[1]) < 2e-5            # at rest (free fall would give ~0.4 m/s by now)
        f.append(sp.force(bid)[1] * sp.thickness(bid))
    assert np.mean(f) == pytest.approx(b.state.mass * 9.81, rel=0.01)
    assert abs(b.state.pos[1] - (0.1 + R)) < 0.005   # on the top face (within half a grid cell)


def test_clump_acts_like_a_sphere():
    """(a) A clump whose second member lies inside the first has the first member's surface: with the
    sphere's mass and inertia it rebounds exactly like the sphere. (b) A two-lobe clump hit off-centre:
    impulse balance within 1 % and a spin from the contact torque."""
    from yade import O

    def drop_single():
        O.reset()
        s = _block(floor=False)
        bid = O.bodies.append(_sphere(0.1, 0.1 + R + 0.002, -1.0))
        sp = ym.DemSpheres(s)
        sp.add("all", mu=0.0)                        # frictionless (the tests were written with mu = 0)
        _run(s, sp)
        m, I = O.bodies[bid].state.mass, O.bodies[bid].state.inertia
        n = _collide(s, sp, bid)
        return n, np.array(O.bodies[bid].state.vel), m, I

    n1, v1, m, I = drop_single()
    O.reset()
    s = _block(floor=False)
    cid, _ = O.bodies.appendClumped([_sphere(0.1, 0.1 + R + 0.002, 0.0), _sphere(0.1 + R / 4, 0.1 + R + 0.002, 0.0, R / 2)])
    c = O.bodies[cid]
    c.state.mass, c.state.inertia = m, I
    c.state.pos = (0.1, 0.1 + R + 0.002, 0.0)
    c.state.blockedDOFs = "zXY"
    c.state.vel = (0.0, -1.0, 0.0)
    sp = ym.DemSpheres(s)
    sp.add("all", mu=0.0)                        # frictionless (the tests were written with mu = 0)
    assert list(sp.ids) == [cid]
    _run(s, sp)
    n2 = _collide(s, sp, cid)
    assert n2 == n1
    np.testing.assert_allclose(np.array(c.state.vel), v1, rtol=1e-9, atol=1e-12)

    O.reset()
    s = _block(floor=False)
    cid, _ = O.bodies.appendClumped([_sphere(0.09, 0.1 + R + 0.002, 0.0), _sphere(0.09 + R, 0.1 + R + 0.002, 0.0)])
    c = O.bodies[cid]
    c.state.blockedDOFs = "zXY"
    c.state.vel = (0.0, -1.0, 0.0)
    sp = ym.DemSpheres(s)
    sp.add("all", mu=0.0)                        # frictionless (the tests were written with mu = 0)
    _run(s, sp)
    p0 = _momentum(s)
    _collide(s, sp, cid)
    J_clump = c.state.mass * (np.array(c.state.vel)[:2] - np.array([0.0, -1.0]))
    J_mpm = sp.thickness(cid) * (_momentum(s) - p0)
    assert np.abs(J_clump + J_mpm).max() <= 0.01 * abs(J_clump[1])
    assert J_clump[1] > 0.3 * c.state.mass
    assert abs(c.state.angVel[2]) > 1e-3             # both lobes touch at once only if it were symmetric


def test_far_spheres_are_skipped_and_change_nothing():
    """100 resting spheres 1 m away: never enabled, the broad phase looks at them once per 200 steps,
    and the particles are bitwise those of the same run without spheres."""
    from yade import O
    a, b = _block(floor=True), _block(floor=True)
    O.reset()
    for k in range(100):
        O.bodies.append(_sphere(2.0 + 0.07 * (k % 10), 1.0 + 0.07 * (k // 10), 0.0))
    sp = ym.DemSpheres(a)
    sp.add("all", mu=0.0)                        # frictionless (the tests were written with mu = 0)
    _run(a, sp)
    O.run(400, True)
    for _ in range(400):
        b.run(1)
    assert not sp.active.any()
    assert sp.checks <= 3
    for name in ("pos", "vel", "stress"):
        np.testing.assert_array_equal(ym.get(a, name), ym.get(b, name))


def test_platen_and_sphere_in_one_engine():
    """RigidBodies (a box platen pressing the left half of the block) and DemSpheres (a sphere resting on
    the right half) in one MpmEngine: both act — the platen receives the block's push-back, the sphere
    carries its weight (two-step mean within 2 %)."""
    from yade import O, utils
    O.reset()
    s = _block(floor=True)
    s.damping = 0.3
    bid = O.bodies.append(_sphere(0.15, 0.1 + R, 0.0))
    box = O.bodies.append(utils.box((0.05, 0.1 + 0.02 + 1e-4, 0.0), (0.03, 0.02, 0.05), fixed=True))
    O.bodies[box].state.vel = (0.0, -0.02, 0.0)
    rb = ym.RigidBodies(s)
    rb.add(box, mu=0.0)
    sp = ym.DemSpheres(s)
    sp.add([bid], mu=0.0)
    with pytest.raises(ValueError, match="list of them"):
        ym.MpmEngine(s, label="mpmBad", bodies=[rb, object()])
    _run(s, [rb, sp], gravity=-9.81)
    O.run(1500, True)
    assert rb.force(box)[1] > 0                       # the block pushes the platen up
    f = []
    for _ in range(2):
        O.step()
        f.append(sp.force(bid)[1] * sp.thickness(bid))
    assert np.mean(f) == pytest.approx(O.bodies[bid].state.mass * 9.81, rel=0.02)


def test_bad_input():
    from yade import O, utils
    O.reset()
    s = _block(floor=False)
    box = O.bodies.append(utils.box((0, 1, 0), (0.1, 0.1, 0.1)))
    sph = O.bodies.append(_sphere(0.1, 0.5, 0.0))
    with pytest.raises(ValueError, match="shape Box"):
        ym.DemSpheres(s).add([box])
    with pytest.raises(ValueError, match="max_check_steps"):
        ym.DemSpheres(s, max_check_steps=0)
    with pytest.raises(ValueError, match="mu"):
        ym.DemSpheres(s).add([sph], mu=-1.0)
    with pytest.raises(ValueError, match="does not exist"):
        ym.DemSpheres(s).add([99])
    far = O.bodies.append(utils.sphere((0.5, 0.5, 1.0), 0.05))
    with pytest.raises(ValueError, match="does not cross the plane"):
        ym.DemSpheres(s).add([far])
