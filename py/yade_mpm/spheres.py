"""DEM spheres and clumps of spheres touching MPM particles, two-way, through the same PTS contact law
as the rigid bodies of ``bodies.py`` (paper Sec. 2.3, Eqs. 23–26; pkg-mpm/contact/PtsContact.hpp):

    sp = ym.DemSpheres(solver)
    sp.add("all", mu=0.3)                              # every free sphere and sphere clump in O.bodies
    sp.add([s1, s2], chi=0.2)                          # or given ids: one call per set of contact parameters
    O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),
                 InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                                 [Law2_ScGeom_FrictPhys_CundallStrack()]),     # sphere–sphere, YADE's own
                 ym.MpmEngine(solver, bodies=sp).runner(),                     # sphere–MPM, both ways
                 NewtonIntegrator(gravity=(0, -9.81, 0))]

Each body is one rigid part of the contact core with its own contact group: a sphere gives one
circle (2D) / sphere (3D), a clump one per member, in the clump's frame. The contact reaction (force
and its moment about the body's centre) goes to ``O.forces`` after the MPM step, the opposite force to
the MPM grid nodes, so NewtonIntegrator moves the spheres; sphere–sphere contacts stay with YADE's
collider and interaction loop. Each active body's mass and inertia (``bodies.body_inertia``; 3D: the
smallest principal moment on every axis) go to the solver every step: the stick step of the friction
moves a free sphere with its contact nodes (doc/reference/contact.md).

Broad phase (far spheres cost almost nothing): a body is *active* (its group enabled, its state sent
to the solver, its reaction read back) only while its bounding circle/sphere comes within ``reach``
(2 grid cells: detection distance + stencil) of the axis-aligned box of the MPM particles. Inactive
bodies are not looked at every step: all positions and velocities are gathered once per check, and
the next check comes after the time the fastest inactive body (plus the fastest MPM particle) needs,
at its current speed and with the gravity acceleration of NewtonIntegrator, to cover half of the
smallest gap — at most ``max_check_steps`` steps later. Between checks a step costs one disabled-flag
test per far body in C++ and nothing in Python.

MPI (``mpirun``, doc/developer/scaling.md "Rigid bodies"): every rank runs the same YADE scene and takes the same
broad-phase decisions — the particle box is the box of every rank's particles (one max-reduction of 2d
doubles per check, ``_core.mpiMax``; a rank without particles takes part) and ``Solver.maxSpeed`` is the
global one — so the ranks enable the same groups at the same steps and meet in the same collectives of
the contact step; the reactions read back are summed over the ranks in rank order (the same bits on every
rank). One process makes no MPI call.

2D (plane strain): a sphere acts through its trace at z = 0, the circle of radius √(R² − z_c²); the MPM
forces are per metre of thickness, and the force/torque added to ``O.forces`` is that × the body's
thickness t (default: its z-extent, 2R for a sphere at z = 0; or ``thickness``), the convention of
``bodies.py``: a sphere of YADE mass m moves like a disc of m/t per metre. 2D spheres must stay in the
plane (``blockedDOFs = 'zXY'``); the trace is taken at registration.

Contact parameters: the keywords of ``RigidBodies.add`` (mu, cohesion, chi, d0, thickness; one
``ym.ContactParams`` declaration, see bodies.py): mu not given = tan(frictionAngle) of each body's YADE
FrictMat (a clump: its members'); d0 = "initial", for a body filling a domain at registration, is
refused here.
"""
import functools
import math
import numbers
import time

import numpy as np

from .bodies import _rot, _vec, _yade_body, body_ids, body_inertia, check_state, check_thickness, contact_params, friction_of
from .scene import dim_of


def _timed(method):
    """Adds the wall time of each call to self.wall (the Python side of the coupling, for the benchmark)."""
    @functools.wraps(method)
    def wrapper(self):
        t0 = time.perf_counter()
        try:
            return method(self)
        finally:
            self.wall += time.perf_counter() - t0
    return wrapper


