"""Rigid YADE bodies in an MPM scene: the adapter between ``O.bodies``/``O.forces`` and the core's PTS
contact (paper Sec. 2.3, Eqs. 23–26; the algorithm is in pkg-mpm/contact/PtsContact.hpp, see doc/reference/contact.md).

    rb = ym.RigidBodies(solver)
    rb.add(platen_id, mu=0.0)                       # one contact group per call, its own μ, c, χ, d0
    rb.add([f1, f2, f3, f4], mu=0.4, cohesion=1e6)  # several bodies may share parameters (a facet prism)
    O.engines = [ForceResetter(), ym.MpmEngine(solver, bodies=rb).runner(), NewtonIntegrator(damping=0)]

Every step the engine calls ``read()`` (position, orientation, velocity and angular velocity of every
registered body from ``O.bodies`` into the solver) before the MPM step and ``write()`` (the contact
reaction force and its torque about the body's centre, ``state.pos``, added to ``O.forces``) after it,
so NewtonIntegrator moves free bodies and bodies with ``blockedDOFs`` and a set velocity keep it.
``read()`` also passes each body's mass and inertia (``body_inertia``): the stick step of the friction
(Eq. 24) moves a free body with its contact nodes, so a light body does not overshoot (doc/reference/contact.md).

Shapes: ``Box`` (oriented), ``Wall`` (``sense`` +1 / −1: the material is on the +axis / −axis side and
the wall is a half-space; ``sense`` 0: a two-sided plane), ``Facet`` (a triangle; facets of one ``add``
whose edges close form a closed prism and get an inside), and a clump of boxes and facets (pass the clump
id). A body id that does not exist, a clump member passed instead of its clump, or another shape raises
``ValueError`` naming it.

2D plane strain: a body acts through its trace in the plane z = 0 (a box crossing z = 0 gives a rectangle,
a facet crossing it a segment, a wall along x or y a line); the MPM forces are per metre of thickness.
The body's *thickness* t is its extent along z (a box: 2·extents.z; facets and clumps: the z-range of
their vertices; a wall: 1 m), or the ``thickness`` given to ``add``. The force and torque added to
``O.forces`` are the per-metre reaction × t, so a free body of YADE mass m moves as a body of m/t
per metre of the plane-strain slice: its dynamics match the MPM side for any t. ``force(id)`` and
``torque(id)`` return the per-metre values. A 2D body must stay in the plane (rotation about z only).

Contact parameters: the keywords ``law``, ``mu``, ``cohesion``, ``chi``, ``d0`` of ``add`` (the same for
``DemSpheres.add``) make one ``ym.ContactParams``, whose parameters are declared once, with unit, range,
default and equation, in pkg-mpm/contact/ContactParams.hpp (``print(ym.materials.describe(ym.ContactParams))``;
table in doc/reference/contact.md). Every keyword is checked before any work; NumPy scalars are numbers.
  mu        friction coefficient μ_con [-]. Not given: tan(frictionAngle) of the bodies' YADE ``FrictMat``
            (``b.material``; a clump: its members'), the friction a YADE user sets on the body; explicit
            values win; bodies of one ``add`` with different friction angles need an explicit mu; a
            material without frictionAngle gives the declared default.
  d0        None (default): ½ V_p^{1/D}, half the particle's own edge (autoD0); a number: fixed d0 [m], at most
            one grid spacing; "initial": the paper's "initial distance of particle" — the particles of the
            first lattice layer next to the body when ``add`` registers it get d0 = their initial distance to
            its surface (a body filling a domain, e.g. a flaw filler); the body must not overlap any particle
            centre (ValueError).
  law       "kinematic" (default): no-penetration impulses at the contacting particles, results independent of
            Δt; "penalty": the paper's Eq. 23 as printed (κ = 2m/Δt²; chi applies to it only)
            (doc/reference/contact.md, "Contact laws").
  cohesion, chi: given or the declared defaults.
"""
import math
import numbers

