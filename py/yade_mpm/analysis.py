"""Crack analytics on 2D particle results, for the questions a rock engineer asks of a failure run:
how symmetric is the damage, where are the shear bands and how are they inclined, which rock has
spalled off an opening (area and mass).

The particles of a scene built with ``add_region`` sit on a regular lattice of spacing dp = l/ppc
in the initial configuration; the functions here work on that lattice (neighbours never change),
with fields given per particle in id order and the initial positions ``x0`` (id order).
"""
import numpy as np


class Lattice:
    """Lattice indices of particles from their initial positions x0 (N, 2) [m], spacing dp [m] and the
    lattice's lower-left corner `origin` [m] (default: half a spacing below the lowest particles; give
    the region's corner when an opening touches the region's edge)."""

    def __init__(self, x0, dp, origin=None):
        x0 = np.asarray(x0, float)
        if x0.ndim != 2 or x0.shape[1] != 2:
            raise ValueError("x0 must be an (N, 2) array of initial particle positions [m] (2D)")
        if not dp > 0:
            raise ValueError(f"dp = {dp} m must be > 0")
        self.dp = float(dp)
        self.lo = x0.min(axis=0) - 0.5 * dp if origin is None else np.asarray(origin, float)   # lower-left corner [m]
        ij = np.rint((x0 - self.lo) / dp - 0.5).astype(np.int64)
        if ij.min() < 0:
            raise ValueError(f"origin = {tuple(self.lo)} m is not below and left of every particle")
        self.i, self.j = ij[:, 0], ij[:, 1]
        self.shape = (int(self.i.max()) + 1, int(self.j.max()) + 1)
        self.slot = -np.ones(self.shape, np.int64)           # particle index at each site, −1 = empty
        self.slot[self.i, self.j] = np.arange(len(x0))
        if np.count_nonzero(self.slot >= 0) != len(x0):
            raise ValueError("x0 is not a lattice of spacing dp (two particles share a site)")

    def grid(self, values, fill=0.0):
        """Per-particle values on the lattice (empty sites = fill)."""
        g = np.full(self.shape, fill, dtype=np.asarray(values).dtype)
        g[self.i, self.j] = values
        return g

    def site_centres(self):
        """Centres of all lattice sites, (nx, ny, 2) [m]."""
        xs = self.lo[0] + (np.arange(self.shape[0]) + 0.5) * self.dp
        ys = self.lo[1] + (np.arange(self.shape[1]) + 0.5) * self.dp
        return np.stack(np.meshgrid(xs, ys, indexing="ij"), axis=-1)


def _label(mask, connectivity=8):
    from scipy import ndimage
    st = np.ones((3, 3), int) if connectivity == 8 else None
    return ndimage.label(mask, structure=st)


def mirror_symmetry(values, lattice, axis_x):
    """Left–right mirror symmetry of a particle field about the vertical line x = axis_x [m]: the
    Pearson correlation of the field (on the lattice, empty sites 0) with its mirror image, over the
    sites on both sides. 1 = mirror symmetric, 0 = unrelated; None if the field is constant (e.g. no
    damage yet)."""
    g = lattice.grid(np.asarray(values, float))
    # mirror index: site centre x ↦ 2 axis_x − x
    xs = lattice.lo[0] + (np.arange(lattice.shape[0]) + 0.5) * lattice.dp
    mi = np.rint((2 * axis_x - xs - lattice.lo[0]) / lattice.dp - 0.5).astype(np.int64)
    ok = (mi >= 0) & (mi < lattice.shape[0])
    a, b = g[ok], g[mi[ok]]
    a, b = a.ravel(), b.ravel()
    if np.std(a) == 0 or np.std(b) == 0:
        return None
    return float(np.corrcoef(a, b)[0, 1])