class DemSpheres:
    """YADE spheres / sphere clumps in two-way PTS contact with one solver's particles (module doc)."""

    def __init__(self, solver, max_check_steps=200):
        """max_check_steps: longest interval between broad-phase checks [steps], an integer ≥ 1. Bodies come
        with ``add``."""
        if not (isinstance(max_check_steps, numbers.Integral) and not isinstance(max_check_steps, bool) and max_check_steps >= 1):
            raise ValueError(f"max_check_steps = {max_check_steps!r} must be an integer ≥ 1")
        from .parallel import size
        self._ranks = size()            # > 1: the particle box of the broad phase is reduced over the ranks
        self.solver, self.dim = solver, dim_of(solver)
        self.ids = np.empty(0, np.int64)
        self.parts = np.empty(0, np.int64)
        self.groups = np.empty(0, np.int64)
        self.bound = np.empty(0)        # bounding radius about the body's centre [m]
        self.thick = np.empty(0)        # 2D thickness t [m] (1 in 3D)
        self.is_clump = np.zeros(0, bool)
        self.active = np.zeros(0, bool)
        self._R0 = {}                   # clump index -> orientation at registration
        self.max_check_steps = int(max_check_steps)
        self._next_check = 0            # solver step of the next broad-phase check
        self.checks = 0                 # broad-phase checks made (for the benchmark)
        self.wall = 0.0                 # wall seconds spent in read() and write() (Python side of the coupling)
        self._newton = None

    def add(self, ids, mu=None, cohesion=None, chi=None, d0=None, thickness=None, law=None):
        """Register YADE spheres and clumps of spheres (an id, a list, or "all": every sphere that is not a
        clump member and every clump of spheres in O.bodies not registered yet), each its own contact group,
        with the keywords of ``RigidBodies.add`` (mu not given: tan(frictionAngle) of each body's FrictMat;
        d0 "initial" refused). Everything is checked before the solver changes. Returns the group indices."""
        from yade import O
        if isinstance(d0, str) and d0 == "initial":
            raise ValueError(f"d0 = {d0!r}: DemSpheres takes a number [m] or None (half the particle edge); "
                             "'initial' is for RigidBodies (a body filling a domain at registration)")
        check_thickness(thickness)
        known = set(self.ids.tolist())
        if isinstance(ids, str) and ids == "all":
            ids = [b.id for b in O.bodies if b is not None and not b.isClumpMember and self._kind(b) is not None
                   and b.id not in known]
            if not ids:
                raise ValueError("ids = 'all': no sphere or clump of spheres to register")
        ids = body_ids(ids)
        s, d = self.solver, self.dim
        rows = []
        for i in ids:
            b = _yade_body(i)
            if i in known:
                raise ValueError(f"body id {i} is already registered for contact")
            check_state(b)
            kind = self._kind(b)
            if kind is None:
                raise ValueError(f"body id {i} has shape {type(b.shape).__name__}; DemSpheres takes spheres and clumps of "
                                 "spheres (use yade_mpm.RigidBodies for boxes, walls, facets)")
            prm = contact_params(friction_of([b]) if mu is None else mu, cohesion, chi, d0, law)
            prm.validateFor(s.spacing)
            rows.append((b, self._members(b, kind), prm))
        n0, n = len(self.ids), len(rows)
        grow = lambda a, fill: np.concatenate([a, np.full(n, fill, a.dtype)])   # noqa: E731
        self.ids = np.concatenate([self.ids, np.array(ids, np.int64)])
        self.parts, self.groups = grow(self.parts, -1), grow(self.groups, -1)
        self.bound, self.thick = grow(self.bound, 0.0), grow(self.thick, 1.0)
        self.is_clump, self.active = grow(self.is_clump, False), grow(self.active, False)
        for k, (b, (members, zext, brad), prm) in enumerate(rows, start=n0):
            part = s._addRigidPart()
            g = s._addContactGroup([part], prm)
            for cL, r in members:
                s._addContactSphere(g, part, tuple(cL[:d]), float(r))
            self.parts[k], self.groups[k], self.bound[k] = part, g, brad
            self.thick[k] = 1.0 if d == 3 else (thickness if thickness is not None else zext)
            self.is_clump[k] = type(b.shape).__name__ == "Clump"
            if self.is_clump[k]:
                self._R0[k] = _rot(b.state.ori)
        s._setContactGroupsEnabled(self.groups[n0:], False)
        self._next_check = 0            # the new bodies get a broad-phase check at the next read()
        return self.groups[n0:].tolist()

    # ------------------------------------------------------------------ set-up helpers
    @staticmethod
    def _kind(b):
        name = type(b.shape).__name__
        if name == "Sphere":
            return "sphere"
        if name == "Clump":
            from yade import O
            if all(type(O.bodies[m].shape).__name__ == "Sphere" for m in b.shape.members):
                return "clump"
        return None

    def _members(self, b, kind):
        """[(centre in the body frame (3,), contact radius)], z-extent, bounding radius; 2D: traces at z = 0."""
        from yade import O
        c0 = _vec(b.state.pos)
        if kind == "sphere":
            spheres = [(np.zeros(3), c0[2], float(b.shape.radius))]
        else:
            # part frame = world axes at registration (YADE's clump frame is its principal axes, which
            # may put a member offset along the local z); later poses: R(t) R(registration)ᵀ
            spheres = []
            for mid in b.shape.members:
                m = O.bodies[mid]
                cm = _vec(m.state.pos)
                spheres.append((cm - c0, cm[2], float(m.shape.radius)))
        out, zlo, zhi, brad = [], [], [], 0.0
        for cL, z, r in spheres:
            zlo.append(z - r), zhi.append(z + r)
            if self.dim == 2:
                if abs(z) >= r:
                    continue                                  # this member does not cross z = 0
                r = math.sqrt(r * r - z * z)                  # trace circle
            out.append((cL, r))
            brad = max(brad, float(np.linalg.norm(cL[:self.dim])) + r)
        if not out:
            raise ValueError(f"body id {b.id} does not cross the plane z = 0 of the 2D scene")
        return out, max(zhi) - min(zlo), brad

    # ------------------------------------------------------------------ every step
    def _gravity(self):
        from yade import O
        if self._newton is None:
            self._newton = next((e for e in O.engines if type(e).__name__ == "NewtonIntegrator"), False)
        return float(np.linalg.norm(_vec(self._newton.gravity))) if self._newton else 0.0

    def _particle_box(self):
        """lo, hi (d,) of the MPM particles. Under MPI the box of every rank's particles (one collective of 2d
        doubles, an exact max): the ranks check at the same steps and take the same decisions from it."""
        s, d = self.solver, self.dim
        if s.numParticles:              # this rank's particles (a rank may hold none under MPI)
            lo = [float(s.view(f"x{a}").min()) for a in range(d)]
            hi = [float(s.view(f"x{a}").max()) for a in range(d)]
        else:
            lo, hi = [math.inf] * d, [-math.inf] * d
        if self._ranks > 1:
            from . import _core
            b = _core.mpiMax([-v for v in lo] + hi)
            lo, hi = [-v for v in b[:d]], b[d:]
        return np.array(lo), np.array(hi)

    def _broad_phase(self):
        from yade import O
        s, d = self.solver, self.dim
        st = [O.bodies[int(i)].state for i in self.ids]
        x = np.array([[q.pos[a] for a in range(d)] for q in st])
        v = np.array([[q.vel[a] for a in range(d)] for q in st])
        bad = ~(np.isfinite(x).all(axis=1) & np.isfinite(v).all(axis=1))
        if bad.any():                                  # a NaN gap would leave the body inactive, silently
            check_state(O.bodies[int(self.ids[np.argmax(bad)])])
        lo, hi = self._particle_box()
        reach = 2.0 * s.spacing
        gap = np.linalg.norm(np.maximum(0.0, np.maximum(lo - x, x - hi)), axis=1) - self.bound - reach
        act = gap <= 0
        on, off = self.groups[act & ~self.active], self.groups[~act & self.active]
        if len(on):
            s._setContactGroupsEnabled(on, True)
        if len(off):
            s._setContactGroupsEnabled(off, False)
        self.active = act
        self.checks += 1
        dt = max(O.dt, 1e-300)
        if act.all():
            self._next_check = s.steps + self.max_check_steps
            return
        g = gap[~act]
        vmax = float(np.max(np.linalg.norm(v[~act], axis=1))) + s.maxSpeed
        acc = self._gravity()
        half = 0.5 * float(g.min())
        # time T to cover half the smallest gap: vmax T + ½ acc T² = half
        if acc > 0:
            T = (-vmax + math.sqrt(vmax * vmax + 2 * acc * half)) / acc
        else:
            T = half / vmax if vmax > 0 else math.inf
        k = int(min(T / dt, self.max_check_steps))
        self._next_check = s.steps + max(1, min(self.max_check_steps, k))

    @_timed
    def read(self):
        """Before the MPM step: broad phase when due, then the kinematics of the active bodies."""
        from yade import O
        s, d = self.solver, self.dim
        if not len(self.ids):
            return
        if s.steps >= self._next_check:
            self._broad_phase()
        k = np.nonzero(self.active)[0]
        if not len(k):
            return
        for j in k[self.is_clump[k]]:                           # orientation matters for clumps only
            q = O.bodies[int(self.ids[j])].state
            R = _rot(q.ori) @ self._R0[j].T
            if d == 2:
                if not (abs(R[0, 2]) < 1e-9 and abs(R[1, 2]) < 1e-9):
                    raise ValueError(f"body id {self.ids[j]}: clump rotated out of the x–y plane (2D: rotation about z only; "
                                     "block it with blockedDOFs = 'zXY')")
                s._setRigidPartState(int(self.parts[j]), (q.pos[0], q.pos[1]), R[:2, :2], (q.vel[0], q.vel[1]), q.angVel[2])
            else:
                s._setRigidPartState(int(self.parts[j]), tuple(q.pos), R, tuple(q.vel), tuple(q.angVel))
        st = [O.bodies[int(i)].state for i in self.ids[k]]
        x = np.array([[q.pos[a] for a in range(d)] for q in st])
        v = np.array([[q.vel[a] for a in range(d)] for q in st])
        w = np.array([[q.angVel[2]] for q in st]) if d == 2 else np.array([[q.angVel[a] for a in range(3)] for q in st])
        s._setRigidPartMotions(self.parts[k], x, v, w)
        mI = [body_inertia(O.bodies[int(self.ids[j])], d, self.thick[j]) for j in k]
        m = np.array([a for a, _ in mI])
        # 3D: the part frame of a clump is not its principal frame; its smallest moment on every axis
        # (a lower bound: the stick step expects more turning than the clump makes; it sticks less, never overshoots)
        I = np.array([[b] if d == 2 else [min(b)] * 3 for _, b in mI])
        s._setRigidPartMasses(self.parts[k], m, I)

    @_timed
    def write(self):
        """After the MPM step: reactions of the active bodies into O.forces (2D: × thickness)."""
        from yade import O
        from yade import Vector3
        k = np.nonzero(self.active)[0]
        if not len(k):
            return
        f, m = self.solver._rigidPartReactions(self.parts[k])
        for j, fj, mj in zip(k, f, m):
            bid, t = int(self.ids[j]), self.thick[j]
            if self.dim == 2:
                if fj[0] == 0 and fj[1] == 0 and mj[0] == 0:
                    continue
                O.forces.addF(bid, Vector3(fj[0] * t, fj[1] * t, 0.0))
                O.forces.addT(bid, Vector3(0.0, 0.0, mj[0] * t))
            else:
                O.forces.addF(bid, Vector3(*fj))
                O.forces.addT(bid, Vector3(*mj))

    # ------------------------------------------------------------------ results
    def _index(self, bid):
        k = np.nonzero(self.ids == int(bid))[0]
        if not len(k):
            raise ValueError(f"body id {bid!r} is not registered; registered: {self.ids.tolist()[:20]}…")
        return int(k[0])

    def force(self, bid):
        """Reaction on body `bid` from the last MPM step [N] (2D: per metre of thickness [N/m])."""
        f, _ = self.solver._rigidPartReactions([int(self.parts[self._index(bid)])])
        return f[0]

    def thickness(self, bid):
        """The 2D thickness t [m] that scales the per-metre reaction into O.forces."""
        return float(self.thick[self._index(bid)])
