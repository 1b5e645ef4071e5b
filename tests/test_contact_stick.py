"""Stick step of a free body (paper Eq. 24 with the body's mass; PtsContact::bodyResponse, doc/reference/contact.md):
every contact node sticks to the body's motion after the step, f_stick,j = −m_j P_j (ṽ_j − J_j Δq)/Δt, with Δq
the body's response to the reactions; for a uniform slip along a face with the rotation prescribed this is
the reduced mass, −m_j ṽ_tan M/(M + S)/Δt (S = Σ_j m_j over the contact nodes); an immovable body keeps the
paper's −m_j ṽ_tan/Δt.

One step, against the analytic momentum balance: a free box sliding at v0 over a slab at rest reaches the
common velocity of box and nodes in one step, momentum conserved; a box between two slabs sliding in
opposite directions stops both faces (full stick, where a reduced-mass factor M/(M + S) would stop only that
fraction); a box free to turn: every node ends on its new rigid motion (2D, 3D). Dynamics through YADE: a
light free block (lighter than the grid nodes along its face) dragged along a slab on a frictionless base
sticks below the friction limit (common acceleration M g_x/(M + m_slab), no chatter) and slides above it
(block g_x − μ g_y, slab μ M g_y/m_slab); the adapter's mass rules; bad input."""
import numpy as np
import pytest
import yade_mpm as ym

SLAB = dict(young=2e7, poisson=0.25, density=1000.0)
L = 0.02                                    # grid spacing [m]
TOP = 0.06                                  # slab top [m]


def _box_sliding_on_slab(d, mass, inertia, v0=0.1, pen=0.002):
    """An elastic slab at rest (no gravity) and a rigid box wider than it, pressed `pen` into the top
    layer's detection distance, moving at v0 along x, with μ = 10 (every node sticks). Returns (solver,
    part, box centre)."""
    s = ym.make_solver(np.zeros(d), (0.4, 0.2, 0.2)[:d], L)
    ym.add_region(s, ym.ElasticMat(**SLAB), (0.1, 0.0, 0.05)[:d], (0.3, TOP, 0.15)[:d])
    p = s._addRigidPart()
    g = s._addContactGroup([p], ym.bodies.contact_params(mu=10.0, cohesion=0.0, chi=0.5, d0=None, law="penalty"))
    half = (0.2, 0.02, 0.2)[:d]                  # flat bottom face over the whole slab: normals exactly −y
    s._addContactBox(g, p, np.zeros(d), np.eye(d), half)
    c = np.array((0.2, TOP + 0.02 - pen, 0.1)[:d])
    s._setRigidPartState(p, c, np.eye(d), (v0,) + (0.0,) * (d - 1), 0.0 if d == 2 else (0.0, 0.0, 0.0))
    s._setRigidPartMass(p, mass, inertia)
    return s, p, c


def _one_step(s):
    s.run(1)
    f = s._contactNodeForces()
    m = s._nodeState()[0]
    on = np.any(f != 0, axis=1)                  # the contact nodes (f_nor ≠ 0)
    return s.time, f, m, on