import numpy as np

from ._core import ContactParams
from .scene import dim_of

D0_CHOICES = "None (half the particle edge) or 'initial' (the first layer's initial distance)"


def contact_params(mu=None, cohesion=None, chi=None, d0=None, law=None):
    """``ContactParams`` from the registration keywords (None: the declared default; d0: None, "initial" or a
    number [m], see the module docstring). Ranges come from the declaration (ValueError naming the keyword)."""
    kw = {k: v for k, v in (("mu", mu), ("cohesion", cohesion), ("chi", chi), ("law", law)) if v is not None}
    if isinstance(d0, str):
        if d0 != "initial":
            raise ValueError(f"d0 = {d0!r} is not a choice: a number [m] in [0, grid spacing], {D0_CHOICES}")
        kw["initialD0"] = True
    prm = ContactParams(**kw)
    if d0 is not None and not isinstance(d0, str):
        try:
            prm.d0, prm.autoD0 = d0, False
        except ValueError as e:
            raise ValueError(f"d0 = {d0!r}: {e}; other choices: {D0_CHOICES}") from None
    return prm


def body_ids(ids):
    """[int] from one YADE body id or a sequence of them (NumPy integers accepted); ValueError for anything
    else, a float id included, and for an id listed twice."""
    def is_int(i):
        return isinstance(i, numbers.Integral) and not isinstance(i, (bool, np.bool_))
    if is_int(ids):
        return [int(ids)]
    if ids is None or isinstance(ids, (str, bytes, numbers.Number)):
        raise ValueError(f"ids must be a YADE body id (an integer) or a list of ids (got {type(ids).__name__} {ids!r})")
    try:
        out = list(ids)
    except TypeError:
        raise ValueError(f"ids must be a YADE body id (an integer) or a list of ids (got {type(ids).__name__} {ids!r})") from None
    for i in out:
        if not is_int(i):
            raise ValueError(f"ids: body id {i!r} must be an integer (got {type(i).__name__})")
    out = [int(i) for i in out]
    if not out:
        raise ValueError("ids: give at least one YADE body id")
    twice = sorted({i for i in out if out.count(i) > 1})
    if twice:
        raise ValueError(f"ids: body id {twice[0]} is listed twice (a body is registered for contact once)")
    return out


def check_thickness(thickness):
    """The 2D thickness override: None (the body's z-extent) or a number in (0, inf) [m]."""
    if thickness is not None and not (isinstance(thickness, numbers.Real) and not isinstance(thickness, (bool, np.bool_))
                                      and 0 < thickness < math.inf):
        raise ValueError(f"thickness = {thickness!r} is outside the allowed range (0, inf) [m] or None (the body's z-extent)")


def friction_of(bodies):
    """μ = tan(frictionAngle) of the YADE materials of `bodies` (a clump: its members'); None when none has a
    frictionAngle; ValueError when they differ (then mu must be given)."""
    from yade import O
    angles = {}
    for b in bodies:
        mats = [O.bodies[m].material for m in b.shape.members] if type(b.shape).__name__ == "Clump" else [b.material]
        for m in mats:
            angles.setdefault(getattr(m, "frictionAngle", None), b.id)
    if set(angles) == {None}:
        return None
    if len(angles) > 1:
        raise ValueError("mu not given and the bodies' materials have different friction angles "
                         f"({', '.join(f'{a!r} (body {i})' for a, i in angles.items())}); pass mu")
    (a, bid), = angles.items()
    if not 0 <= a < math.pi / 2:
        raise ValueError(f"mu not given: body id {bid}'s material has frictionAngle = {a!r} rad, outside [0, pi/2); pass mu")
    return math.tan(a)


def check_state(b):
    """A body's position [m] and velocity [m/s] must be finite (a DEM sphere at a NaN position was registered
    and never touched anything)."""
    for name, v, unit in (("pos", b.state.pos, "m"), ("vel", b.state.vel, "m/s")):
        if not all(math.isfinite(x) for x in v):
            raise ValueError(f"body id {b.id}: state.{name} = ({', '.join(repr(float(x)) for x in v)}) [{unit}] must be finite")


