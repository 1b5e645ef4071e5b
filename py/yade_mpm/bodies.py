"""Rigid YADE bodies in an MPM scene: the adapter between ``O.bodies``/``O.forces`` and the core's PTS
contact (paper Sec. 2.3, Eqs. 23–26; the algorithm is in pkg-mpm/PtsContact.hpp, see doc/contact.md).

    rb = ym.RigidBodies(solver)
    rb.add(platen_id, mu=0.0)                       # one contact group per call, its own μ, c, χ, d0
    rb.add([f1, f2, f3, f4], mu=0.4, cohesion=1e6)  # several bodies may share parameters (a facet prism)
    O.engines = [ForceResetter(), ym.MpmEngine(solver, bodies=rb).runner(), NewtonIntegrator(damping=0)]

Every step the engine calls ``read()`` (position, orientation, velocity and angular velocity of every
registered body from ``O.bodies`` into the solver) before the MPM step and ``write()`` (the contact
reaction force and its torque about the body's centre, ``state.pos``, added to ``O.forces``) after it,
so NewtonIntegrator moves free bodies and bodies with ``blockedDOFs`` and a set velocity keep it.
``read()`` also passes each body's mass and inertia (``body_inertia``): the stick step of the friction
(Eq. 24) moves a free body with its contact nodes, so a light body does not overshoot (doc/contact.md).

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

Contact parameters (defaults and units; each validated with its range before any step):
  mu        Coulomb friction coefficient μ_con [-], ≥ 0; default 0 (frictionless)
  cohesion  contact cohesion c_con [Pa], ≥ 0; default 0
  chi       residual penetration factor χ [-], 0 ≤ χ < 1; default ½: with positions advanced by the
            updated velocity, (1 − χ)·2m/Δt² = m/Δt² takes a penetrating particle back to d0 in one step
            (χ = 0 reflects the contact layer and gained 15 % energy at a 3D impact)
  d0        detection distance d0 [m], ≥ 0; default None = ½ V_p^{1/D}, half the particle's own edge:
            a particle stands for a cell of edge V_p^{1/D} centred on it, so contact starts when that
            cell's face reaches the surface (for ppc = 2 this is a quarter of the grid spacing).
            "initial": the paper's "initial distance of particle" — the particles of the first lattice
            layer next to the body when ``add`` registers it get d0 = their initial distance to its surface
            (they touch it at zero force from t = 0: a body filling a domain, e.g. a flaw filler); the
            others keep ½ V_p^{1/D}. The body must not overlap any particle centre (ValueError).
"""
import numpy as np

from . import _core
from .scene import dim_of

CONTACT_DEFAULTS = dict(_core.contactDefaults())   # declared once, in ContactParams (RigidSurface.hpp)


def _check_params(mu, cohesion, chi, d0, thickness):
    def bad(name, v, rng):
        raise ValueError(f"{name} = {v!r} is outside the allowed range {rng}")
    for name, v, ok, rng in (("mu", mu, lambda x: x >= 0, "[0, inf) [-]"),
                             ("cohesion", cohesion, lambda x: x >= 0, "[0, inf) [Pa]"),
                             ("chi", chi, lambda x: 0 <= x < 1, "[0, 1) [-]")):
        if not (isinstance(v, (int, float)) and np.isfinite(v) and ok(v)):
            bad(name, v, rng)
    if not (d0 is None or (isinstance(d0, str) and d0 == "initial")
            or (isinstance(d0, (int, float)) and not isinstance(d0, bool) and np.isfinite(d0) and d0 >= 0)):
        bad("d0", d0, "[0, inf) [m], None (half the particle edge) or 'initial' (the first layer's initial distance)")
    if thickness is not None and not (isinstance(thickness, (int, float)) and np.isfinite(thickness) and thickness > 0):
        bad("thickness", thickness, "(0, inf) [m] or None (the body's z-extent)")


