"""Elastic reference scenes: the circular opening (paper Sec. 3.1, against Kirsch), the pressurised
line crack (Sec. 3.2, against Sneddon) and the boundary checks of doc/reference/boundaries.md."""
import numpy as np

from yade_mpm import rocks
from yade_mpm.fields import get
from yade_mpm.geometry import Box, Circle
from yade_mpm.materials import ElasticMat
from yade_mpm.scene import add_region, apply_face_traction, apply_traction, make_solver, set_initial_stress

# ------------------------------------------------------------------------------------------------
# Circular opening, paper Sec. 3.1 (Figs. 3-5)
OPENING_CENTER = 2.5        # hole centre x = y [m]
OPENING_RADIUS = 0.1        # a [m] (diameter 0.2 m)
OPENING_SXX = 20e6          # far-field compression σxx [Pa], compression positive
OPENING_SYY = 10e6          # far-field compression σyy [Pa]


def apply_far_field(solver, lo, hi, ppc, sxx, syy, boundary_load="consistent", sides=(-1, 1), field=None):
    """Far-field traction t = σ0·n (σ0 = diag(sxx, syy), tension positive [Pa]) on the four faces of
    the 2D block [lo, hi] [m]: spread over the outer particle rows with ``consistent_row_weights``
    (boundary_load="consistent", exact discrete equilibrium of the intact block) or on the outermost
    row only ("outer-row"). sides: the faces loaded along each axis (a quarter model loads only +1).
    field: instead of σ0, a stress field σ(points) → (σxx, σyy, σxy) arrays [Pa, tension positive] whose
    traction σ·n is applied at each face point (e.g. Kirsch's, so the finite block carries the infinite plate's solution)."""
    if boundary_load not in ("consistent", "outer-row"):
        raise ValueError(f"boundary_load = {boundary_load!r} must be 'consistent' or 'outer-row'")
    for axis, far in ((0, sxx), (1, syy)):
        for side, face in ((sd, lo[axis] if sd < 0 else hi[axis]) for sd in sides):
            t = np.zeros(2)
            t[axis] = side * far                  # σ0·n with n = side·e_axis: compression pushes inwards
            if field is not None:                 # (σ·n)_a = σ_a,axis · side
                def t(pts, axis=axis, side=side):
                    sxx_, syy_, sxy_ = field(pts)
                    return side * (np.column_stack((sxx_, sxy_)) if axis == 0 else np.column_stack((sxy_, syy_)))
            apply_face_traction(solver, axis, side, face, t, ppc, consistent=(boundary_load == "consistent"))


FAR_FIELDS = ("uniform", "kirsch")   # the block faces' load: the paper's uniform far field, or Kirsch's stress there


def circular_opening(spacing, domain=4.8, ppc=2, damping=0.5, boundary_load="consistent", material=None, quarter=False,
                     grid_shift=None, far_field="uniform"):
    """Square block of side `domain` [m] centred on (2.5, 2.5) m with a hole of radius 0.1 m, every
    particle at the in-situ stress (σxx, σyy) = (−20, −10) MPa, σzz = ν(σxx + σyy) (plane strain), and
    the far-field traction on its faces, so only the hole wall is out of balance ("excavation").
    material: default ``rocks.granite()``. quarter=True models the quadrant x, y ≥ 2.5 m only, with
    slip (symmetry) planes on x = 2.5 m and y = 2.5 m (doc/reference/boundaries.md). grid_shift: (fx, fy) fractions of a
    cell by which the grid is moved against the block (``make_solver``'s `shift`; the quarter model's symmetry planes
    take 0 or 0.5 only). far_field: "uniform" (the paper's: σ0·n on the faces; the finite block then differs from
    Kirsch's infinite plate by O((a/L)²)) or "kirsch" (Kirsch's stress σ_K·n on the faces: the block's exact solution is
    Kirsch's, so the error against it is the discretisation's alone — for convergence studies). Returns (solver, lo, hi)."""
    if far_field not in FAR_FIELDS:
        raise ValueError(f"far_field = {far_field!r} must be one of {FAR_FIELDS}")
    mat = material or rocks.granite()
    lo, hi = np.full(2, OPENING_CENTER - domain / 2), np.full(2, OPENING_CENTER + domain / 2)
    if quarter:
        lo = np.full(2, OPENING_CENTER)
    s = make_solver(lo, hi, spacing, margin=2, shift=grid_shift)
    add_region(s, mat, lo, hi, ppc=ppc, holes=[Circle((OPENING_CENTER, OPENING_CENTER), OPENING_RADIUS)])
    sxx, syy = -OPENING_SXX, -OPENING_SYY     # tension positive inside the solver
    set_initial_stress(s, (sxx, syy, mat.poisson * (sxx + syy), 0.0))
    field = None
    if far_field == "kirsch":                 # Eqs. 41–42 at the face points, tension positive
        from ..validation import kirsch
        field = lambda p: tuple(-c for c in kirsch.cartesian(p[:, 0], p[:, 1], (OPENING_CENTER,) * 2, OPENING_RADIUS, OPENING_SXX, OPENING_SYY))
    apply_far_field(s, lo, hi, ppc, sxx, syy, boundary_load, sides=(1,) if quarter else (-1, 1), field=field)
    if quarter:
        s.addBoundaryPlane(0, -1, OPENING_CENTER, "slip")
        s.addBoundaryPlane(1, -1, OPENING_CENTER, "slip")
    s.damping = damping
    return s, lo, hi


