"""Building a scene: a solver whose grid covers a region, particles from geometry, in-situ stress and
surface tractions (reading particle fields: ``yade_mpm.fields``)."""
import numpy as np
from . import _core
from .fields import SYM_NAMES, dim_of
from .geometry import _corners, _holes, _integer, _number, fill_region, fill_region_chunks


def make_solver(lo, hi, spacing, margin=2, shift=None, distribute=False):
    """Solver (2D if lo has 2 components, else 3D) whose grid covers [lo, hi] [m] plus `margin` cells
    on every side, with grid spacing l = spacing [m].
    distribute: True → under MPI with more than one rank, distributed construction from the start
    (yade_mpm.parallel.distribute: each rank builds only its slab) and the grid is never allocated whole
    on any rank (only this rank's node layers); on 1 process nothing changes.
    shift: per axis, a fraction of a cell in [0, 1) by which the grid's nodes are moved towards −axis
    (None: no shift): the same scene cut differently by the grid, to measure how much a result depends on
    where the grid cuts it (one more cell is added on a shifted axis, so [lo, hi] stays covered). A boundary
    plane must still lie on a node line or halfway between two (addBoundaryPlane says which shifts fit)."""
    lo, hi = _corners(lo, hi, "make_solver")
    spacing = _number(spacing, "spacing", "m", positive=True)
    margin = _integer(margin, "margin [cells]", 0)
    frac = np.zeros(len(lo))
    if shift is not None:
        frac = np.array([_number(f, "shift", "cells") for f in np.atleast_1d(shift)], float)
        if frac.shape != lo.shape or not np.all((frac >= 0) & (frac < 1)):
            raise ValueError(f"shift = {shift!r}: expected {len(lo)} fractions of a cell, each in [0, 1)")
    cells = np.ceil((hi - lo) / spacing - 1e-9).astype(int) + 2 * int(margin) + (frac > 0)
    origin = lo - (margin + frac) * spacing
    if not isinstance(distribute, (bool, np.bool_)):
        raise ValueError(f"make_solver: distribute = {distribute!r} must be True or False")
    cls = _core.Solver2D if len(lo) == 2 else _core.Solver3D
    return cls(tuple(origin), float(spacing), tuple(int(c) for c in cells), distribute=bool(distribute))


def _settings_probe():
    """A one-cell solver whose settings hold the declared defaults (read by the setting helpers below)."""
    return _core.Solver2D((0.0, 0.0), 1.0, (1, 1))


def check_setting(name, value, option=None):
    """Checks a solver setting (declared once in pkg-mpm/core/SolverSettings.hpp) before any solver exists,
    e.g. a command-line option; the ValueError names `option` (default: the setting) with the declared
    unit and range. Returns the value."""
    probe = _settings_probe()
    if name not in probe.settings():
        raise ValueError(f"unknown solver setting '{name}'; known: {', '.join(probe.settings())}")
    try:
        setattr(probe, name, value)
    except ValueError as e:
        raise ValueError(str(e).replace(f"Solver2D.{name}", option or name)) from None
    return value


def setting_default(name):
    """The declared default of a solver setting (pkg-mpm/core/SolverSettings.hpp), e.g. for a script option
    whose default is the solver's: read here, never repeated."""
    probe = _settings_probe()
    if name not in probe.settings():
        raise ValueError(f"unknown solver setting '{name}'; known: {', '.join(probe.settings())}")
    return getattr(probe, name)


def setting_choices(name):
    """The words a choice setting accepts (e.g. velocityUpdate), read from its declaration."""
    probe = _settings_probe()
    choices = {p["name"]: tuple(p["choices"]) for p in probe.settingsTable() if "choices" in p}
    if name not in choices:
        raise ValueError(f"'{name}' is not a choice setting; choice settings: {', '.join(choices)}")
    return choices[name]


def courant_option(ap):
    """Adds --courant and --velocity-update to a script's argparse parser: default None = the solver's declared
    value (read, not repeated); a C is checked against the declared range by :func:`check_courant`; both are
    set on a solver by :func:`apply_step_options`."""
    ap.add_argument("--courant", type=float, default=None,
                    help=f"Courant number C of the step Δt = C·l/(v_c + max|v|) (default: the solver's, {setting_default('courant'):g})")
    ap.add_argument("--velocity-update", choices=setting_choices("velocityUpdate"), default=None,
                    help=f"particle velocity update in G2P: 'pic' (Eq. 6 as printed, the paper's) or 'flip' (default: the "
                         f"solver's, {setting_default('velocityUpdate')})")