@pytest.mark.parametrize("d", [2, 3])
def test_uniform_slip_is_removed_in_one_step_with_momentum_conserved(d):
    v0, M = 0.1, (0.5, 0.2)[d - 2]              # kg/m (2D) or kg: lighter than its contact nodes
    inf = float("inf")
    s, p, _ = _box_sliding_on_slab(d, M, inf if d == 2 else (inf,) * 3)
    dt, f, m, on = _one_step(s)
    S = m[on].sum()
    assert S > 2 * M                             # the case that chattered: nodes heavier than the body
    alpha = M / (M + S)
    # every contact node gets the same share of its stick force, f_x = α m_i v0/Δt (Eq. 24 × α)
    assert np.allclose(f[on, 0] / m[on], alpha * v0 / dt, rtol=1e-12, atol=0)
    # analytic one-step balance: body v0 + Δt F/M, nodes α v0 -> no relative slip left, momentum conserved
    F = np.asarray(s._rigidPartForce(p))
    v_body = v0 + dt * F[0] / M
    assert v_body == pytest.approx(alpha * v0, rel=1e-12)
    pm = s.view("mass") @ s.view("v0")           # particles' momentum along x after the step
    assert M * v_body + pm == pytest.approx(M * v0, rel=1e-10)
    assert pm == pytest.approx(S * alpha * v0, rel=1e-10)
    # an immovable body (the default, and a prescribed one) keeps the paper's stick step: α = 1
    s2, _, _ = _box_sliding_on_slab(d, inf, inf if d == 2 else (inf,) * 3)
    dt2, f2, m2, on2 = _one_step(s2)
    assert np.array_equal(on2, on)
    assert np.allclose(f2[on2, 0] / m2[on2], v0 / dt2, rtol=1e-12, atol=0)


def test_box_sheared_between_two_slabs_stops_both_faces():
    """A free box (rotation prescribed) between an upper slab moving at +v0 and a lower one at −v0: the
    stick impulses cancel on the box (b = 0, Δv = 0), so every contact node stops relative to it in one
    step, f_x = −m_i v_i/Δt — the paper's full stick, as for a flaw filler whose faces slide past each
    other; a single reduced-mass factor M/(M + S) on −m ṽ/Δt would stop only that fraction of the slip."""
    v0, M, inf = 0.1, 0.3, float("inf")
    s = ym.make_solver((0, 0), (0.4, 0.24), L)
    ym.add_region(s, ym.ElasticMat(**SLAB), (0.1, 0.0), (0.3, TOP))
    ym.add_region(s, ym.ElasticMat(**SLAB), (0.1, TOP + 0.06), (0.3, TOP + 0.12))
    p = s._addRigidPart()
    g = s._addContactGroup([p], ym.bodies.contact_params(mu=10.0, cohesion=0.0, chi=0.5, d0=None, law="penalty"))
    s._addContactBox(g, p, (0.0, 0.0), np.eye(2), (0.2, 0.03 + 0.002))      # pressed 2 mm into both faces
    s._setRigidPartState(p, (0.2, TOP + 0.03), np.eye(2), (0.0, 0.0), 0.0)
    s._setRigidPartMass(p, M, inf)
    s.view("v0")[:] = np.where(s.view("x1") > TOP + 0.03, v0, -v0)
    s.run(1)
    f, m = s._contactNodeForces(), s._nodeState()[0]
    on = np.any(f != 0, axis=1)
    y = s._nodePositions()[on][:, 1]
    S = m[on].sum()
    assert np.any(y > TOP + 0.03) and np.any(y < TOP + 0.03) and S > 2 * M   # both faces, heavier than the box
    assert np.allclose(f[on, 0] / m[on], np.where(y > TOP + 0.03, -v0, v0) / s.time, rtol=1e-9, atol=0)
    assert abs(s._rigidPartForce(p)[0]) < 1e-9 * S * v0 / s.time             # the box stays at rest