# ------------------------------------------------------------------------------------------------
# Pressurised line crack, paper Sec. 3.2 (Figs. 6-9)
CRACK_HALF_LENGTH = 0.2     # c [m] (crack length 0.4 m)


def line_crack(size, spacing, material, pressure, ramp, damping, crack_nodes="excluded", half_length=CRACK_HALF_LENGTH,
               grid_shift=None):
    """Square block [0, size]² [m] with a line crack of half-length c at its centre, made by removing
    the particles of two cell layers (ppc = 2); the crack faces carry the pressure P [Pa] as a particle
    traction, ramped linearly over `ramp` [s]. crack_nodes = "excluded" (default) takes the grid nodes
    between the faces out of the WLS fits (``add_region(gap_nodes="excluded")``, ``scene.thin_gap_nodes``):
    the faces are 2 cells apart and the cubic B-spline reaches 2 cells, so with "shared" (the paper's
    construction) both faces map to the mid-line node row and stay tied — the opening then moves away
    from Sneddon as the grid is refined (doc/reference/boundaries.md). grid_shift: (fx, fy) fractions of a cell by
    which the grid is moved against the block (``make_solver``'s `shift`): the particles and the crack stay where
    they are, the grid cuts them anew (slip planes on the block's faces take 0 or 0.5 along their axis).

    Returns (solver, geo): geo = dict(xc, yc, h, dp, x0 (initial positions by id), top, bot (particle
    ids of the loaded face rows), half_length)."""
    if crack_nodes not in ("shared", "excluded"):
        raise ValueError(f"crack_nodes = {crack_nodes!r} must be 'shared' or 'excluded'")
    if not (np.isfinite(half_length) and 0 < half_length < size / 2 - 2 * spacing):
        raise ValueError(f"half_length = {half_length} m must lie in (0, size/2 − 2·spacing) = (0, {size / 2 - 2 * spacing:g}) m")
    h = spacing
    s = make_solver((0, 0), (size, size), h, margin=2, shift=grid_shift)
    xc = yc = round(size / 2 / h) * h   # crack centre on a grid line so the hole is exactly two cell layers
    crack = Box((xc - half_length, yc - h), (xc + half_length, yc + h))
    add_region(s, material, (0, 0), (size, size), ppc=2, holes=[crack], gap_nodes=crack_nodes)
    x0 = get(s, "pos")                  # by particle id (== storage slot before the first step)
    dp = h / 2                          # particle spacing
    along = np.abs(x0[:, 0] - xc) < half_length
    top = np.nonzero(along & (np.abs(x0[:, 1] - (yc + h + dp / 2)) < dp / 4))[0]
    bot = np.nonzero(along & (np.abs(x0[:, 1] - (yc - h - dp / 2)) < dp / 4))[0]
    # pressure P on the faces: traction −P n, n the outward normal of the solid (−y on the upper face)
    apply_traction(s, top, (0.0, pressure), dp)
    apply_traction(s, bot, (0.0, -pressure), dp)
    s.damping = damping
    s.tractionRampTime = ramp
    return s, dict(xc=xc, yc=yc, h=h, dp=dp, x0=x0, top=top, bot=bot, half_length=half_length)



