"""Particle fields for users: one vocabulary, one order.

``get(solver, name)`` and ``fields(solver)`` return COPIES in particle-id order (the order of
``add_region``'s returned ids, stable over the whole run), with YADE-like names (``pos``, ``vel``,
``mass`` as ``b.state.pos`` …). Both stresses have a name: ``stress`` is the stress the particle carries
(damaged for DP–GK, Eq. 40), ``undamaged_stress`` the stress of the intact material that the
constitutive update advances (equal to ``stress`` for elastic particles and for D = 0).

Removed particles (``Solver.outside``: material that left the grid and was taken out of the computation)
keep their ids and rows: every float field is NaN in a removed particle's row, ``id`` and ``material`` keep
their values and the bool field ``removed`` is True there (N rows = particles added, removed or not; sum
with ``np.nansum``, or select ``~f["removed"]``). ``removed(solver)`` lists their state at removal and the
running account (count, mass, momentum, kinetic energy, faces). Under MPI each rank reads its own particles
(no rows for removed ones).

Power users: ``solver.view(name)`` and ``views(solver)`` are live NumPy views on the solver's own
arrays (no copy, writable) under the core's short names (x0, v0, sig0.., epsP, vol …) in STORAGE
order, which changes whenever the solver re-sorts its particles (every step may); ``view("id")``
tells which particle sits in each slot. Write through them only before a step and call
``solver.requestSort()`` afterwards; the ``id`` view is read-only (``views``, ``solver.view``).
"""
import numpy as np

from . import _core

SYM_NAMES = {2: ("xx", "yy", "zz", "xy"), 3: ("xx", "yy", "zz", "xy", "xz", "yz")}

# name: (storage view(s) or how it is computed, unit, meaning) — the one declaration of the user fields
FIELDS = {
    "id": ("id", "-", "particle id (add_region's return values)"),
    "pos": ("x", "m", "position, (N, D)"),
    "vel": ("materialVelocity()", "m/s", "velocity of the material point, (N, D): under velocityUpdate 'pic' the particle moves "
            "with it, under 'flip' it is the carried v_p (the particle moves with Σ ψ_i v_i); next to a body (cut WLS "
            "stencil) v_p + C_p (x_p − x̄_p), see 'momentum'"),
    "momentum": ("mass·v", "kg·m/s", "momentum m_p v_p, (N, D): Σ over the particles is the total momentum exactly (the "
                 "grid's); v_p = momentum/mass equals vel except next to a body, where it is the velocity at x̄_p"),
    "stress": ("effectiveStress()", "Pa", "stress carried, damaged for DP–GK (Eq. 40); (N, 4) xx, yy, zz, xy in 2D, "
               "(N, 6) xx, yy, zz, xy, xz, yz in 3D; tension positive"),
    "undamaged_stress": ("sig", "Pa", "stress of the undamaged material (the constitutive state, Eqs. 26–33); "
                         "components and sign as stress"),
    "max_principal_stress": ("maxPrincipalStress()", "Pa", "largest principal value of stress (σ̃max, tension positive)"),
    "damage": ("damage", "-", "Grady–Kipp damage D in [0, 1] (0 for elastic particles)"),
    "plastic_strain": ("epsP", "-", "accumulated plastic strain ε̄p (0 for elastic particles)"),
    "cohesion": ("_cohesion()", "Pa", "current cohesion c(ε̄p) (Eq. 34; NaN for elastic particles); DP–GK scenes only"),
    "mass": ("mass", "kg", "mass (per metre of thickness in 2D)"),
    "volume": ("vol", "m³", "current volume (m² × 1 m in 2D)"),
    "material": ("material", "-", "material index (solver.material(i))"),
    "removed": ("removedParticles()", "-", "True for a particle removed after it left the grid (Solver.outside): its "
                "rows of every float field are NaN, id and material keep their values; removed(solver) has its state at removal"),
}
_RENAMED = {"state_stress": "undamaged_stress", "sig": "stress' or 'undamaged_stress", "x": "pos", "v": "vel",
            "epsP": "plastic_strain", "vol": "volume", "position": "pos", "velocity": "vel"}


def dim_of(solver):
    """2 or 3; ValueError if `solver` is not a Solver2D/Solver3D."""
    if isinstance(solver, _core.Solver2D):
        return 2
    if isinstance(solver, _core.Solver3D):
        return 3
    raise ValueError(f"solver must be a Solver2D or Solver3D (got {type(solver).__name__})")


def views(solver):
    """POWER USERS: live NumPy views (STORAGE order, no copy) of every allocated particle array, keyed by
    the core's names: x0.., v0.., sig0.. (undamaged stress xx, yy, zz, xy[, xz, yz]), mass, vol, vol0, id
    (read-only), material (read-only), epsP, damage, eps0, nFlaw. The storage order changes when the
    particles are re-sorted (a step may); `id` tells which particle sits in each slot. For analysis use
    ``get`` / ``fields`` (copies, id order, user names)."""
    d = dim_of(solver)
    names = [f"x{a}" for a in range(d)] + [f"v{a}" for a in range(d)] + [f"sig{k}" for k in range(len(SYM_NAMES[d]))]
    names += ["mass", "vol", "vol0", "id", "material", "epsP", "damage", "eps0", "nFlaw"]
    out = {}
    for n in names:
        try:
            out[n] = solver.view(n)
        except ValueError:
            pass
    return out