def apply_step_options(solver, args):
    """Sets the step options of :func:`courant_option` (args.courant, args.velocity_update; None = the solver's) on
    `solver`; returns them as a dict for a run's record."""
    if args.courant is not None:
        solver.courant = args.courant
    if args.velocity_update is not None:
        solver.velocityUpdate = args.velocity_update
    return dict(courant=solver.courant, velocity_update=solver.velocityUpdate)


def check_courant(value, option="--courant"):
    """`value` checked against the solver's declared range (None: the solver's default); returns the C
    a run will use."""
    return setting_default("courant") if value is None else check_setting("courant", value, option)


GAP_NODES = ("excluded", "shared")
STENCIL_CELLS = 4          # the cubic B-spline support [cells]: a hole at least this wide keeps its faces apart on the grid


def is_thin(hole, spacing):
    """True when `hole` (a geometry shape) is narrower than the cubic B-spline support, STENCIL_CELLS cells of
    `spacing` [m]: only then can particles on its two faces share grid nodes."""
    return hole.width() < STENCIL_CELLS * spacing


def add_region(solver, material, lo, hi, ppc=2, holes=(), keep=None, gap_nodes="excluded"):
    """Fill [lo, hi] minus holes with particles of `material` (ppc per cell per axis, default 2).
    Each region keeps its own material (several materials per scene, e.g. rock with an elastic infill):
    the material is added to the solver (an identical one already there is reused) and the damage
    thresholds of the new particles follow from it. Returns the ids of the new particles (an array; under
    yade_mpm.parallel.distribute a `range` of the same ids, so no rank holds an array of every particle's id).

    gap_nodes: "excluded" (default) takes the grid nodes inside thin holes (a flaw or hole narrower than
    the cubic B-spline support, 4 cells) out of the WLS fits, so the two faces are not tied through
    shared nodes (thin_gap_nodes); "shared" keeps them (the paper's construction). Particles of a later
    region that fill such a gap (a filled flaw) put its nodes back into the fits."""
    d = dim_of(solver)
    if np.ndim(lo) != 1 or len(lo) != d:
        raise ValueError(f"region lo = {lo} must have {d} components for a {d}D solver")
    if gap_nodes not in GAP_NODES:
        raise ValueError(f"gap_nodes = {gap_nodes!r} must be one of {GAP_NODES}")
    if _distributed(solver):
        return _add_region_distributed(solver, material, lo, hi, ppc, holes, keep, gap_nodes)
    x, v = fill_region(lo, hi, solver.spacing, ppc, holes, keep)
    first = solver.numParticles
    index = material_index(solver, material)
    solver._addParticles(x, np.full(len(x), v), np.full(len(x), v * material.density), material=index)
    _refill_gaps(solver, solver.spacing / ppc)
    if gap_nodes == "excluded" and len(holes):
        for i in thin_gap_nodes(solver, lo, hi, solver.spacing / ppc, holes):
            solver._setNodeExcluded(int(i), True)
    return np.arange(first, first + len(x))


def _distributed(solver):
    """True when each MPI rank builds only its slab of this solver's particles (yade_mpm.parallel.distribute)."""
    return hasattr(solver, "mpiInfo") and bool(solver.mpiInfo()["distributedBuild"])


def _add_region_distributed(solver, material, lo, hi, ppc, holes, keep, gap_nodes):
    """add_region under distributed construction: the lattice in chunks of slices along x (at most about
    CHUNK particles each, in the order of fill_region), each rank keeping its slab's particles (the core clips;
    ids are the running index over all ranks, as on 1 process). The lattice is generated twice (`keep` is
    called twice per chunk): first its particles are counted per block layer, so the scene's first region
    sets the ranks' start layout from them (each rank starts near N/R particles) and each rank reserves its
    share at once; then it is added. Returns the global ids of the new particles as a range (an array of them
    would hold 8 bytes per particle of the whole region on every rank)."""
    if gap_nodes == "excluded" and any(is_thin(h, solver.spacing) for h in _holes(holes, dim_of(solver))):
        raise ValueError("add_region: gap_nodes = 'excluded' with a thin hole needs every particle near the gap on every rank; under "
                         "yade_mpm.parallel.distribute use gap_nodes = 'shared', or build the scene without distribute")
    counts = None
    for x, _ in fill_region_chunks(lo, hi, solver.spacing, ppc, holes, keep, CHUNK):
        c = np.asarray(solver._mpiLayerCounts(x))
        counts = c if counts is None else counts + c
    if counts is None:
        raise ValueError("the region holds no particles (holes cover it or it is smaller than a sub-cell)")
    index = material_index(solver, material)
    first = int(solver.mpiInfo()["builtParticles"])
    solver._mpiPlan(counts.tolist())
    total = 0
    for x, v in fill_region_chunks(lo, hi, solver.spacing, ppc, holes, keep, CHUNK):   # fill_region's points and order
        solver._addParticles(x, np.full(len(x), v), np.full(len(x), v * material.density), material=index)
        total += len(x)
        del x
    return range(first, first + total)