def test_two_free_parts_of_one_group_each_take_their_own_response():
    """One contact group over two free boxes (rotation prescribed) of different masses side by side on a
    slab, both sliding at v0: each node gets the reduced mass of the box that owns its nearest surface
    point, f_x/m_i = v0 M_k/(M_k + S_k)/Δt with S_k the mass of box k's contact nodes (per-part sums)."""
    v0, Ms, inf = 0.1, (0.2, 3.0), float("inf")
    s = ym.make_solver((0, 0), (0.4, 0.2), L)
    s.courant = 0.5   # every node sticks: at C = 1 the node at x = 0.42 m (box 2's end, a small overlap) slips, its
                      # stick force m v0/Δt then above μ times its penalty force 2 m d/Δt² (measured 0.585 of α v0/Δt)
    ym.add_region(s, ym.ElasticMat(**SLAB), (0.0, 0.0), (0.4, TOP))
    parts = [s._addRigidPart(), s._addRigidPart()]
    g = s._addContactGroup(parts, ym.bodies.contact_params(mu=10.0, cohesion=0.0, chi=0.5, d0=None, law="penalty"))
    for k, p in enumerate(parts):
        s._addContactBox(g, p, (0.0, 0.0), np.eye(2), (0.09, 0.02))
        s._setRigidPartState(p, (0.1 + 0.2 * k, TOP + 0.02 - 0.002), np.eye(2), (v0, 0.0), 0.0)
        s._setRigidPartMass(p, Ms[k], inf)
    dt, f, m, on = _one_step(s)
    x = s._nodePositions()
    owner = np.array([s._contactQuery(g, tuple(xi))[2] for xi in x[on]])
    for k, p in enumerate(parts):
        mine = owner == p
        S = m[on][mine].sum()
        assert S > 0
        alpha = Ms[k] / (Ms[k] + S)
        assert np.allclose(f[on][mine, 0] / m[on][mine], alpha * v0 / dt, rtol=1e-12, atol=0)
        assert s._rigidPartForce(p)[0] == pytest.approx(-alpha * S * v0 / dt, rel=1e-12)


@pytest.mark.parametrize("d", [2, 3])
def test_free_rotation_every_node_sticks_to_the_body_in_one_step(d):
    """A free box that also turns (I = ½ M h² about every axis, a disc whose centre is h = 2 cm above its
    contact): the stick impulses below its centre turn it, and the nodes lie on two rows at different lever
    arms, so no single factor on m ṽ/Δt stops them all. After the step every contact node moves with the
    box's new motion, v' + ω' × r (the box's v' = v0 + Δt F/M, ω' = Δt T/I from the reaction), to round-off;
    linear momentum of particles + box is conserved."""
    v0, M = 0.1, (2.0, 0.8)[d - 2]
    I = 0.5 * M * 0.02 ** 2
    s, p, c = _box_sliding_on_slab(d, M, I if d == 2 else (I,) * 3)
    dt, f, m, on = _one_step(s)
    r = s._nodePositions()[on] - c
    assert len(np.unique(np.round(r[:, 1], 9))) >= 2                # node rows at different lever arms
    F, T = np.asarray(s._rigidPartForce(p)), np.atleast_1d(s._rigidPartTorque(p))
    v_body, w_body = np.eye(d)[0] * v0 + dt * F / M, dt * T / I
    if d == 2:
        body_at = v_body + w_body[0] * np.column_stack([-r[:, 1], r[:, 0]])
    else:
        body_at = v_body + np.cross(w_body, r)
    node = dt * f[on] / m[on][:, None]                               # the slab was at rest
    tang = [0] if d == 2 else [0, 2]                                # the face's tangent plane (normal y)
    assert np.abs(node[:, tang] - body_at[:, tang]).max() < 1e-10 * v0
    assert np.abs(w_body).max() * 0.02 > 0.1 * v0                   # it did turn
    assert s.view("mass") @ s.view("v0") + M * v_body[0] == pytest.approx(M * v0, rel=1e-10)


# ---------------------------------------------------------------- through YADE (bodies.py)
yade = pytest.importorskip("yade")
G_Y, MU = 10.0, 0.5