def _yade_body(i):
    """O.bodies[i] for a registrable id: it must exist and not be a clump member (pass the clump)."""
    from yade import O
    if i < 0 or i >= len(O.bodies) or O.bodies[i] is None:
        raise ValueError(f"body id {i!r} does not exist in O.bodies")
    b = O.bodies[i]
    if b.isClumpMember:
        raise ValueError(f"body id {i} is a member of clump {b.clumpId}; pass the clump id {b.clumpId}")
    return b


def body_inertia(b, dim, thickness):
    """(mass, principal moments) of YADE body `b` as the contact's stick step sees it, inf along what is
    prescribed: a body that is not dynamic, or with a translational DOF of the plane (2D: x, y; 3D: x, y, z)
    in ``blockedDOFs``, has an infinite mass; a blocked rotation (2D: Z; 3D: any of X, Y, Z) infinite
    moments. 2D: per metre of `thickness` [kg/m, kg m²/m], the z moment only (a float); 3D: [kg], the three
    principal moments along the body's axes [kg m²] (a tuple)."""
    st, inf = b.state, float("inf")
    blocked, fixed = st.blockedDOFs, not b.dynamic
    trans, rot = ("xy", "Z") if dim == 2 else ("xyz", "XYZ")
    mass = inf if fixed or any(c in blocked for c in trans) else st.mass
    free_rot = not (fixed or any(c in blocked for c in rot))
    if mass != inf and not mass > 0:
        raise ValueError(f"body id {b.id}: state.mass = {mass!r} kg must be > 0 for a dynamic body free in the plane")
    moments = [st.inertia[a] if free_rot else inf for a in ((2,) if dim == 2 else (0, 1, 2))]
    if free_rot and not all(m > 0 for m in moments):
        raise ValueError(f"body id {b.id}: state.inertia = {tuple(st.inertia)!r} kg m² must be > 0 for a free rotation")
    if dim == 2:
        return mass / thickness, moments[0] / thickness
    return mass, tuple(moments)


def _rot(q):
    m = q.toRotationMatrix()
    return np.array([[m[i, j] for j in range(3)] for i in range(3)])


def _vec(v):
    return np.array([v[0], v[1], v[2]], float)


