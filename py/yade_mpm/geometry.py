"""Particles from geometry: a rectangle (2D) or box (3D) filled with ``ppc`` particles per cell per
axis, with holes (circles/spheres, polygons, boxes) cut out. Particles sit at the centres of the
sub-cells of the background grid, so a grid aligned with the region gives a regular lattice."""
import numpy as np


def _number(v, name, unit, positive=False):
    """A finite float (> 0 if positive) or ValueError naming the parameter, unit and range. NumPy scalars
    are numbers; a float32 is read as the decimal it prints as (np.float32(0.002) → 0.002, not
    0.0020000000949949: a grid spacing must divide the specimen exactly)."""
    try:
        if isinstance(v, (bool, np.bool_, str, bytes)):
            raise TypeError
        f = float(str(v)) if isinstance(v, np.floating) and v.dtype.itemsize < 8 else float(v)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number [{unit}] (got {type(v).__name__} {v!r})") from None
    if not np.isfinite(f) or (positive and not f > 0):
        raise ValueError(f"{name} = {v} {unit} is outside the allowed range {'(0, inf)' if positive else '(-inf, inf)'}")
    return f


def _point(v, name, dims=(2, 3), hole=True):
    """A finite point with 2 or 3 components [m], or ValueError naming the parameter."""
    try:
        p = np.asarray(v, float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be {' or '.join(map(str, dims))} numbers [m] (got {type(v).__name__} {v!r})") from None
    if p.ndim != 1 or len(p) not in dims:
        raise ValueError(f"{name} must have {' or '.join(map(str, dims))} components [m] (got shape {p.shape})")
    if not np.all(np.isfinite(p)):
        raise ValueError(f"{name} = {tuple(p.tolist())} m must be finite" + (" (a NaN or inf coordinate removes nothing)" if hole else ""))
    return p


def _integer(v, name, lo, hi=None):
    """An integer in [lo, hi] (bools and floats refused), or ValueError naming the parameter and range."""
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo or (hi is not None and v > hi):
        raise ValueError(f"{name} = {v!r} must be an integer in [{lo}, {'inf' if hi is None else hi}]")
    return int(v)


def _corners(lo, hi, who):
    """Finite corners lo < hi of a box with 2 or 3 components, or ValueError naming them."""
    lo, hi = _point(lo, f"{who} lo", hole=who in ("Box",)), _point(hi, f"{who} hi", hole=who in ("Box",))
    if lo.shape != hi.shape:
        raise ValueError(f"{who} lo and hi must both have 2 (plane strain) or 3 components")
    if np.any(hi <= lo):
        raise ValueError(f"{who} hi {tuple(hi)} must exceed lo {tuple(lo)} on every axis")
    return lo, hi


class Circle:
    """Disc (2D) or sphere (3D) of given centre [m] and radius [m]."""
    def __init__(self, center, radius):
        self.center = _point(center, "Circle center")
        self.radius = _number(radius, "Circle radius", "m", positive=True)
        self.dims = (len(self.center),)

    def contains(self, x):
        return np.sum((x - self.center) ** 2, axis=1) < self.radius ** 2

    def width(self):
        """Narrowest extent [m] (thin holes: yade_mpm.scene.thin_gap_nodes)."""
        return 2 * self.radius


class Box:
    """Axis-aligned box [lo, hi] [m]."""
    def __init__(self, lo, hi):
        self.lo, self.hi = _corners(lo, hi, "Box")
        self.dims = (len(self.lo),)

    def contains(self, x):
        return np.all((x >= self.lo) & (x <= self.hi), axis=1)

    def width(self):
        """Narrowest extent [m]."""
        return float(np.min(self.hi - self.lo))


class Polygon:
    """Closed 2D polygon given by its vertices [m] (any orientation); in 3D it is a prism along z."""
    dims = (2, 3)

    def __init__(self, vertices):
        try:
            self.v = np.asarray(vertices, float)
        except (TypeError, ValueError):
            raise ValueError(f"Polygon vertices must be an (n ≥ 3, 2) array of numbers [m] (got {type(vertices).__name__})") from None
        if self.v.ndim != 2 or self.v.shape[1] != 2 or len(self.v) < 3:
            raise ValueError(f"Polygon vertices must be an (n ≥ 3, 2) array [m] (got shape {self.v.shape})")
        if not np.all(np.isfinite(self.v)):
            raise ValueError("Polygon vertices must be finite (a NaN or inf vertex removes nothing)")
        x, y = self.v[:, 0], self.v[:, 1]
        if not abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) > 0:
            raise ValueError("Polygon vertices enclose zero area (all on one line)")

    def contains(self, x):
        px, py = x[:, 0], x[:, 1]
        inside = np.zeros(len(x), bool)
        v = self.v
        for i in range(len(v)):
            (x1, y1), (x2, y2) = v[i], v[(i + 1) % len(v)]
            crosses = (y1 > py) != (y2 > py)
            with np.errstate(divide="ignore", invalid="ignore"):
                xint = x1 + (py - y1) * (x2 - x1) / (y2 - y1)
            inside ^= crosses & (px < xint)
        return inside

    def width(self):
        """Narrowest extent [m] of the convex hull (the smallest extent across an edge direction)."""
        v = self.v
        e = np.roll(v, -1, axis=0) - v
        n = np.column_stack([-e[:, 1], e[:, 0]]) / np.linalg.norm(e, axis=1)[:, None]
        proj = v @ n.T
        return float(np.min(proj.max(axis=0) - proj.min(axis=0)))


