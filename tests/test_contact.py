"""PTS contact between MPM particles and rigid bodies (paper Sec. 2.3, Eqs. 23–26), in 2D and 3D:
Coulomb sliding on an incline against g(sin θ − μ cos θ), sticking below the friction angle, contact
cohesion capacity A·c, a dropped block rebounding without energy gain, action = −reaction every step,
a free YADE box coming to rest on a block and a thrown box conserving momentum, bad input."""
import numpy as np
import pytest
import yade_mpm as ym
from yade_mpm.fields import id_order

G = 9.81
ELASTIC = dict(young=2e7, poisson=0.25, density=1000.0)


def _rot(d, th):
    R = np.eye(d)
    R[:2, :2] = [[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]]
    return R


def _block_on_incline(d, theta, mu, cohesion=0.0, chi=0.5, shift=(0.0, 0.0, 0.0)):
    """An elastic block L × H (× W) resting on a rigid box tilted by theta about z (gravity −y), the scene
    shifted by `shift` grid cells against the grid.
    Returns (solver, part, up-slope tangent, grid spacing, block mass per metre (2D) / kg (3D))."""
    l = 0.02 if d == 2 else 0.04
    sp = l / 2
    dims = (0.2, 0.1) if d == 2 else (0.16, 0.08, 0.08)
    axes = [np.arange(sp / 2, L, sp) - (L / 2 if k != 1 else 0) for k, L in enumerate(dims)]
    loc = np.column_stack([g.ravel() for g in np.meshgrid(*axes, indexing="ij")])
    R = _rot(d, theta)
    c0 = np.array([0.5, 0.3, 0.2][:d]) + np.asarray(shift[:d]) * l
    x = c0 + loc @ R.T
    s = ym.make_solver(np.zeros(d), (1.0, 0.8, 0.4)[:d], l)
    s.setMaterial(ym.ElasticMat(**ELASTIC))
    s.addParticles(x, np.full(len(x), sp ** d), np.full(len(x), sp ** d * ELASTIC["density"]))
    s.gravity = (0, -G, 0)[:d]
    p = s.addRigidPart()
    g = s.addContactGroup([p], ym.bodies.contact_params(mu=mu, cohesion=cohesion, chi=chi, d0=None))
    s.addContactBox(g, p, np.zeros(d), np.eye(d), (1.0, 0.1, 1.0)[:d])
    s.setRigidPartState(p, c0 - 0.1 * R[:, 1], R, np.zeros(d), 0.0 if d == 2 else (0, 0, 0))
    return s, p, R[:, 0], l, s.view("mass").sum()


def _com(s, d, name):
    m = s.view("mass")
    return np.array([m @ s.view(f"{name}{a}") for a in range(d)]) / m.sum()


def _slide(s, d, t_end, t_fit):
    """Centre-of-mass (time, position along the slope, velocity along the slope) history."""
    out = []
    while s.time < t_end:
        s.step()
        out.append((s.time, _com(s, d, "x"), _com(s, d, "v")))
    return out


@pytest.mark.parametrize("d", [2, 3])
def test_incline_slides_with_coulomb_acceleration(d):
    theta, mu = np.radians(30), 0.3
    s, _, t, l, _ = _block_on_incline(d, theta, mu)
    hist = _slide(s, d, 0.1, 0.03)
    tt = np.array([h[0] for h in hist])
    vt = np.array([h[2] @ t for h in hist])
    sel = tt > 0.03   # after the first contact transient
    a = -np.polyfit(tt[sel], vt[sel], 1)[0]
    expected = G * (np.sin(theta) - mu * np.cos(theta))
    assert a == pytest.approx(expected, rel=0.03)


@pytest.mark.parametrize("d", [2, 3])
def test_incline_sticks_below_friction_angle(d):
    theta, mu = np.radians(20), 0.5          # tan θ = 0.36 < μ
    s, _, t, l, _ = _block_on_incline(d, theta, mu)
    x0 = _com(s, d, "x")
    hist = _slide(s, d, 0.1, 0.0)
    drift = max(abs((h[1] - x0) @ t) for h in hist)
    assert drift < 0.01 * l