def _yade_body(i):
    """O.bodies[i] for a registrable id: it must exist and not be a clump member (pass the clump)."""
    from yade import O
    if not isinstance(i, (int, np.integer)) or i < 0 or i >= len(O.bodies) or O.bodies[int(i)] is None:
        raise ValueError(f"body id {i!r} does not exist in O.bodies")
    b = O.bodies[int(i)]
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
    def add(self, ids, mu=CONTACT_DEFAULTS["mu"], cohesion=CONTACT_DEFAULTS["cohesion"], chi=CONTACT_DEFAULTS["chi"],
            d0=CONTACT_DEFAULTS["d0"], thickness=None):
        """Register YADE bodies (an id or a list) as one contact group with friction coefficient mu [-],
        cohesion [Pa], residual penetration factor chi [-] and detection distance d0 [m] (None: half the
        particle edge; "initial": the first particle layer's distance to the body now, see the module
        docstring); thickness [m] overrides the 2D z-extent. Returns the group index."""
        _check_params(mu, cohesion, chi, d0, thickness)
        ids = [ids] if isinstance(ids, (int, np.integer)) else list(ids)
        if not ids:
            raise ValueError("ids: give at least one YADE body id")
        bodies = []
        for i in ids:
            b = _yade_body(i)
            if int(i) in self._part_of:
                raise ValueError(f"body id {i} is already registered for contact")
            bodies.append(b)
        prims = [self._primitives(b) for b in bodies]   # validates shapes before touching the solver
        s = self.solver
        parts = [s.addRigidPart() for _ in bodies]
        g = s.addContactGroup(parts, float(mu), float(cohesion), float(chi), d0 if d0 is None or isinstance(d0, str) else float(d0))
        for b, part, (plist, t) in zip(bodies, parts, prims):
            for kind, args in plist:
                getattr(s, kind)(g, part, *args)
        if d0 == "initial":                # the first layer's distances at the bodies' poses now
            try:
                self._read_parts(zip((b.id for b in bodies), parts))
                s.captureContactD0(g)
            except ValueError:
                s.removeLastContactGroup()   # refused (a particle inside the body): nothing registered
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
        return np.asarray(self.solver.contactInitialD0(group))

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
                return [("addContactBox", (tuple(cL), RL, tuple(h)))], (0.0, 0.0)
            self._planar(RL, b.id)
            corners_z = zref + cL[2] + np.array([-1, 1]) * (np.abs(RL[2, :]) @ h)
            if not (corners_z[0] < 0 < corners_z[1]):
                return [], tuple(corners_z)
            return [("addContactBox", (tuple(cL[:2]), RL[:2, :2], tuple(h[:2])))], tuple(corners_z)
        if name == "Facet":
            v = np.array([cL + RL @ _vec(x) for x in sh.vertices])
            if d == 3:
                return [("addContactElement", (v,))], (0.0, 0.0)
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
            return [("addContactElement", (np.array(seg),))], zr
        if name == "Wall":
            if clump_member:
                raise ValueError(f"body id {b.id}: a Wall cannot be part of a clump for MPM contact")
            axis, sense = int(sh.axis), int(sh.sense)
            if axis >= d:
                raise ValueError(f"body id {b.id}: a Wall with axis {axis} is parallel to the 2D plane (use axis 0 or 1)")
            n = np.zeros(d)
            n[axis] = -1.0 if sense < 0 else 1.0
            return [("addContactPlane", (tuple(np.zeros(d)), tuple(n), sense == 0))], (-0.5, 0.5)
        raise ValueError(f"body id {b.id} has shape {name}, which MPM contact does not support "
                         "(supported: Box, Wall, Facet, Clump of Box/Facet)")

    def _planar(self, R, bid):
        if not (abs(R[0, 2]) < 1e-9 and abs(R[1, 2]) < 1e-9 and abs(R[2, 0]) < 1e-9 and abs(R[2, 1]) < 1e-9):
            raise ValueError(f"body id {bid} is rotated out of the x–y plane; a 2D scene allows rotation about z only")

    # ------------------------------------------------------------------ every step
    def read(self):
        """Kinematics, mass and inertia (``body_inertia``) of every registered body from O.bodies into the
        solver (before the MPM step)."""
        from yade import O
        self._read_parts((bid, part) for bid, part, _ in self._parts)
        for bid, part, t in self._parts:
            self.solver.setRigidPartMass(part, *body_inertia(O.bodies[bid], self.dim, t))

    def _read_parts(self, pairs):
        from yade import O
        d, s = self.dim, self.solver
        for bid, part in pairs:
            st = O.bodies[bid].state
            R, x, v, w = _rot(st.ori), st.pos, st.vel, st.angVel
            if d == 2:
                self._planar(R, bid)
                s.setRigidPartState(part, (x[0], x[1]), R[:2, :2], (v[0], v[1]), w[2])
            else:
                s.setRigidPartState(part, (x[0], x[1], x[2]), R, (v[0], v[1], v[2]), (w[0], w[1], w[2]))

    def write(self):
        """Contact reactions of the last MPM step into O.forces (2D: per-metre values × thickness)."""
        from yade import O
        from yade import Vector3
        s = self.solver
        for bid, part, t in self._parts:
            f, m = s.rigidPartForce(part), s.rigidPartTorque(part)
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
        return np.array(self.solver.rigidPartForce(self._part(bid)[1]))

    def torque(self, bid):
        """Its moment about the body's centre [N m] (2D: ω_z component per metre, [N m/m])."""
        return np.array(self.solver.rigidPartTorque(self._part(bid)[1]))

    def thickness(self, bid):
        """The z-extent t [m] that scales the 2D per-metre reaction into O.forces."""
        return self._part(bid)[2]

    @property
    def ids(self):
        return [p[0] for p in self._parts]
