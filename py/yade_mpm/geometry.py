"""Particles from geometry: a rectangle (2D) or box (3D) filled with ``ppc`` particles per cell per
axis, with holes (circles/spheres, polygons, boxes) cut out. Particles sit at the centres of the
sub-cells of the background grid, so a grid aligned with the region gives a regular lattice."""
import numpy as np


class Circle:
    """Disc (2D) or sphere (3D) of given centre [m] and radius [m]."""
    def __init__(self, center, radius):
        self.center, self.radius = np.asarray(center, float), float(radius)
        if not self.radius > 0:
            raise ValueError(f"Circle radius = {radius} m must be > 0")

    def contains(self, x):
        return np.sum((x - self.center) ** 2, axis=1) < self.radius ** 2


class Box:
    """Axis-aligned box [lo, hi] [m]."""
    def __init__(self, lo, hi):
        self.lo, self.hi = np.asarray(lo, float), np.asarray(hi, float)
        if np.any(self.hi <= self.lo):
            raise ValueError(f"Box hi {hi} must exceed lo {lo} on every axis")

    def contains(self, x):
        return np.all((x >= self.lo) & (x <= self.hi), axis=1)


class Polygon:
    """Closed 2D polygon given by its vertices [m] (any orientation); in 3D it is a prism along z."""
    def __init__(self, vertices):
        self.v = np.asarray(vertices, float)
        if self.v.ndim != 2 or self.v.shape[1] != 2 or len(self.v) < 3:
            raise ValueError("Polygon vertices must be an (n ≥ 3, 2) array")

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


def rotated_rectangle(center, length, width, angle):
    """Polygon of a rectangle (a flaw) of given length/width [m] rotated by angle [rad] from x."""
    c, s = np.cos(angle), np.sin(angle)
    hl, hw = length / 2, width / 2
    pts = np.array([[-hl, -hw], [hl, -hw], [hl, hw], [-hl, hw]])
    return Polygon(pts @ np.array([[c, s], [-s, c]]) + np.asarray(center, float))


def fill_region(lo, hi, spacing, ppc=2, holes=(), keep=None):
    """Particle centres and volume for the box [lo, hi] on a grid of spacing l with ppc particles per
    cell per axis, minus the holes. Returns (positions (N, D), volume per particle [m³])."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    if lo.shape != hi.shape or lo.ndim != 1 or len(lo) not in (2, 3):
        raise ValueError("lo and hi must both have 2 or 3 components")
    if not spacing > 0:
        raise ValueError(f"spacing = {spacing} m must be > 0")
    if int(ppc) != ppc or ppc < 1:
        raise ValueError(f"ppc (particles per cell per axis) = {ppc} must be an integer ≥ 1")
    if np.any(hi <= lo):
        raise ValueError("hi must exceed lo on every axis")
    d = spacing / ppc
    axes = [np.arange(a + d / 2, b - d / 4, d) for a, b in zip(lo, hi)]
    grids = np.meshgrid(*axes, indexing="ij")
    x = np.column_stack([g.ravel() for g in grids])
    mask = np.ones(len(x), bool)
    for h in holes:
        mask &= ~h.contains(x)
    if keep is not None:
        mask &= keep(x)
    x = x[mask]
    if len(x) == 0:
        raise ValueError("the region holds no particles (holes cover it or it is smaller than a sub-cell)")
    return x, d ** len(lo)