CHUNK = 1 << 17   # particles generated at once by a distributed add_region (every rank generates every chunk)


def thin_gap_nodes(solver, lo, hi, dp, holes):
    """Grid nodes (stored indices) that tie the two faces of a thin gap: strictly inside a hole narrower
    than the cubic B-spline support (hole.width() < 4 cells; a flaw, a slot, a hole of diameter < 4 cells),
    empty (no particle's cell, a square of side dp [m], contains the node) and reaching particles on BOTH
    sides along some grid axis within its support (2 cells), in a tube of half-width dp/2 around the node's
    axis line. Such a node would move both faces with one velocity. Nodes of wide openings, nodes on a
    hole's boundary (its tips) and nodes reaching one face only are kept, so a particle that later moves
    into the gap still has active nodes on both sides for its WLS fit (tests/test_boundaries.py).
    Only nodes strictly inside the box [lo, hi] [m]; every particle in the solver counts."""
    from scipy.spatial import cKDTree
    d = dim_of(solver)
    h = solver.spacing
    thin = [g for g in holes if is_thin(g, h)]
    if not thin:
        return np.zeros(0, np.int64)
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    xn = solver._nodePositions()
    cand = np.nonzero(np.all((xn > lo + 1e-9 * h) & (xn < hi - 1e-9 * h), axis=1))[0]
    # strictly inside a thin hole: the node and its 3^D − 1 neighbours at 1e-6 l are all inside
    offsets = 1e-6 * h * (np.array(np.meshgrid(*[[-1, 0, 1]] * d, indexing="ij")).reshape(d, -1).T)
    strict = np.zeros(len(cand), bool)
    for g in thin:
        strict |= np.all([g.contains(xn[cand] + o) for o in offsets], axis=0)
    cand = cand[strict]
    if len(cand) == 0:
        return np.zeros(0, np.int64)
    xp = np.column_stack([solver.view(f"x{a}") for a in range(d)])
    tree = cKDTree(xp)
    near, _ = tree.query(xn[cand], p=np.inf)
    cand = cand[near > 0.5 * dp * (1 + 1e-6)]                 # empty
    out = []
    for i, nb in zip(cand, tree.query_ball_point(xn[cand], 2 * h * (1 - 1e-9), p=np.inf)):
        if not nb:
            continue
        r = xp[nb] - xn[i]
        for a in range(d):
            tube = np.all(np.abs(np.delete(r, a, axis=1)) <= 0.5 * dp * (1 + 1e-6), axis=1)
            if np.any(tube & (r[:, a] > 0)) and np.any(tube & (r[:, a] < 0)):
                out.append(i)
                break
    return np.array(out, dtype=np.int64)


def _refill_gaps(solver, dp):
    """Gap nodes that particles added since now cover (a filled flaw) take part in the fits again."""
    from scipy.spatial import cKDTree
    gap = np.nonzero(solver._excludedNodes() & _core.exclusionBits["gap"])[0]
    if len(gap) == 0:
        return
    d = dim_of(solver)
    tree = cKDTree(np.column_stack([solver.view(f"x{a}") for a in range(d)]))
    near, _ = tree.query(solver._nodePositions()[gap], p=np.inf)
    for i in gap[near <= 0.5 * dp * (1 + 1e-6)]:
        solver._setNodeExcluded(int(i), False)


def material_index(solver, material):
    """Index of `material` in the solver: an identical material (same type and parameters) already added
    is reused, else it is added (solver._addMaterial)."""
    for i in range(solver.numMaterials):
        m = solver.material(i)
        if type(m) is type(material) and m.toDict() == material.toDict():
            return i
    return solver._addMaterial(material)


def set_initial_stress(solver, stress):
    """In-situ stress for every particle: components (xx, yy, zz, xy[, xz, yz]) [Pa], tension positive."""
    d = dim_of(solver)
    n = len(SYM_NAMES[d])
    try:
        stress = np.asarray(stress, float)
    except (TypeError, ValueError):
        raise ValueError(f"initial stress must be {n} numbers {SYM_NAMES[d]} [Pa] (got {type(stress).__name__} {stress!r})") from None
    if stress.shape != (n,) or not np.all(np.isfinite(stress)):
        raise ValueError(f"initial stress must be {n} finite components {SYM_NAMES[d]} [Pa] (got {stress.tolist()})")
    for k in range(n):
        solver.view(f"sig{k}")[:] = stress[k]
    solver.requestSort()


