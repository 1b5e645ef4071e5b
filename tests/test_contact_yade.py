"""PTS contact with YADE bodies through the adapter (ym.RigidBodies, paper Sec. 2.3): a free YADE box thrown
spinning at a block conserves the total momentum (2D per metre of thickness, and 3D) and bounces, a free box
comes to rest on a block, bad contact input is refused naming it, and the uniaxial builder (cases.uniaxial_flaw)
places its platen and filler and ramps the platen. The solver-level contact tests are in tests/test_contact.py."""
import numpy as np
import pytest
import yade_mpm as ym
from yade_mpm.fields import id_order

from test_contact import ELASTIC, G

yade = pytest.importorskip("yade")


def _yade_scene(bodies, solver, label, newton_damping=0.0, gravity=(0, 0, 0), record=None):
    from yade import O
    from yade.wrapper import ForceResetter, NewtonIntegrator, PyRunner
    rb = ym.RigidBodies(solver)
    for ids, kw in bodies:
        rb.add(ids, **kw)
    engines = [ForceResetter(), ym.MpmEngine(solver, label=label, bodies=rb).runner(),
               NewtonIntegrator(damping=newton_damping, gravity=gravity)]
    if record is not None:
        import builtins
        builtins._contact_test_record = record
        engines.append(PyRunner(command="_contact_test_record()", iterPeriod=1))
    O.engines = engines
    O.dt = 1.0
    return rb


def test_thrown_free_box_conserves_total_momentum():
    """No gravity, no boundaries: block particles + a free YADE box (thickness 0.6 m, so the 2D
    per-metre mapping matters) thrown spinning against the block; total momentum per metre is
    conserved every step and the box bounces."""
    from yade import O, utils, Vector3
    from yade.wrapper import FrictMat
    O.reset()
    s = ym.make_solver((0, 0), (0.6, 0.3), 0.02)
    ym.add_region(s, ym.ElasticMat(young=1e6, poisson=0.25, density=1000.0), (0.3, 0.05), (0.5, 0.25))
    t = 0.6
    bid = O.bodies.append(utils.box((0.15, 0.15, 0), (0.05, 0.05, t / 2), material=FrictMat(density=2000)))
    b = O.bodies[bid]
    b.state.vel, b.state.angVel = Vector3(2.0, 0.3, 0), Vector3(0, 0, 3.0)
    m = s.view("mass")

    def momentum():
        v = b.state.vel
        return np.array([m @ s.view("v0"), m @ s.view("v1")]) + b.state.mass / t * np.array([v[0], v[1]])
    rec = []
    rb = _yade_scene([(bid, dict(mu=0.4))], s, "mpmThrow", record=lambda: rec.append(momentum()))
    assert rb.thickness(bid) == pytest.approx(t)
    p0 = momentum()
    while O.time < 0.167:                             # hit and bounced (600 steps at C = 0.5); a fixed time, at any C
        O.run(1, True)
    assert np.abs(np.array(rec) - p0).max() < 1e-10 * np.abs(p0).max()
    assert b.state.vel[0] < 0.5                       # it hit the block and lost most of its x velocity