def _gravity_prestress(s, theta, H=0.1):
    """Stress of a long layer of height H on the incline in equilibrium with gravity (σ_nn, σ_tn
    linear in depth): without it the released block rings on its support and the bottom particles
    lose contact (and with it the cohesive capacity) periodically."""
    t, n = _rot(2, theta)[:, 0], _rot(2, theta)[:, 1]
    x = np.column_stack([s.view("x0"), s.view("x1")])
    depth = H - (x @ n - (x @ n).min() + 0.25 * s.spacing)
    rho, nu = ELASTIC["density"], ELASTIC["poisson"]
    snn, stn = -rho * G * np.cos(theta) * depth, -rho * G * np.sin(theta) * depth
    for name, (a, b) in (("sig0", (0, 0)), ("sig1", (1, 1)), ("sig3", (0, 1))):
        s.view(name)[:] = (t[a] * n[b] + n[a] * t[b]) * stn + n[a] * n[b] * snn
    s.view("sig2")[:] = nu * snn
    s.requestSort()


def test_cohesion_sticks_below_area_times_c_and_slides_above():
    """μ = 0: the tangential capacity is A·c with A the contact length (2D, per metre): the block
    stays at 1.1× its drive and slides at 0.9× with about the acceleration of the difference."""
    theta = np.radians(30)
    moved = {}
    for factor in (1.1, 0.9):
        s, _, t, l, m = _block_on_incline(2, theta, 0.0, cohesion=1.0)
        drive, A = m * G * np.sin(theta), 0.2      # N/m along the slope, contact length [m]
        s, _, t, l, m = _block_on_incline(2, theta, 0.0, cohesion=factor * drive / A)
        _gravity_prestress(s, theta)
        x0 = _com(s, 2, "x")
        hist = _slide(s, 2, 0.1, 0.0)
        moved[factor] = -(hist[-1][1] - x0) @ t
    assert abs(moved[1.1]) < 0.01 * l              # sticks below A·c
    a = 0.1 * G * np.sin(theta)                    # (drive − A c)/m at 0.9×
    assert moved[0.9] == pytest.approx(0.5 * a * 0.1 ** 2, rel=0.3)   # slides above it


def _drop(d, chi=None):
    l = 0.02 if d == 2 else 0.04
    s = ym.make_solver((0, -0.05, 0)[:d], (0.4, 0.4, 0.16)[:d], l)
    ym.add_region(s, ym.ElasticMat(young=1e6, poisson=0.25, density=1000.0), (0.1, 0.1, 0.04)[:d], (0.3, 0.2, 0.12)[:d])
    s.gravity = (0, -G, 0)[:d]
    p = s.addRigidPart()
    g = s.addContactGroup([p], ym.bodies.contact_params(mu=0.0, cohesion=0.0, chi=chi, d0=None))
    n = np.zeros(d)
    n[1] = 1
    s.addContactPlane(g, p, np.zeros(d), n, False)   # the wall y = 0, material above
    s.setRigidPartState(p, np.zeros(d), np.eye(d), np.zeros(d), 0.0 if d == 2 else (0, 0, 0))
    return s


@pytest.mark.parametrize("d", [2, 3])
def test_dropped_block_rebounds_without_energy_gain(d):
    s = _drop(d)
    m = s.view("mass")

    def energy():
        return s.kineticEnergy() + s.elasticEnergy() + G * (m @ s.view("x1"))
    e0, y0 = energy(), _com(s, d, "x")[1]
    emax, ymin, hist = e0, np.inf, []
    while s.time < 0.45:
        s.step()
        emax = max(emax, energy())
        ymin = min(ymin, s.view("x1").min())
        hist.append((_com(s, d, "x")[1], _com(s, d, "v")[1]))
    y, vy = np.array(hist).T
    first = np.argmax(vy > 0)                      # first time the block moves up: it hit the wall
    assert first > 0 and y[first] < y0 - 0.08      # it fell ~0.1 m first
    assert y[first:].max() > y[first] + 0.03       # and bounced back up
    assert emax <= 1.01 * e0
    assert ymin > 0                                # no particle centre crosses the wall (bounded penetration)