def _dragged_block(g_x, steps, rho_block=400.0):
    """A free rigid YADE box 0.1 × 0.02 m (1 m thick, 0.8 kg/m at 400 kg/m³) on an elastic slab
    0.4 × 0.06 m (24 kg/m) resting on a frictionless base (slip plane); μ = 0.5; the block's gravity
    (g_x, −g_y) drags and presses it, the slab's (0, −g_y) presses it on the base. Returns (history
    (time, block v_x, slab v_x, v_x of the particles under the block), block mass M, slab mass, node mass
    S in contact with the block at the end)."""
    import builtins
    from yade import O, utils
    from yade.wrapper import ForceResetter, FrictMat, NewtonIntegrator, PyRunner
    O.reset()
    s = ym.make_solver((0, 0), (0.6, 0.2), L)
    ym.add_region(s, ym.ElasticMat(**SLAB), (0.1, 0.0), (0.5, TOP))
    s.addBoundaryPlane(1, -1, 0.0, "slip")
    s.gravity = (0, -G_Y)
    # bottom face where the top row's detection distance (half a particle edge) ends: contact at zero force
    bid = O.bodies.append(utils.box((0.3, TOP + 0.01, 0), (0.05, 0.01, 0.5), material=FrictMat(density=rho_block)))
    st = O.bodies[bid].state
    st.blockedDOFs = "zXY"
    rb = ym.RigidBodies(s)
    rb.add(bid, mu=MU)
    m = s.view("mass")
    rec = []

    def record():
        x0, x1, v0 = s.view("x0"), s.view("x1"), s.view("v0")
        under = (np.abs(x0 - st.pos[0]) < 0.04) & (x1 > TOP - L / 2)
        rec.append((O.time, st.vel[0], m @ v0 / m.sum(), m[under] @ v0[under] / m[under].sum()))
    builtins._stick_test_record = record
    O.engines = [ForceResetter(), ym.MpmEngine(s, label="mpmDrag", bodies=rb).runner(),
                 NewtonIntegrator(damping=0.0, gravity=(g_x, -G_Y, 0)), PyRunner(command="_stick_test_record()", iterPeriod=1)]
    O.dt = 1.0
    O.run(steps, True)
    f, mn = s._contactNodeForces(), s._nodeState()[0]
    return np.array(rec), st.mass, m.sum(), mn[np.any(f != 0, axis=1)].sum()


def test_light_block_dragged_below_friction_limit_moves_with_the_slab():
    """Below μN: block and slab accelerate together at a = M g_x/(M + m_slab) (frictionless base); the
    friction needed, M g_x m_slab/(M + m_slab), is half of μ M g_y. The block's contact nodes weigh ~11× it.
    Second half of 1200 steps; the accelerations from velocities averaged over 126 steps (3 periods of the
    undamped slab's shear oscillation) at its start and end. Measured (immovable-body stick step in brackets):
    block −0.02 % of a (+0.5 %), slip velocity against the top particles 1.45 ± 0.05 g_x Δt (1.81 ± 0.91:
    the block's drag acts after the contact step, an O(Δt) lag), sign flips of its velocity increment in
    the last 100 steps 0 (65)."""
    M0, ms0 = 0.8, 24.0
    g_x = 0.5 * MU * G_Y * (M0 + ms0) / ms0
    h, M, ms, S = _dragged_block(g_x, 1200)
    assert M == pytest.approx(M0) and ms == pytest.approx(ms0) and S > 5 * M
    t, vb, vs, vtop = h.T
    dt = t[1] - t[0]
    a = M * g_x / (M + ms)
    i0, i1 = slice(600, 726), slice(1074, 1200)
    for v in (vb, vs):
        assert (v[i1].mean() - v[i0].mean()) / (t[i1].mean() - t[i0].mean()) == pytest.approx(a, rel=0.01)
    slip = (vb - vtop)[600:]
    assert abs(slip.mean()) < 2 * g_x * dt and slip.std() < 0.3 * g_x * dt
    dv = np.diff(vb[-100:])
    assert np.sum(np.sign(dv[1:]) != np.sign(dv[:-1])) < 10


def test_light_block_dragged_above_friction_limit_slides_with_coulomb_force():
    """Above μN (g_x = 3 μ g_y): the block accelerates at g_x − μ g_y, the slab's centre of mass at
    μ M g_y/m_slab (the Coulomb force is the only horizontal force on it); measured −0.01 % and +0.03 %.
    (Without the second, slip-aware solve of the body's response the slab's was −1.1 %: the stick targets
    assumed every node sticks.)"""
    g_x = 3 * MU * G_Y
    h, M, ms, _ = _dragged_block(g_x, 400)
    t, vb, vs, _ = h.T
    late = t > t[-1] / 3
    assert np.polyfit(t[late], vb[late], 1)[0] == pytest.approx(g_x - MU * G_Y, rel=0.01)
    assert np.polyfit(t[late], vs[late], 1)[0] == pytest.approx(MU * M * G_Y / ms, rel=0.01)