def boundary_particles(solver, axis, side, tol=None):
    """Storage indices of the particle layer nearest the region face `side` (-1 low, +1 high) of `axis`."""
    _axis_side(solver, axis, side)
    d = solver.spacing / 2 if tol is None else _number(tol, "tol", "m", positive=True)
    x = solver.view(f"x{axis}")
    if _distributed(solver):   # each rank holds its slab: the face is the global edge (a collective)
        from . import _core
        m = _core.mpiMax([-x.min() if len(x) else -np.inf, x.max() if len(x) else -np.inf])
        edge = -m[0] if side < 0 else m[1]
        if not np.isfinite(edge):
            raise ValueError("boundary_particles: the solver has no particles")
        return np.nonzero(np.abs(x - edge) < 0.5 * d)[0]
    if solver.numParticles == 0:
        raise ValueError("boundary_particles: the solver has no particles")
    edge = x.min() if side < 0 else x.max()
    return np.nonzero(np.abs(x - edge) < 0.5 * d)[0]


def apply_traction(solver, indices, traction, area):
    """Prescribed traction t [Pa] on particle faces of area `area` [m² per particle; in 2D face length
    × 1 m]: adds the surface force t·area to each particle (Eq. 22). Indices are storage slots; call
    before stepping (the solver re-sorts particles but carries the forces with them)."""
    d = dim_of(solver)
    idx = np.asarray(indices)
    if idx.ndim != 1 or not (idx.dtype.kind in "iu" or len(idx) == 0):
        raise ValueError(f"indices must be a 1-D array of integer particle slots (got dtype {idx.dtype}, shape {idx.shape})")
    if len(idx) == 0 and not _distributed(solver):   # distributed construction: a rank may hold none of the face
        raise ValueError("indices is empty: the traction would be applied to no particle")
    t = _traction(traction, d, len(idx))
    area = _number(area, "area", "m²", positive=True)
    if len(idx) == 0:
        return
    indices = idx
    try:
        old = np.column_stack([solver.view(f"trac{a}")[indices] for a in range(d)])
    except ValueError:
        old = 0.0
    solver._setParticleForces(np.asarray(indices, np.int64), old + t * area)


def _axis_side(solver, axis, side):
    d = dim_of(solver)
    _integer(axis, "axis", 0, d - 1)
    if isinstance(side, bool) or side not in (-1, 1):
        raise ValueError(f"side = {side!r} must be -1 (material above the face) or +1 (material below)")


def _traction(traction, d, n=None):
    """Traction [Pa] as a finite D-vector (or (n, D) rows), or ValueError naming it."""
    try:
        t = np.asarray(traction, float)
    except (TypeError, ValueError):
        raise ValueError(f"traction must be {d} numbers [Pa] (got {type(traction).__name__} {traction!r})") from None
    if t.shape != (d,) and not (n is not None and t.shape == (n, d)):
        raise ValueError(f"traction must have shape ({d},){'' if n is None else f' or ({n}, {d})'} [Pa] for a {d}D solver (got {t.shape})")
    if not np.all(np.isfinite(t)):
        raise ValueError(f"traction = {t.tolist()} Pa must be finite")
    return np.broadcast_to(t, (n, d)) if n is not None else t


def _bspline3(t):
    """Cubic B-spline weight of the WLS shape functions (Eq. 13), t in cells."""
    t = np.abs(t)
    return np.where(t < 1, 0.5 * t ** 3 - t ** 2 + 2 / 3, np.where(t < 2, (2 - t) ** 3 / 6, 0.0))