@pytest.mark.parametrize("law, down, lift", [("penalty", 0.5, 0.0), ("kinematic", 2.0, 0.045)])
@pytest.mark.parametrize("d", [2, 3])
def test_reaction_is_minus_the_nodal_contact_forces_every_step(d, law, down, lift):
    """A rotating, translating box with friction pushes into a block: every step the body's force and
    torque equal minus the sum (and moment) of the nodal contact forces, and the particles' momentum
    change is Δt·(gravity + minus the body force) — an independent check through the G2P transfer.
    The kinematic law closes an overlap in one step (the penalty's 3.8 cm start would throw the block off) and
    leaves none: its box starts at the block's top (lift) and moves down faster to stay on the falling block."""
    l = 0.05 if d == 2 else 0.1
    s = ym.make_solver((0, 0, 0)[:d], (1, 1, 0.6)[:d], l)
    ym.add_region(s, ym.ElasticMat(**ELASTIC), (0.2, 0.2, 0.1)[:d], (0.8, 0.5, 0.5)[:d])
    s.gravity = (0.3, -G, 0.2)[:d]
    p = s.addRigidPart()
    g = s.addContactGroup([p], ym.bodies.contact_params(mu=0.4, cohesion=1e3, chi=0.5, d0=None, law=law))
    s.addContactBox(g, p, np.zeros(d), np.eye(d), (0.15, 0.1, 0.15)[:d])
    c = np.array([0.45, 0.59 + lift, 0.3][:d])
    R = _rot(d, 0.2)
    v = np.array([0.3, -down, 0.1][:d])
    w = 2.0 if d == 2 else (0.5, 0.3, 2.0)
    X = s.nodePositions()
    m = s.view("mass")
    checked = 0
    for k in range(60):
        s.setRigidPartState(p, c + v * s.time, R, v, w)
        p0 = np.array([m @ s.view(f"v{a}") for a in range(d)])
        s.step()
        p1 = np.array([m @ s.view(f"v{a}") for a in range(d)])
        fn = s.contactNodeForces()
        F, T = np.array(s.rigidPartForce(p)), np.array(s.rigidPartTorque(p))
        if not np.any(F):
            continue
        checked += 1
        scale = np.abs(fn).sum()
        np.testing.assert_allclose(F, -fn.sum(axis=0), rtol=0, atol=1e-12 * scale)
        r = X - (c + v * (s.time - s.lastDt))
        mom = r[:, 0] * fn[:, 1] - r[:, 1] * fn[:, 0] if d == 2 else np.cross(r, fn)
        np.testing.assert_allclose(T, -np.sum(mom, axis=0), rtol=0, atol=1e-12 * scale)
        gravity = m.sum() * np.array(s.gravity)
        np.testing.assert_allclose((p1 - p0) / s.lastDt, gravity - F, rtol=0, atol=1e-9 * (scale + np.abs(gravity).sum()))
    assert checked >= 10


@pytest.mark.parametrize("free, law, damping", [(False, "kinematic", 0.0), (True, "kinematic", 0.0), (True, "kinematic", 0.3),
                                                (False, "penalty", 0.0), (True, "penalty", 0.3)])
def test_contact_is_bitwise_identical_for_1_and_2_threads(free, law, damping, monkeypatch):
    """free: the incline is a free part (its mass and inertia set; the stick step's body response); damping > 0: the
    late damping (and the kinematic law's second projection)."""
    orig = ym.bodies.contact_params
    monkeypatch.setattr(ym.bodies, "contact_params", lambda *a, **k: orig(*a, law=law, **k))

    def run(n):
        ym.setThreads(n)
        try:
            s, *_ = _block_on_incline(2, np.radians(30), 0.3)
            assert s.contactParams(0).law == law
            s.damping = damping
            if free:
                s.setRigidPartMass(0, 5.0, 0.5)
            for _ in range(150):
                s.step()
            return ym.get(s, "pos"), ym.get(s, "vel"), s.rigidPartForce(0)
        finally:
            ym.setThreads(old)
    old = ym.getThreads()
    a, b = run(1), run(2)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(np.asarray(x), np.asarray(y))


def test_nodes_covered_by_a_body_are_excluded_and_released():
    s = _drop(2)
    X = s.nodePositions()
    s.step()
    ex = s.excludedNodes()
    inside = (X[:, 1] < -1e-12) & (X[:, 1] > -0.05) & (X[:, 0] > 0.01) & (X[:, 0] < 0.39)
    bit = ym._core.exclusionBits["contact"]
    assert np.all(ex[inside] & bit)                      # covered by the wall: contact bit
    assert not np.any(ex[X[:, 1] > 1e-12] & bit)         # above it: active


# ---------------------------------------------------------------- YADE bodies (the adapter)
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
    O.run(600, True)
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
        s.addContactGroup([s.addRigidPart()], ym.bodies.contact_params(mu=0.0, cohesion=0.0, chi=1.0, d0=None))
    assert not s.contactActive                       # nothing was registered by the refused calls


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
    d, n, part = s.contactQuery(1, tuple(c))       # group 1: the filler
    assert d < 0
    O.step()
    ex = s.excludedNodes()
    X = s.nodePositions()
    inside = np.array([s.contactQuery(1, tuple(x))[0] < 0 for x in X[np.abs(X[:, 1] - c[1]) < 0.01]])
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
