"""Contact parameters declared once (pkg-mpm/contact/ContactParams.hpp, issue 20): every Python-visible contact
attribute documents its unit and range, the ends of each range are enforced, doc/reference/contact.md holds the
generated table, RigidBodies.add and DemSpheres.add take the same keywords, a body registered without mu
takes tan(frictionAngle) of its YADE FrictMat (incline against g(sin θ − μ cos θ)), and the bad inputs of
issue 20 are refused (or, NumPy scalars, accepted) before any work."""
import inspect
import json
import math
import os
import re

import numpy as np
import pytest
import yade_mpm as ym

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
UNIT = re.compile(r"\[[^\]]+\]")
RANGE = re.compile(r"range [\[(][^,]+, [^\])]+[\])]|True or False|one of '")
G = 9.81
ELASTIC = dict(young=2e7, poisson=0.25, density=1000.0)


def test_every_contact_attribute_has_unit_range_and_doc():
    cls = ym.ContactParams
    attrs = sorted(n for n in dir(cls) if not n.startswith("_") and isinstance(getattr(cls, n), property))
    table = {p["name"]: p for p in cls.paramTable()}
    assert set(attrs) == set(table) == {"law", "mu", "cohesion", "chi", "d0", "autoD0", "initialD0"}
    for n in attrs:
        doc = getattr(cls, n).__doc__ or ""
        assert UNIT.search(doc) and RANGE.search(doc), f"ContactParams.{n}: {doc!r}"
        assert table[n]["doc"] and table[n]["doc"] in doc and table[n]["eq"].startswith("Eq"), n
        assert n in cls.__doc__
    # units and ranges as the paper states them (Sec. 2.3: 0 ≤ χ < 1)
    assert (table["chi"]["lo"], table["chi"]["hi"], table["chi"]["loOpen"], table["chi"]["hiOpen"]) == (0, 1, False, True)
    assert [table[n]["unit"] for n in ("mu", "cohesion", "chi", "d0")] == ["-", "Pa", "-", "m"]


def test_contact_ranges_are_enforced_at_the_ends_and_round_trip():
    for p in ym.ContactParams.paramTable():
        if p["type"] != "float":
            continue
        for end, is_open in ((p["lo"], p["loOpen"]), (p["hi"], p["hiOpen"])):
            if math.isinf(end):
                continue
            c = ym.ContactParams()
            if is_open:
                with pytest.raises(ValueError, match=re.escape(p["name"]) + ".*outside the allowed range"):
                    setattr(c, p["name"], end)
            else:
                setattr(c, p["name"], end)
    c = ym.bodies.contact_params(mu=0.35, cohesion=2e5, chi=0.25, d0=0.004)
    d = c.toDict()
    assert d == dict(law="kinematic", mu=0.35, cohesion=2e5, chi=0.25, d0=0.004, autoD0=False, initialD0=False)
    assert ym.ContactParams.fromDict(json.loads(json.dumps(d))).toDict() == d
    assert ym.bodies.contact_params(d0="initial").toDict()["initialD0"] is True


def test_doc_contact_md_holds_the_generated_table():
    with open(os.path.join(ROOT, "doc", "reference", "contact.md"), encoding="utf-8") as f:
        assert ym.materials.markdown_table(ym.ContactParams) in f.read()


def test_one_registration_shape_for_rigid_bodies_and_spheres():
    keywords = ["ids", "mu", "cohesion", "chi", "d0", "thickness", "law"]
    for cls in (ym.RigidBodies, ym.DemSpheres):
        sig = inspect.signature(cls.add)
        assert list(sig.parameters)[1:] == keywords, cls
        assert all(sig.parameters[k].default is None for k in keywords[1:]), cls


yade = pytest.importorskip("yade")