def test_free_box_comes_to_rest_on_block():
    from yade import O, utils
    from yade.wrapper import FrictMat
    O.reset()
    l = 0.02
    s = ym.make_solver((0, 0), (0.4, 0.3), l)
    ym.add_region(s, ym.ElasticMat(young=5e6, poisson=0.25, density=1000.0), (0.1, 0.0), (0.3, 0.1))
    s.addBoundaryPlane(1, -1, 0.0, "fixed")
    s.gravity = (0, -G)
    s.damping = 0.3
    # box bottom at d0 (¼ cell) above the block top
    bid = O.bodies.append(utils.box((0.2, 0.1 + l / 4 + 0.03, 0), (0.05, 0.03, 0.1), material=FrictMat(density=2000)))
    ys = []
    _yade_scene([(bid, dict(mu=0.5))], s, "mpmRest", newton_damping=0.3, gravity=(0, -G, 0),
                record=lambda: ys.append((O.bodies[bid].state.pos[0], O.bodies[bid].state.pos[1])))
    O.run(2500, True)
    x, y = np.array(ys).T
    late = slice(len(ys) * 3 // 4, None)
    assert np.ptp(y[late]) < 0.01 * l and np.ptp(x[late]) < 0.01 * l   # no drift, no chatter
    assert y[-1] < 0.1 + l / 4 + 0.03                                  # it pressed onto the block


def test_bad_contact_input_is_refused_naming_it():
    from yade import O, utils
    from yade.wrapper import Body, Tetra
    O.reset()
    s = ym.make_solver((0, 0), (0.4, 0.3), 0.02)
    ym.add_region(s, ym.ElasticMat(**ELASTIC), (0.1, 0.0), (0.3, 0.1))
    box = O.bodies.append(utils.box((0.2, 0.2, 0), (0.05, 0.05, 0.1)))
    rb = ym.RigidBodies(s)
    for kw, word in ((dict(chi=1.0), "chi"), (dict(chi=-0.1), "chi"), (dict(mu=-0.1), "mu"),
                     (dict(cohesion=-1.0), "cohesion"), (dict(d0=-1e-3), "d0"), (dict(thickness=0.0), "thickness")):
        with pytest.raises(ValueError, match=word):
            rb.add(box, **kw)
    with pytest.raises(ValueError, match="body id 99 does not exist"):
        rb.add(99)
    tet = Body()
    tet.shape = Tetra(v=[(0, 0, -1), (1, 0, 1), (0, 1, 1), (0, 0, 1)])
    tid = O.bodies.append(tet)
    with pytest.raises(ValueError, match="Tetra"):
        rb.add(tid)
    far = O.bodies.append(utils.box((0.2, 0.2, 5.0), (0.05, 0.05, 0.1)))
    with pytest.raises(ValueError, match="does not cross the plane z = 0"):
        rb.add(far)
    with pytest.raises(ValueError, match="chi"):
        s._addContactGroup([s._addRigidPart()], ym.bodies.contact_params(mu=0.0, cohesion=0.0, chi=1.0, d0=None))
    assert not s._contactActive                       # nothing was registered by the refused calls


def test_uniaxial_builder_places_platen_and_filler():
    """cases.uniaxial_flaw (paper Sec. 3.3): the platen's lower face on the specimen top, the filler a
    free body inside the flaw (its centre inside the body, the nodes it covers excluded), the top
    particle row at the detection distance; an unknown variant is refused."""
    from yade import O
    from yade_mpm_paper import cases
    s, sc = cases.uniaxial_flaw("filled", 0.002, mu_con=0.4)
    W, H = sc["width"], sc["height"]
    platen, filler = O.bodies[sc["platen"]], O.bodies[sc["filler"]]
    assert platen.state.pos[1] - platen.shape.extents[1] == pytest.approx(H)
    assert platen.state.blockedDOFs == "xyzXYZ" and platen.state.vel[1] == pytest.approx(-0.1)
    assert filler.state.blockedDOFs == "zXY"
    c = sc["flaw"]["center"]
    assert np.hypot(filler.state.pos[0] - c[0], filler.state.pos[1] - c[1]) < 1e-12
    d, n, part = s._contactQuery(1, tuple(c))       # group 1: the filler
    assert d < 0
    O.step()
    ex = s._excludedNodes()
    X = s._nodePositions()
    inside = np.array([s._contactQuery(1, tuple(x))[0] < 0 for x in X[np.abs(X[:, 1] - c[1]) < 0.01]])
    assert np.all(ex[np.abs(X[:, 1] - c[1]) < 0.01][inside] & ym._core.exclusionBits["contact"])
    top = ym.get(s, "pos")[:, 1].max()
    # d0 = half the particle edge; the kinematic law moves the touching top row with the platen from the first step
    assert H - top == pytest.approx(0.5 * s.spacing / 2 + 0.1 * s.lastDt, rel=1e-6)
    assert sc["axial_stress"]() >= 0 and sc["axial_strain"]() > 0
    with pytest.raises(ValueError, match="variant"):
        cases.uniaxial_flaw("cracked", 0.002)


def test_uniaxial_builder_ramp_and_end_caps():
    """cases.uniaxial_flaw options of scripts/paper/compare_bonded.py: the platen at rest until advance(), then
    moving each chunk at speed·min(1, t/ramp_time) of the chunk start (displacement = Σ v_k Δt_k, an
    independent sum over the clock), ε_D⁰ = 0.99 exactly in the capped rows near base and platen and the
    rock's value elsewhere; bad options refused before any work."""
    from yade import O
    from yade_mpm_paper import cases
    l, speed, ramp, caps = 0.005, 1.0, 2e-5, 2
    def eps0(solver):                                  # ε_D⁰ by particle id
        return solver.view("eps0")[id_order(solver)].copy()
    e0_free = eps0(cases.uniaxial_flaw("intact", l, side_room=4 * l)[0])       # no caps: the rock's thresholds
    s, sc = cases.uniaxial_flaw("intact", l, platen_speed=speed, ramp_time=ramp, end_cap_cells=caps, side_room=4 * l)
    p = O.bodies[sc["platen"]]
    assert p.state.vel[1] == 0.0
    y0, H = p.state.pos[1], sc["height"]
    x = ym.get(s, "pos")
    e0 = eps0(s)
    cap = (x[:, 1] < caps * l) | (x[:, 1] > H - caps * l)
    assert cap.sum() == 2 * 2 * caps * (sc["width"] / (l / 2)) and np.all(e0[cap] == 0.99)
    assert np.all(e0[~cap] == e0_free[~cap]) and np.all(e0_free < 0.99)
    expect = 0.0
    for _ in range(4):
        t0 = O.time
        sc["advance"](3)
        expect += speed * min(1.0, t0 / ramp) * (O.time - t0)
    assert O.time > ramp / 4
    assert y0 - p.state.pos[1] == pytest.approx(expect, rel=1e-9)
    assert sc["axial_strain"]() == pytest.approx(expect / H, rel=1e-9)
    for kw, name in ((dict(ramp_time=-1e-3), "ramp_time"), (dict(end_cap_cells=1.5), "end_cap_cells"),
                     (dict(end_cap_cells=H / l), "end_cap_cells"), (dict(side_room=0.0), "side_room")):
        with pytest.raises(ValueError, match=name):
            cases.uniaxial_flaw("intact", l, **kw)


def test_thrown_free_box_conserves_total_momentum_3d():
    """The adapter's 3D path: a spinning free YADE box thrown at an elastic block (no gravity, no
    boundaries); total momentum of particles + box conserved every step, and the box bounces."""
    from yade import O, utils, Vector3
    from yade.wrapper import FrictMat
    O.reset()
    s = ym.make_solver((0, 0, 0), (0.6, 0.3, 0.3), 0.05)
    ym.add_region(s, ym.ElasticMat(young=1e6, poisson=0.25, density=1000.0), (0.3, 0.05, 0.05), (0.5, 0.25, 0.25))
    bid = O.bodies.append(utils.box((0.15, 0.15, 0.15), (0.05, 0.05, 0.05), material=FrictMat(density=2000)))
    b = O.bodies[bid]
    b.state.vel, b.state.angVel = Vector3(2.0, 0.3, -0.2), Vector3(1.0, -2.0, 3.0)
    m = s.view("mass")

    def momentum():
        v = b.state.vel
        return np.array([m @ s.view(f"v{a}") for a in range(3)]) + b.state.mass * np.array([v[0], v[1], v[2]])
    rec = []
    _yade_scene([(bid, dict(mu=0.4))], s, "mpmThrow3", record=lambda: rec.append(momentum()))
    p0 = momentum()
    O.run(250, True)
    assert np.abs(np.array(rec) - p0).max() < 1e-10 * np.abs(p0).max()
    assert b.state.vel[0] < 1.0                       # it hit the block