def consistent_row_weights(ppc, offset=0.0):
    """Shares β_k (Σβ = 1) of a face traction carried by the particle rows k = 0, 1, … counted from a
    free face, such that the nodal forces of the traction cancel, node by node, the internal force
    (Eq. 21) of the matching uniform stress: an intact block loaded this way stays in equilibrium.

    With the interior WLS closed form (ψ_i = w_i, ∇ψ_i = w_i·3/l²·(x_i − x_p)) the internal force of a
    uniform stress near a face is not what a traction on the outermost row alone delivers through ψ_i;
    that leaves a self-equilibrated residual that halves the stress of the outer particle row (measured
    on the circular opening). The problem factorises per axis, so a 1D solve over 3·ppc rows is exact,
    also at corners. offset [cells, in [0, 1)]: where the face lies between two node lines, measured from
    the node line behind it (outside the material) towards the material; 0 = on a node line. Exact weights
    exist for every offset, but between about 0.3 and 0.8 they alternate with amplitudes up to ~20 (their
    balance is exact for the particles where they start; a face on or near a node line is the robust
    choice). Valid for a flat face with ppc particles per cell per axis and no other free face within
    3 cells. Cells are the unit of length here."""
    _integer(ppc, "ppc (ppc = 1 has no consistent face load: use consistent=False)", 2, 16)
    offset = _number(offset, "offset", "cells")
    if not 0 <= offset < 1:
        raise ValueError(f"offset = {offset} cells must lie in [0, 1)")
    rows = offset + (np.arange(10 * ppc) + 0.5) / ppc  # particle rows inside the face at x = offset
    nodes = np.arange(-2, 8)                          # node columns whose support the first rows touch
    # internal force per unit stress (up to the common factor V·Σw_y): Σ_k w_i(x_k)(x_i − x_k)·3
    f_int = np.array([np.sum(_bspline3(i - rows) * (i - rows)) * 3 / ppc for i in nodes])
    for n in range(1, 5 * ppc + 1):                   # fewest rows that balance every node exactly
        A = np.array([[_bspline3(i - x) for x in rows[:n]] for i in nodes])
        a = np.linalg.lstsq(A, f_int, rcond=None)[0]
        if np.abs(A @ a - f_int).max() < 1e-9 * np.abs(f_int).max():
            return a / a.sum()
    raise ValueError(f"ppc = {ppc}, offset = {offset}: no exact consistent face load exists; load the outer row (consistent=False)")


def apply_face_traction(solver, axis, side, face, traction, ppc=2, consistent=True):
    """Traction t [Pa] (a D-vector, e.g. σ0·n) on the flat face x_axis = face [m] of a particle lattice
    with ppc particles per cell per axis, side = -1 when the material lies above the face, +1 below.
    consistent=True spreads it over the outer rows with consistent_row_weights (recommended: exact
    equilibrium with a uniform stress, for the face's place between the grid's node lines); False puts
    it all on the outermost row. A traction that varies
    along the face: a callable t(points) → (n, D) array [Pa], called with the face points (n, D) [m] of
    each loaded row's particles (their positions moved onto the face). Call before stepping."""
    _axis_side(solver, axis, side)
    d = dim_of(solver)
    face = _number(face, "face", "m")
    t = traction if callable(traction) else _traction(traction, d)
    _integer(ppc, "ppc (particles per cell per axis)", 1)
    dp = solver.spacing / ppc                         # particle spacing = face length of a boundary particle
    frac = (face - solver.origin[axis]) / solver.spacing % 1.0   # where the face lies between two node lines
    frac = 0.0 if min(frac, 1 - frac) < 1e-9 else frac
    beta = consistent_row_weights(ppc, frac if side < 0 else (1.0 - frac) % 1.0) if consistent else np.array([1.0])
    dist = _distributed(solver)
    if solver.numParticles == 0 and not dist:
        raise ValueError("apply_face_traction: the solver has no particles")
    x = solver.view(f"x{axis}")
    depth = (x - face) if side < 0 else (face - x)
    row = np.round(depth / dp - 0.5).astype(int)      # 0 = outermost particle row
    rows = [np.nonzero(row == k)[0] for k in range(len(beta))]
    counts = [len(r) for r in rows]
    if dist:   # each rank holds its slab: a row has particles if it has on some rank (a collective)
        from . import _core
        counts = [int(c) for c in _core.mpiMax([float(c > 0) for c in counts])]
    for k, r in enumerate(rows):                       # a face off the lattice applied nothing before
        if counts[k] == 0:
            raise ValueError(f"face x{axis} = {face} m (side {side:+d}) has no particles in row {k} of the {len(beta)} loaded rows: "
                             f"the particles span [{x.min():.6g}, {x.max():.6g}] m along axis {axis}; the face must be the "
                             f"{'lower' if side < 0 else 'upper'} edge of the particle lattice")
    area = dp ** (d - 1)                              # 2D: face length × 1 m thickness
    for r, b in zip(rows, beta):
        if callable(t):                                # t at the face point of each particle of the row
            pts = np.column_stack([solver.view(f"x{a}")[r] if a != axis else np.full(len(r), face) for a in range(d)])
            apply_traction(solver, r, b * np.asarray(t(pts), float), area)
        else:
            apply_traction(solver, r, b * t, area)