def _incline_scene(theta, material, **add_kw):
    """Elastic block 0.2 × 0.1 m (l = 0.02 m, ppc 2) resting on a fixed YADE box tilted by theta about z,
    registered through RigidBodies.add(**add_kw); MpmEngine + NewtonIntegrator. Returns (solver, rb, box)."""
    from yade import O, utils
    from yade.minieigenHP import Quaternion, Vector3
    from yade.wrapper import ForceResetter, NewtonIntegrator
    O.reset()
    l, sp = 0.02, 0.01
    R = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    axes = [np.arange(sp / 2, 0.2, sp) - 0.1, np.arange(sp / 2, 0.1, sp)]
    loc = np.column_stack([g.ravel() for g in np.meshgrid(*axes, indexing="ij")])
    c0 = np.array([0.5, 0.3])
    x = c0 + loc @ R.T
    s = ym.make_solver((0, 0), (1.0, 0.8), l)
    s._setMaterial(ym.ElasticMat(**ELASTIC))
    s._addParticles(x, np.full(len(x), sp ** 2), np.full(len(x), sp ** 2 * ELASTIC["density"]))
    s.gravity = (0, -G)
    centre = c0 - 0.1 * R[:, 1]
    box = O.bodies.append(utils.box((centre[0], centre[1], 0), (1.0, 0.1, 0.1), orientation=Quaternion(Vector3(0, 0, 1), theta),
                                    fixed=True, material=material))
    rb = ym.RigidBodies(s)
    rb.add(box, **add_kw)
    O.engines = [ForceResetter(), ym.MpmEngine(s, label="mpmIncline", bodies=rb).runner(), NewtonIntegrator(damping=0)]
    O.dt = 1.0
    return s, rb, box, R[:, 0]


def test_box_friction_from_yade_frictmat_slides_with_coulomb_acceleration():
    """Bar of issue 20: FrictMat(frictionAngle = atan 0.35), no mu given: the group's μ is 0.35 and the
    block's centre of mass accelerates down the 30° slope at g(sin θ − 0.35 cos θ) within 2 %."""
    from yade import O
    from yade.wrapper import FrictMat
    theta = math.radians(30)
    s, rb, box, t = _incline_scene(theta, FrictMat(frictionAngle=math.atan(0.35), density=1000))
    assert s._contactParams(rb.groups[0]).mu == pytest.approx(0.35, rel=1e-12)
    m = s.view("mass")
    hist = []
    while O.time < 0.1:
        O.run(1, True)
        v = np.array([m @ s.view("v0"), m @ s.view("v1")]) / m.sum()
        hist.append((O.time, v @ t))
    tt, vt = np.array(hist).T
    sel = tt > 0.03                                    # after the first contact transient
    a = -np.polyfit(tt[sel], vt[sel], 1)[0]
    assert a == pytest.approx(G * (math.sin(theta) - 0.35 * math.cos(theta)), rel=0.02)


def test_explicit_mu_wins_and_mixed_friction_angles_need_mu():
    from yade import O, utils
    from yade.wrapper import FrictMat
    s, rb, box, _ = _incline_scene(0.0, FrictMat(frictionAngle=0.3), mu=0.0)
    assert s._contactParams(rb.groups[0]).mu == 0.0
    a = O.bodies.append(utils.box((0.5, 0.7, 0), (0.05, 0.02, 0.1), material=FrictMat(frictionAngle=0.2)))
    b = O.bodies.append(utils.box((0.7, 0.7, 0), (0.05, 0.02, 0.1), material=FrictMat(frictionAngle=0.4)))
    with pytest.raises(ValueError, match="different friction angles.*pass mu"):
        rb.add([a, b])
    g = rb.add([a, b], mu=0.1)
    assert s._contactParams(g).mu == 0.1


def _block_and_box():
    from yade import O, utils
    O.reset()
    s = ym.make_solver((0, 0), (0.4, 0.3), 0.02)
    ym.add_region(s, ym.ElasticMat(**ELASTIC), (0.1, 0.0), (0.3, 0.1))
    box = O.bodies.append(utils.box((0.2, 0.2, 0), (0.05, 0.05, 0.1)))
    return s, box