# ------------------------------------------------------------------------------------------------
# Boundary checks (doc/reference/boundaries.md)
def uniform_stress_block(dim, axis, side, kind="slip", cells=8, spacing=0.1, sigma=-40e6, damping=0.1, material=None):
    """Block [0, cells·l]^dim under a uniform normal stress σ [Pa] along `axis` (every particle starts at it),
    resting on a boundary plane of `kind` at its face `side` (−1 low, +1 high); the opposite face carries the
    consistent traction σ·n, the lateral faces are free: an exact equilibrium. material: default granite."""
    mat = material or rocks.granite()
    W = cells * spacing
    lo, hi = np.zeros(dim), np.full(dim, W)
    s = make_solver(lo, hi, spacing, margin=2)
    add_region(s, mat, lo, hi, ppc=2)
    st = np.zeros(4 if dim == 2 else 6)
    st[axis] = sigma
    if dim == 2:
        st[2] = mat.poisson * sigma                     # plane-strain σzz of the uniaxial state
    set_initial_stress(s, st)
    n = np.zeros(dim)
    n[axis] = -side                                     # outward normal of the loaded (opposite) face
    apply_face_traction(s, axis, -side, W if side < 0 else 0.0, sigma * n, 2)
    s.addBoundaryPlane(axis, side, 0.0 if side < 0 else W, kind)
    s.damping = damping
    return s


def fixed_free_bar(cells_x, length=1.0, cells_y=2, material=None, amplitude=0.01):
    """Bar [0, L] × [0, cells_y·l] fixed at x = 0 ('fixed' plane), free at x = L, between slip planes in y
    (1D strain), moving in its first mode v_x = a sin(πx/2L). Returns (solver, T = 4L/c_p [s], mode shape)."""
    h = length / cells_x
    s = make_solver((0.0, 0.0), (length, cells_y * h), h, margin=2)
    m = material or ElasticMat(young=1e9, poisson=0.25, density=1000.0)
    add_region(s, m, (0.0, 0.0), (length, cells_y * h), ppc=2)
    s.addBoundaryPlane(0, -1, 0.0, "fixed")
    s.addBoundaryPlane(1, -1, 0.0, "slip")
    s.addBoundaryPlane(1, 1, cells_y * h, "slip")
    shape = lambda x: np.sin(np.pi * x / (2 * length))
    s.view("v0")[:] = amplitude * shape(s.view("x0"))
    s.requestSort()
    return s, 4 * length / np.sqrt((m.bulk() + 4 * m.shear() / 3) / m.density), shape


def mode_period(solver, shape, t_end):
    """Mean period [s] of the modal momentum q = Σ m v_x shape(x) between its downward zero crossings
    (linearly interpolated), stepping `solver` to `t_end` [s]."""
    t, q = [], []
    while solver.time < t_end:
        solver.run(1)
        t.append(solver.time)
        q.append(np.sum(solver.view("mass") * solver.view("v0") * shape(solver.view("x0"))))
    t, q = np.array(t), np.array(q)
    k = np.nonzero((q[:-1] > 0) & (q[1:] <= 0))[0]
    if len(k) < 2:
        raise ValueError(f"t_end = {t_end} s holds fewer than two downward zero crossings of the mode")
    tz = t[k] + (t[k + 1] - t[k]) * q[k] / (q[k] - q[k + 1])
    return float(np.mean(np.diff(tz)))


def drifting_block(spacing=0.01, speed=35.0, rebalance=1.1):
    """A 0.1 × 0.24 m soft elastic block (E = 2 MPa, ν = 0.25, ρ = 2000 kg/m³: c_p ≈ 37 m/s) drifting up a
    0.64 m tall empty grid at `speed` [m/s] with a little shear (±1 m/s along y, ±0.5 m/s along x): the
    material leaves the MPI slabs it started in (the load-balance scene of doc/developer/scaling.md). `rebalance`
    is Solver.mpiRebalance (inf: never re-cut). Returns the solver."""
    s = make_solver((-0.03, 0.0), (0.13, 0.64), spacing, margin=2)
    add_region(s, ElasticMat(young=2e6, poisson=0.25, density=2000.0), (0.0, 0.0), (0.1, 0.24))
    s.sortPeriod = 10
    s.mpiRebalance = rebalance
    x0, x1 = np.array(s.view("x0")), np.array(s.view("x1"))
    s.view("v1")[:] = speed + np.sin(np.pi * x0 / 0.1)
    s.view("v0")[:] = 0.5 * np.cos(np.pi * x1 / 0.24)
    s.requestSort()
    return s