def id_order(solver):
    """Storage slots in particle-id order (valid until the next step re-sorts the particles)."""
    return np.argsort(solver.view("id"), kind="stable")


def _removed_ids(solver):
    """Ids of the removed particles of a one-process solver (None when there are none or under MPI, where
    each rank reads only its own particles)."""
    from .parallel import size
    if solver._removedAccount()["count"] == 0 if size() == 1 else True:
        return None
    return solver._removedParticles()["id"]


def _with_removed_rows(solver, name, live, order):
    """Spreads the live particles' rows (id order) over all ids, removed ones included: NaN rows (float
    fields), the id, the material index, the removed flag."""
    gone = _removed_ids(solver)
    if gone is None:
        return live
    ids = solver.view("id")[order]
    total = len(ids) + len(gone)
    if name == "id":
        return np.arange(total, dtype=live.dtype)
    if name == "removed":
        out = np.zeros(total, dtype=bool)
        out[gone] = True
        return out
    if name == "material":
        out = np.empty(total, dtype=live.dtype)
        out[ids] = live
        out[gone] = solver._removedParticles()["material"]
        return out
    out = np.full((total,) + live.shape[1:], np.nan)
    out[ids] = live
    return out


def removed(solver):
    """What left the grid and was removed (``Solver.outside``): a dict with the running account — count,
    mass [kg], momentum (Σ m v) [kg·m/s], kinetic_energy [J], last_time [s], last_step, faces {'x-': n, …} —
    and 'particles', the removed particles in removal order: id, step, time [s], pos [m], vel [m/s] (at
    removal), mass [kg], damage, face ('x+' …), material, reason ('remove', 'damaged' = D = 1, 'detached' =
    not in the body's cluster). Under MPI the account is over every rank (a collective), the particles are
    this rank's."""
    d = dict(solver._removedAccount())
    p = dict(solver._removedParticles())
    dim = dim_of(solver)
    p["face"] = np.array([f"{'xyz'[f // 2]}{'+' if f % 2 else '-'}" for f in p["face"]], dtype=f"<U2")
    p["reason"] = np.array([("remove", "damaged", "detached")[r] for r in p["reason"]], dtype="<U8")
    p["pos"], p["vel"] = p["pos"].reshape(-1, dim), p["vel"].reshape(-1, dim)
    d["particles"] = p
    return d


def get(solver, name, order=None):
    """Copy of the particle field `name` in particle-id order (row k = particle id k). Names (``FIELDS``):
    id, pos, vel [m, m/s] (of the material point), momentum [kg·m/s] (sums to the total exactly), stress (carried, damaged for DP–GK) and undamaged_stress [Pa] (xx, yy, zz, xy[,
    xz, yz], tension positive), max_principal_stress [Pa], damage, plastic_strain, cohesion [Pa], mass
    [kg], volume [m³], material, removed (True for a particle removed after it left the grid: NaN in its
    rows of the float fields). Pass order=id_order(solver) when reading several fields of one state."""
    d = dim_of(solver)
    if name not in FIELDS:
        hint = f" (use '{_RENAMED[name]}')" if name in _RENAMED else ""
        raise ValueError(f"unknown field {name!r}{hint}; fields: {', '.join(FIELDS)}")
    o = id_order(solver) if order is None else order
    return _with_removed_rows(solver, name, _get_live(solver, name, o, d), o)


def _get_live(solver, name, o, d):
    """Field `name` of the particles in the computation, in id order (storage slots o)."""
    if name == "removed":
        return np.zeros(len(o), dtype=bool)
    if name == "pos":
        return np.column_stack([solver.view(f"x{a}") for a in range(d)])[o]
    if name == "vel":
        return solver._materialVelocity()[o]
    if name == "momentum":
        return (solver.view("mass")[:, None] * np.column_stack([solver.view(f"v{a}") for a in range(d)]))[o]
    if name == "stress":
        return solver._effectiveStress()[o]
    if name == "undamaged_stress":
        return np.column_stack([solver.view(f"sig{k}") for k in range(len(SYM_NAMES[d]))])[o]
    if name == "max_principal_stress":
        return solver._maxPrincipalStress()[o]
    if name in ("damage", "plastic_strain"):
        try:
            return solver.view(FIELDS[name][0])[o].copy()
        except ValueError:                       # not allocated: no DP–GK material in the scene
            return np.zeros(len(o))
    if name == "cohesion":
        if 1 not in solver._materialKinds:
            raise ValueError("cohesion exists only for the DP–GK material")
        return solver._cohesion()[o]              # Eq. 34 with each particle's material; NaN for other materials
    return solver.view(FIELDS[name][0])[o].copy()


def fields(solver, names=None, exclude=()):
    """Several fields of one state (default: every field of ``FIELDS`` the scene has), less those named in
    `exclude`, each a copy in particle-id order, plus 'time' [s] and 'steps'; a dict ready for ``np.savez`` or
    ``analysis``."""
    bad = [n for n in exclude if n not in FIELDS]
    if bad:
        raise ValueError(f"exclude: unknown field(s) {bad}; known: {', '.join(FIELDS)}")
    o = id_order(solver)
    if names is None:
        names = [n for n in FIELDS if n != "cohesion" or 1 in solver._materialKinds]
    names = [n for n in names if n not in exclude]
    out = {n: get(solver, n, o) for n in names}
    out["time"], out["steps"] = float(solver.time), int(solver.steps)
    return out