@pytest.mark.parametrize("ids, kw, msg", [
    ("twice", {}, r"body id \d+ is listed twice"),                               # was silent: reaction 0 in the solver
    (None, {}, r"ids must be a YADE body id \(an integer\) or a list of ids \(got NoneType None\)"),   # was a bare TypeError
    ("float", {}, r"ids: body id 0.0 must be an integer \(got float\)"),
    ("box", dict(mu=True), r"ContactParams.mu must be a number \[-\] in \[0, inf\) \(got bool True\)"),   # was accepted as 1
    ("box", dict(d0=0.5), r"d0 = 0.5 \[m\] is outside the allowed range \[0, 0.02\] \(at most one grid spacing"),  # PyRunner error later
    ("box", dict(d0=True), r"d0 = True: .*must be a number \[m\].*'initial'"),
])
def test_bad_registration_is_refused_before_any_work(ids, kw, msg):
    s, box = _block_and_box()
    ids = {"twice": [box, box], "float": [float(box)], "box": box}.get(ids, ids) if ids is not None else None
    rb = ym.RigidBodies(s)
    with pytest.raises(ValueError, match=msg):
        rb.add(ids, **kw)
    assert not s._contactActive and s._numContactGroups == 0 and rb.ids == []


def test_numpy_scalars_are_numbers():
    """mu = np.float32(0.3) was refused with "0.3 is outside the allowed range [0, inf)"."""
    s, box = _block_and_box()
    rb = ym.RigidBodies(s)
    g = rb.add(np.int64(box), mu=np.float32(0.3), cohesion=np.int64(1000), chi=np.float64(0.25), d0=np.float32(0.005),
               thickness=np.float32(0.2))
    p = s._contactParams(g)
    assert p.mu == pytest.approx(0.3, rel=1e-7) and p.cohesion == 1000 and p.chi == 0.25 and not p.autoD0
    assert rb.thickness(box) == pytest.approx(0.2, rel=1e-7)


def test_dem_sphere_with_nan_position_is_refused():
    """A DEM sphere at a NaN position was registered and silently never touched anything (the broad phase
    saw a NaN gap); now add() names it, and a position that turns NaN later stops the step."""
    from yade import O, utils
    s, _ = _block_and_box()
    bad = O.bodies.append(utils.sphere((0.2, 0.2, 0), 0.02))
    O.bodies[bad].state.pos = (float("nan"), 0.2, 0.0)
    sp = ym.DemSpheres(s)
    with pytest.raises(ValueError, match=rf"body id {bad}: state.pos = \(nan, 0.2, 0(.0)?\) \[m\] must be finite"):
        sp.add([bad])
    assert s._numContactGroups == 0
    O.bodies[bad].state.pos = (0.2, 0.25, 0.0)
    sp.add([bad], mu=0.0)
    O.bodies[bad].state.pos = (0.2, float("nan"), 0.0)
    with pytest.raises(ValueError, match=rf"body id {bad}: state.pos .* \[m\] must be finite"):
        sp.read()


def test_rigid_body_velocity_message_has_its_unit():
    s = ym.make_solver((0, 0), (0.4, 0.3), 0.02)
    p = s._addRigidPart()
    with pytest.raises(ValueError, match=r"rigid body velocity\[0\] = nan \[m/s\]"):
        s._setRigidPartState(p, (0, 0), np.eye(2), (float("nan"), 0), 0.0)
    with pytest.raises(ValueError, match=r"rigid body position\[1\] = inf \[m\]"):
        s._setRigidPartState(p, (0, float("inf")), np.eye(2), (0, 0), 0.0)
    s._addContactGroup([p], ym.ContactParams())
    with pytest.raises(ValueError, match=r"rigid body velocity \[m/s\] must be a finite number"):
        s._setRigidPartMotions([p], [[0.0, 0.0]], [[float("nan"), 0.0]], [[0.0]])