def test_adapter_passes_mass_and_inertia_and_prescribed_bodies_are_immovable():
    """bodies.body_inertia: a free 2D box gets its mass and z moment per metre of thickness; a blocked
    in-plane translation or a non-dynamic body gives an infinite mass, a blocked rotation an infinite
    moment; 3D passes the principal moments."""
    from yade import O, utils
    O.reset()
    s = ym.make_solver((0, 0), (0.4, 0.3), L)
    ym.add_region(s, ym.ElasticMat(**SLAB), (0.1, 0.0), (0.3, 0.1))
    rb = ym.RigidBodies(s)
    t = 0.4
    ids = [O.bodies.append(utils.box((0.2, 0.2 + 0.03 * k, 0), (0.05, 0.01, t / 2))) for k in range(4)]
    O.bodies[ids[1]].state.blockedDOFs = "y"
    O.bodies[ids[2]].state.blockedDOFs = "zXYZ"
    O.bodies[ids[3]].dynamic = False
    for i in ids:
        rb.add(i)
    st = O.bodies[ids[0]].state
    part = {i: rb._part(i)[1] for i in ids}
    m, I = s._rigidPartMass(part[ids[0]])
    assert m == pytest.approx(st.mass / t, rel=1e-15) and I == pytest.approx(st.inertia[2] / t, rel=1e-15)
    assert s._rigidPartMass(part[ids[1]])[0] == float("inf") and np.isfinite(s._rigidPartMass(part[ids[1]])[1])
    assert np.isfinite(s._rigidPartMass(part[ids[2]])[0]) and s._rigidPartMass(part[ids[2]])[1] == float("inf")
    assert s._rigidPartMass(part[ids[3]]) == (float("inf"), float("inf"))
    st.mass = 2.0                                 # read every step
    rb.read()
    assert s._rigidPartMass(part[ids[0]])[0] == pytest.approx(2.0 / t)
    s3 = ym.make_solver((0, 0, 0), (0.4, 0.3, 0.3), 0.05)
    ym.add_region(s3, ym.ElasticMat(**SLAB), (0.1, 0.0, 0.1), (0.3, 0.1, 0.2))
    b3 = O.bodies.append(utils.box((0.2, 0.2, 0.15), (0.05, 0.01, 0.03)))
    rb3 = ym.RigidBodies(s3)
    rb3.add(b3)
    m3, I3 = s3._rigidPartMass(rb3._part(b3)[1])
    assert m3 == pytest.approx(O.bodies[b3].state.mass) and I3 == pytest.approx(tuple(O.bodies[b3].state.inertia))


def test_bad_mass_input_is_refused_naming_it():
    s = ym.make_solver((0, 0), (0.4, 0.3), L)
    p = s._addRigidPart()
    for bad in (0.0, -1.0, float("nan"), "1", True):
        with pytest.raises(ValueError, match="mass"):
            s._setRigidPartMass(p, bad, 1.0)
        with pytest.raises(ValueError, match="inertia"):
            s._setRigidPartMass(p, 1.0, bad)
    assert s._rigidPartMass(p) == (float("inf"), float("inf"))          # nothing changed
    q = s._addRigidPart()
    with pytest.raises(ValueError, match="mass"):
        s._setRigidPartMasses([p, q], [1.0, -1.0], [[1.0], [1.0]])
    assert s._rigidPartMass(p) == (float("inf"), float("inf"))          # checked before any change
    s._setRigidPartMass(p, 3.0, float("inf"))                           # inf: that motion prescribed
    assert s._rigidPartMass(p) == (3.0, float("inf"))