class Disc:
    """3D thin disc (a penny-shaped flaw): the points within `radius` [m] of the axis through `center` [m]
    along the unit `normal` and within `thickness`/2 [m] of the mid-plane."""
    dims = (3,)

    def __init__(self, center, normal, radius, thickness):
        self.center = _point(center, "Disc center", dims=(3,))
        n = _point(normal, "Disc normal", dims=(3,))
        if not np.linalg.norm(n) > 0:
            raise ValueError(f"Disc normal = {tuple(n)} must be a non-zero vector")
        self.normal = n / np.linalg.norm(n)
        self.radius = _number(radius, "Disc radius", "m", positive=True)
        self.thickness = _number(thickness, "Disc thickness", "m", positive=True)

    def contains(self, x):
        r = np.asarray(x, float) - self.center
        h = r @ self.normal
        return (np.abs(h) <= self.thickness / 2) & (np.sum(r * r, axis=1) - h * h < self.radius ** 2)

    def width(self):
        """Narrowest extent [m]: the thickness."""
        return self.thickness


def rotated_rectangle(center, length, width, angle):
    """Polygon of a rectangle (a flaw) of given length/width [m] rotated by angle [rad] from x."""
    center = _point(center, "rotated_rectangle center", dims=(2,))
    length = _number(length, "rotated_rectangle length", "m", positive=True)
    width = _number(width, "rotated_rectangle width", "m", positive=True)
    angle = _number(angle, "rotated_rectangle angle", "rad")
    c, s = np.cos(angle), np.sin(angle)
    hl, hw = length / 2, width / 2
    pts = np.array([[-hl, -hw], [hl, -hw], [hl, hw], [-hl, hw]])
    return Polygon(pts @ np.array([[c, s], [-s, c]]) + center)


def fill_region(lo, hi, spacing, ppc=2, holes=(), keep=None):
    """Particle centres and volume for the box [lo, hi] on a grid of spacing l with ppc particles per
    cell per axis, minus the holes. Returns (positions (N, D), volume per particle [m³])."""
    axes, holes, v = _lattice_axes(lo, hi, spacing, ppc, holes, keep)
    x = _lattice(axes, holes, keep)
    if len(x) == 0:
        raise ValueError("the region holds no particles (holes cover it or it is smaller than a sub-cell)")
    return x, v


def fill_region_chunks(lo, hi, spacing, ppc=2, holes=(), keep=None, chunk=1 << 20):
    """fill_region in pieces of about `chunk` lattice points (whole slices along x), yielding (positions,
    volume) in fill_region's order, the same values; pieces without particles are left out."""
    axes, holes, v = _lattice_axes(lo, hi, spacing, ppc, holes, keep)
    step = max(1, int(chunk) // max(1, int(np.prod([len(a) for a in axes[1:]]))))
    for i0 in range(0, len(axes[0]), step):
        x = _lattice([axes[0][i0:i0 + step]] + axes[1:], holes, keep)
        if len(x):
            yield x, v


def _lattice_axes(lo, hi, spacing, ppc, holes, keep):
    """The checked inputs of fill_region as (lattice coordinates per axis, holes as a list, volume per particle [m³])."""
    lo, hi = _corners(lo, hi, "region")
    spacing = _number(spacing, "spacing", "m", positive=True)
    ppc = _integer(ppc, "ppc (particles per cell per axis)", 1)
    holes = _holes(holes, len(lo))
    if keep is not None and not callable(keep):
        raise ValueError(f"keep must be a function of the (N, {len(lo)}) positions returning N booleans (got {type(keep).__name__})")
    d = spacing / ppc
    return [np.arange(a + d / 2, b - d / 4, d) for a, b in zip(lo, hi)], holes, d ** len(lo)


def _lattice(axes, holes, keep):
    """The lattice points of the axes (the last axis fastest) outside the holes and kept by `keep`."""
    grids = np.meshgrid(*axes, indexing="ij")
    x = np.column_stack([g.ravel() for g in grids])
    del grids
    mask = np.ones(len(x), bool)
    for h in holes:
        mask &= ~h.contains(x)
    if keep is not None:
        k = np.asarray(keep(x))
        if k.shape != (len(x),):
            raise ValueError(f"keep returned shape {k.shape}; expected ({len(x)},): one boolean per position")
        mask &= k.astype(bool)
    return x[mask]


def _holes(holes, dim):
    """The holes as a list of shapes whose dimension matches the region (2D circle in 3D: refused)."""
    if hasattr(holes, "contains"):
        holes = [holes]
    try:
        holes = list(holes)
    except TypeError:
        raise ValueError(f"holes must be a list of Circle/Box/Polygon shapes (got {type(holes).__name__})") from None
    for k, h in enumerate(holes):
        if not hasattr(h, "contains"):
            raise ValueError(f"holes[{k}] must be a Circle, Box or Polygon (got {type(h).__name__})")
        dims = getattr(h, "dims", (dim,))
        if dim not in dims:
            raise ValueError(f"holes[{k}] is a {'/'.join(f'{d}D' for d in dims)} {type(h).__name__} but the region is {dim}D")
    return holes