def bands(mask, lattice, min_sites=None):
    """Elongated clusters (8-connected lattice sites where mask is true, e.g. plastic strain past the
    softening end): a list, largest first, of dict(sites, centroid [m], length [m], angle_deg =
    inclination of the cluster's principal axis to the horizontal in (−90, 90], positive when it
    rises to the right, elongation = ratio of the principal standard deviations). Clusters of fewer
    than min_sites sites (default: max(12, 3 % of the sites in the mask)) are skipped."""
    g = lattice.grid(np.asarray(mask, bool), fill=False)
    lab, n = _label(g, 8)
    if n == 0:
        return []
    if min_sites is None:
        min_sites = max(12, int(0.03 * np.count_nonzero(g)))
    centres = lattice.site_centres()
    out = []
    for k in range(1, n + 1):
        pts = centres[lab == k]
        if len(pts) < min_sites:
            continue
        c = pts.mean(axis=0)
        w, v = np.linalg.eigh(np.cov((pts - c).T))
        major = v[:, 1]
        ang = np.degrees(np.arctan2(major[1], major[0]))
        ang = ang - 180 if ang > 90 else (ang + 180 if ang <= -90 else ang)
        proj = (pts - c) @ major
        out.append(dict(sites=int(len(pts)), centroid=c.tolist(), length=float(proj.max() - proj.min() + lattice.dp),
                        angle_deg=float(ang), elongation=float(np.sqrt(w[1] / max(w[0], 1e-30)))))
    return sorted(out, key=lambda b: -b["sites"])


def _opening_sites(lattice, in_opening):
    """(hole, surface): lattice sites inside the opening, particle sites with a 4-neighbour in it."""
    M = lattice.slot >= 0
    hole = np.zeros(lattice.shape, bool)
    if (~M).any():
        hole[~M] = in_opening(lattice.site_centres()[~M])
    near = np.zeros_like(hole)
    near[1:, :] |= hole[:-1, :]
    near[:-1, :] |= hole[1:, :]
    near[:, 1:] |= hole[:, :-1]
    near[:, :-1] |= hole[:, 1:]
    return hole, near & M


def opening_surface(lattice, in_opening):
    """Per particle: True on the surface of the opening (a 4-neighbour lattice site inside it)."""
    return _opening_sites(lattice, in_opening)[1][lattice.i, lattice.j]


def clusters_touching(mask, lattice, seeds):
    """Per particle: in an 8-connected cluster of `mask` that contains a particle of `seeds` (both per
    particle, bool) — e.g. the failed zone grown from a flaw tip."""
    g = lattice.grid(np.asarray(mask, bool), fill=False)
    lab, _ = _label(g, 8)
    per = lab[lattice.i, lattice.j]
    hit = np.unique(per[np.asarray(seeds, bool) & (per > 0)])
    return np.isin(per, hit) & (per > 0)


def spalled(failed, lattice, in_opening, mass=None):
    """Rock spalled off an opening: the failed particles (fully damaged or softened) connected through
    failed particles (8-neighbours) to the opening surface, plus the intact fragments cut off from the
    main rock body (4-connected components other than the largest) that touch the opening or those
    failed particles. in_opening(points (M, 2)) -> bool marks lattice sites inside the opening.
    Returns dict(mask (per particle, bool), failed_connected, fragments (particle counts),
    area [m², per metre of thickness in 2D], mass [kg] (sum of `mass` if given))."""
    failed = np.asarray(failed, bool)
    F = lattice.grid(failed, fill=False)
    M = lattice.slot >= 0
    hole, surface = _opening_sites(lattice, in_opening)
    lab, n = _label(F, 8)
    touching = np.unique(lab[surface & F])
    touching = touching[touching > 0]
    S_f = np.isin(lab, touching)
    intact = M & ~F
    lab2, n2 = _label(intact, 4)
    S_d = np.zeros_like(F)
    if n2 > 1:
        sizes = np.bincount(lab2.ravel())[1:]
        main = 1 + int(np.argmax(sizes))
        grow = S_f | hole
        from scipy import ndimage
        adj = ndimage.binary_dilation(grow, structure=np.ones((3, 3), bool))   # 8-adjacent to the opening or S_f
        frag = np.unique(lab2[adj & intact])
        frag = frag[(frag > 0) & (frag != main)]
        S_d = np.isin(lab2, frag)
    S = (S_f | S_d)[lattice.i, lattice.j]
    res = dict(mask=S, failed_connected=int(np.count_nonzero(S_f)), fragments=int(np.count_nonzero(S_d)),
               area=float(np.count_nonzero(S) * lattice.dp ** 2))
    res["mass"] = float(np.sum(np.asarray(mass)[S])) if mass is not None else None
    return res