class RigidBodies:
    """Rigid YADE bodies in contact with the particles of one solver (see the module docstring)."""

    def __init__(self, solver):
        self.solver = solver
        self.dim = dim_of(solver)
        self._parts = []      # (yade id, core part index, thickness)
        self._part_of = {}    # yade id -> index in _parts
        self.groups = []      # core group indices, one per add()

    # ------------------------------------------------------------------ set-up
    def add(self, ids, mu=None, cohesion=None, chi=None, d0=None, thickness=None, law=None):
        """Register YADE bodies (an id or a list) as one contact group with friction coefficient mu [-]
        (not given: tan(frictionAngle) of the bodies' YADE FrictMat; explicit values win), cohesion [Pa],
        residual penetration factor chi [-] and detection distance d0 (None: half the particle edge; a number
        [m] up to one grid spacing; "initial": the first particle layer's distance to the body now); ranges
        and defaults: ``ym.ContactParams`` (module docstring). thickness [m] overrides the 2D z-extent. law:
        "kinematic" (default, independent of Δt) or "penalty" (Eq. 23 as printed).
        Everything is checked before the solver changes. Returns the group index."""
        ids = body_ids(ids)
        check_thickness(thickness)
        bodies = []
        for i in ids:
            b = _yade_body(i)
            if i in self._part_of:
                raise ValueError(f"body id {i} is already registered for contact")
            check_state(b)
            bodies.append(b)
        prm = contact_params(friction_of(bodies) if mu is None else mu, cohesion, chi, d0, law)
        prm.validateFor(self.solver.spacing)
        prims = [self._primitives(b) for b in bodies]   # validates shapes before touching the solver
        s = self.solver
        parts = [s._addRigidPart() for _ in bodies]
        g = s._addContactGroup(parts, prm)
        for b, part, (plist, t) in zip(bodies, parts, prims):
            for kind, args in plist:
                getattr(s, kind)(g, part, *args)
        if d0 == "initial":                # the first layer's distances at the bodies' poses now
            try:
                self._read_parts(zip((b.id for b in bodies), parts))
                s._captureContactD0(g)
            except ValueError:
                s._removeLastContactGroup()   # refused (a particle inside the body): nothing registered
                raise
        for b, part, (plist, t) in zip(bodies, parts, prims):
            self._part_of[b.id] = len(self._parts)
            self._parts.append((b.id, part, thickness if thickness is not None else t))
        self.groups.append(g)
        self.read()
        return g

    def initial_d0(self, group):
        """d0 = "initial" groups: the captured d0 [m] per particle id (the ``"id"`` field), NaN where the
        particle keeps the default ½ V_p^{1/D}; an empty array for other groups."""
        if group not in self.groups:
            raise ValueError(f"group = {group!r} is not a contact group of these bodies; groups: {self.groups}")
        return np.asarray(self.solver._contactInitialD0(group))

    def _primitives(self, b):
        """[(solver method, args)], thickness for one body (a clump: its members in the clump frame)."""
        name = type(b.shape).__name__
        if name == "Clump":
            from yade import O
            R0, c0 = _rot(b.state.ori), _vec(b.state.pos)
            out, zlo, zhi = [], [], []
            for mid in b.shape.members:
                m = O.bodies[mid]
                Rm, cm = _rot(m.state.ori), _vec(m.state.pos)
                p, (lo, hi) = self._shape(m, R0.T @ (cm - c0), R0.T @ Rm, c0[2], clump_member=True)
                out += p
                zlo.append(lo), zhi.append(hi)
            if not out:
                raise ValueError(f"body id {b.id}: clump {b.id} has no member crossing the plane z = 0")
            return out, max(zhi) - min(zlo)
        p, (lo, hi) = self._shape(b, np.zeros(3), np.eye(3), _vec(b.state.pos)[2])
        if not p:
            raise ValueError(f"body id {b.id} ({name}) does not cross the plane z = 0 of the 2D scene")
        return p, hi - lo

    def _shape(self, b, cL, RL, zref, clump_member=False):
        """Primitives of one shape placed at cL, RL in its part frame; (primitives, (z-min, z-max))."""
        name, d, sh = type(b.shape).__name__, self.dim, b.shape
        if name == "Box":
            h = _vec(sh.extents)
            if d == 3:
                return [("_addContactBox", (tuple(cL), RL, tuple(h)))], (0.0, 0.0)
            self._planar(RL, b.id)
            corners_z = zref + cL[2] + np.array([-1, 1]) * (np.abs(RL[2, :]) @ h)
            if not (corners_z[0] < 0 < corners_z[1]):
                return [], tuple(corners_z)
            return [("_addContactBox", (tuple(cL[:2]), RL[:2, :2], tuple(h[:2])))], tuple(corners_z)
        if name == "Facet":
            v = np.array([cL + RL @ _vec(x) for x in sh.vertices])
            if d == 3:
                return [("_addContactElement", (v,))], (0.0, 0.0)
            self._planar(RL, b.id)
            z = zref + v[:, 2]
            seg = []
            for k in range(3):
                a, c = k, (k + 1) % 3
                if (z[a] < 0) != (z[c] < 0):
                    t = z[a] / (z[a] - z[c])
                    seg.append(v[a, :2] + t * (v[c, :2] - v[a, :2]))
            zr = (z.min(), z.max())
            if len(seg) != 2 or np.linalg.norm(seg[0] - seg[1]) == 0:
                return [], zr
            return [("_addContactElement", (np.array(seg),))], zr
        if name == "Wall":
            if clump_member:
                raise ValueError(f"body id {b.id}: a Wall cannot be part of a clump for MPM contact")
            axis, sense = int(sh.axis), int(sh.sense)
            if axis >= d:
                raise ValueError(f"body id {b.id}: a Wall with axis {axis} is parallel to the 2D plane (use axis 0 or 1)")
            n = np.zeros(d)
            n[axis] = -1.0 if sense < 0 else 1.0
            return [("_addContactPlane", (tuple(np.zeros(d)), tuple(n), sense == 0))], (-0.5, 0.5)
        raise ValueError(f"body id {b.id} has shape {name}, which MPM contact does not support "
                         "(supported: Box, Wall, Facet, Clump of Box/Facet)")

    def _planar(self, R, bid):
        if not (abs(R[0, 2]) < 1e-9 and abs(R[1, 2]) < 1e-9 and abs(R[2, 0]) < 1e-9 and abs(R[2, 1]) < 1e-9):
            raise ValueError(f"body id {bid} is rotated out of the x–y plane; a 2D scene allows rotation about z only")

    # ------------------------------------------------------------------ every step
    def read(self):
        """Kinematics, mass and inertia (``body_inertia``) of every registered body from O.bodies into the
        solver (before the MPM step). Runs every step: each body is looked up once and its state passed as
        plain tuples (the per-step glue of a paper tunnel, doc/developer/performance.md)."""
        from yade import O
        s, d = self.solver, self.dim
        for bid, part, t in self._parts:
            b = O.bodies[bid]
            self._read_state(b.state, bid, part)
            s._setRigidPartMass(part, *body_inertia(b, d, t))

    def _read_parts(self, pairs):
        from yade import O
        for bid, part in pairs:
            self._read_state(O.bodies[bid].state, bid, part)

    def _read_state(self, st, bid, part):
        m, x, v, w = st.ori.toRotationMatrix(), st.pos, st.vel, st.angVel
        if self.dim == 2:
            self._planar(m, bid)
            self.solver._setRigidPartState(part, (x[0], x[1]), ((m[0, 0], m[0, 1]), (m[1, 0], m[1, 1])), (v[0], v[1]), w[2])
        else:
            R = tuple(tuple(m[i, j] for j in range(3)) for i in range(3))
            self.solver._setRigidPartState(part, (x[0], x[1], x[2]), R, (v[0], v[1], v[2]), (w[0], w[1], w[2]))

    def write(self):
        """Contact reactions of the last MPM step into O.forces (2D: per-metre values × thickness)."""
        from yade import O
        from yade import Vector3
        s = self.solver
        for bid, part, t in self._parts:
            f, m = s._rigidPartForce(part), s._rigidPartTorque(part)
            if self.dim == 2:
                O.forces.addF(bid, Vector3(f[0] * t, f[1] * t, 0.0))
                O.forces.addT(bid, Vector3(0.0, 0.0, m * t))
            else:
                O.forces.addF(bid, Vector3(*f))
                O.forces.addT(bid, Vector3(*m))

    # ------------------------------------------------------------------ results
    def _part(self, bid):
        try:
            return self._parts[self._part_of[int(bid)]]
        except (KeyError, TypeError, ValueError):
            raise ValueError(f"body id {bid!r} is not registered for contact; registered: {sorted(self._part_of)}") from None

    def force(self, bid):
        """Reaction force on body `bid` from the last MPM step [N] (2D: [N/m], per metre of thickness)."""
        return np.array(self.solver._rigidPartForce(self._part(bid)[1]))

    def torque(self, bid):
        """Its moment about the body's centre [N m] (2D: ω_z component per metre, [N m/m])."""
        return np.array(self.solver._rigidPartTorque(self._part(bid)[1]))

    def thickness(self, bid):
        """The z-extent t [m] that scales the 2D per-metre reaction into O.forces."""
        return self._part(bid)[2]

    @property
    def ids(self):
        return [p[0] for p in self._parts]
