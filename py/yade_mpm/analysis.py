"""Crack analytics on 2D particle results, for the questions a rock engineer asks of a failure run on
any scene: which rock has spalled off an opening (area, mass), where the shear bands are and how they
are inclined, how long the tensile cracks are and how they are oriented, how far the failed zone
grown from a point (a flaw toe) reaches, how symmetric the damage is.

    import yade_mpm as ym
    from yade_mpm import analysis
    lat = analysis.Lattice(ym.get(s, "pos"), dp=s.spacing / ppc)      # at the start (initial positions)
    ...                                                                # run
    r = analysis.crack_report(ym.fields(s), lat, opening=holes, soft_end=analysis.softening_end(s),
                              axis_x=0.075, point=flaw_toe)
    r["spalled"]["area"], r["bands"][0]["angle_deg"], r["cracks"][0]["length"], r["symmetry_damage"]

The pieces: ``spalled``, ``shear_bands`` / ``bands``, ``cracks``, ``zone_from`` / ``clusters_touching``,
``mirror_symmetry``, ``opening_surface``, ``opening_distance``, ``distance_to_segment``, ``failed``,
``softening_end``, ``region_test`` (an opening or a region of interest as shapes or a function),
``flaw_end_cracks`` (wing / anti-wing cracks and shear cracks grown from the ends of a flaw).

The particles of a scene built with ``add_region`` sit on a regular lattice of spacing dp = l/ppc
in the initial configuration; the functions here work on that lattice (neighbours never change),
with fields given per particle in id order (``ym.get`` / ``ym.fields``) and the initial positions
``x0`` (id order).
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
        self.x0 = x0
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
    rises to the right, elongation = ratio of the principal standard deviations, bbox = width, height
    of the axis-aligned bounding box [m], fill = sites / sites of that box: 1 a rectangle, π/4 an
    ellipse, 1/2 a right triangle with sides on the axes). Clusters of fewer
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
        box = (pts.max(axis=0) - pts.min(axis=0)) / lattice.dp + 1          # bounding box in sites
        out.append(dict(sites=int(len(pts)), centroid=c.tolist(), length=float(proj.max() - proj.min() + lattice.dp),
                        angle_deg=float(ang), elongation=float(np.sqrt(w[1] / max(w[0], 1e-30))),
                        bbox=(box * lattice.dp).tolist(), fill=float(len(pts) / np.prod(box))))
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
    """Per particle: True on the surface of the opening (a 4-neighbour lattice site inside it);
    in_opening: a shape, a list of shapes or a callable (``region_test``)."""
    return _opening_sites(lattice, region_test(in_opening, "opening"))[1][lattice.i, lattice.j]


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
    failed particles. in_opening: the opening as a shape, a list of shapes (e.g. the holes given to
    ``add_region``) or a callable in_opening(points (M, 2)) -> bool (``region_test``).
    Returns dict(mask (per particle, bool), failed_connected, fragments (particle counts),
    area [m², per metre of thickness in 2D], mass [kg] (sum of `mass` if given))."""
    failed = np.asarray(failed, bool)
    F = lattice.grid(failed, fill=False)
    M = lattice.slot >= 0
    hole, surface = _opening_sites(lattice, region_test(in_opening, "opening"))
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


# ------------------------------------------------------------------------------ regions and masks
def region_test(region, name="region"):
    """in_region(points (M, D)) -> bool from a geometry shape (``Circle``, ``Box``, ``Polygon``: anything
    with ``contains``), a list of shapes (their union) or a callable; ValueError otherwise."""
    if hasattr(region, "contains"):
        region = [region]
    if isinstance(region, (list, tuple)):
        if not region or not all(callable(getattr(g, "contains", None)) for g in region):
            raise ValueError(f"{name} must be a shape with contains(points) (Circle, Box, Polygon), a non-empty list "
                             f"of them, or a callable in_region(points) -> bool (got {region!r})")
        shapes = list(region)
        return lambda p: np.any([g.contains(np.asarray(p, float)) for g in shapes], axis=0)
    if callable(region):
        return region
    raise ValueError(f"{name} must be a shape (Circle, Box, Polygon), a list of shapes or a callable (got {type(region).__name__})")


def softening_end(solver, order=None):
    """Per particle (id order, or `order`): the accumulated plastic strain ε̄p at which the DP–GK
    cohesion reaches its floor, (1 − c_r)·ε̄p_crit (Eq. 34); inf for particles of other materials, NaN for
    removed ones (rows as ``fields.get``)."""
    from .fields import id_order, _with_removed_rows
    kinds = solver._materialKinds
    mats = [solver.material(i) for i in range(solver.numMaterials)]
    end = np.array([(1 - m.residualCohesion) * m.critPlasticStrain if k == 1 else np.inf for m, k in zip(mats, kinds)])
    o = id_order(solver) if order is None else order
    return _with_removed_rows(solver, "softening_end", end[solver.view("material")[o].astype(np.int64)], o)


def failed(damage, plastic_strain, soft_end):
    """Per particle: failed = fully damaged (D ≥ 1, a tensile crack) or softened (ε̄p ≥ soft_end, a
    shear crack: the cohesion at its floor, Eq. 34)."""
    return (np.asarray(damage) >= 1.0) | (np.asarray(plastic_strain) >= soft_end)


def distance_to_segment(points, a, b):
    """Distance [m] of points (N, 2) from the segment a–b (e.g. a flaw's toe and tip)."""
    p, a, b = np.asarray(points, float), np.asarray(a, float), np.asarray(b, float)
    u = b - a
    L = float(np.hypot(*u))
    if L == 0:
        return np.hypot(*(p - a).T)
    s = np.clip((p - a) @ (u / L), 0, L)
    return np.hypot(*(p - a - s[:, None] * (u / L)).T)


def opening_distance(lattice, opening):
    """Per particle: distance [m] of its lattice site from the nearest site inside the opening
    (in_opening as for ``spalled``), measured between site centres (Euclidean distance transform)."""
    from scipy import ndimage
    hole = _opening_sites(lattice, region_test(opening, "opening"))[0]
    if not hole.any():
        return np.full(len(lattice.i), np.inf)
    d = ndimage.distance_transform_edt(~hole) * lattice.dp
    return d[lattice.i, lattice.j]


# ------------------------------------------------------------------------------ cracks and bands
def shear_bands(plastic_strain, lattice, zone=None, fraction=0.5, floor=5e-4, min_sites=None):
    """Shear bands: the elongated clusters (``bands``) of the particles of `zone` (default all) whose
    plastic strain ε̄p ≥ threshold = max(floor, fraction × the 99th percentile of ε̄p in the zone), i.e.
    localised plastic strain. Returns (bands, threshold)."""
    e = np.asarray(plastic_strain, float)
    zone = np.ones(len(e), bool) if zone is None else np.asarray(zone, bool)
    ref = float(np.percentile(e[zone], 99)) if zone.any() else 0.0
    thr = max(floor, fraction * ref)
    return bands(zone & (e >= thr), lattice, min_sites), thr


def cracks(damage, lattice, level=1.0, min_sites=None):
    """Tensile cracks: the clusters of particles with D ≥ level (default fully damaged), each with its
    length [m], orientation (angle_deg to the horizontal) and centroid, as ``bands`` (largest first)."""
    return bands(np.asarray(damage) >= level, lattice, min_sites)


def zone_from(point, mask, lattice, x0, radius):
    """Per particle: the 8-connected clusters of `mask` that start within `radius` [m] of `point` [m]
    (e.g. the failed zone grown from a flaw toe); the seeds are the mask's particles in that circle."""
    seeds = np.asarray(mask, bool) & (np.hypot(*(np.asarray(x0, float) - np.asarray(point, float)).T) < radius)
    return clusters_touching(mask, lattice, seeds)


# ------------------------------------------------------------------------------ everything at once
def crack_report(fields, lattice, opening, soft_end, rock=None, axis_x=None, flaw=None, point=None, band_gap=5e-3,
                 band_fraction=0.5, band_floor=5e-4, point_radius=4e-3, opening_dist=None):
    """The crack analytics of one state of a 2D scene with an opening, in one call.

    fields: per-particle arrays in id order with keys damage, plastic_strain and (optional) mass, e.g.
    ``yade_mpm.fields(solver)``; lattice: ``Lattice`` of the initial positions; opening: the region the
    rock spalls into (shape, list of shapes, callable; None: none, nothing spalls); soft_end: ε̄p of a shear crack (scalar, or
    ``softening_end(solver)``); rock: the particles analysed (default all; e.g. not a grout infill);
    axis_x [m]: mirror axis of the symmetry (None: not computed); flaw: segment (a, b) [m] whose faces
    slide — no band is looked for within band_gap [m] of it, nor of the opening (opening_dist: per particle
    distance from the opening [m], default ``opening_distance``); point [m] (e.g. a flaw toe): the failed
    zone and the plastic band grown from within point_radius [m] of it.

    Returns dict: failed, softened (per particle), spalled (``spalled``), surface (the failed part of
    the spalled rock: where the opening wall broke), bands, band_threshold (``shear_bands`` of the rock with D < 1 beyond
    band_gap), cracks (``cracks``), symmetry_damage, symmetry_plastic, damaged_fraction,
    softened_fraction (of the rock); with point: point_damaged, point_softened (counts within
    point_radius), point_failed_reach, point_plastic_reach (per particle: the zone grown from the point
    on the opening surface), point_failed_gap (distance [m] from the opening of the failed zone grown from
    the point: 0 when it reaches it; None: no failed particle near the point) and point_failed_gap_at (the
    particle where that distance is smallest)."""
    D, e = np.asarray(fields["damage"], float), np.asarray(fields["plastic_strain"], float)
    n = len(lattice.i)
    if D.shape != (n,) or e.shape != (n,):
        raise ValueError(f"fields damage and plastic_strain must hold one value per lattice particle ({n})")
    rock = np.ones(n, bool) if rock is None else np.asarray(rock, bool)
    in_opening = (lambda p: np.zeros(len(p), bool)) if opening is None else region_test(opening, "opening")
    fail = rock & failed(D, e, soft_end)
    soft = rock & (e >= soft_end)
    sp = spalled(fail, lattice, in_opening, fields.get("mass"))
    dist = opening_distance(lattice, in_opening) if opening_dist is None else np.asarray(opening_dist, float)
    zone = rock & (D < 1) & (dist > band_gap)
    if flaw is not None:
        zone &= distance_to_segment(lattice.x0, *flaw) > band_gap
    bnd, thr = shear_bands(e, lattice, zone, band_fraction, band_floor)
    res = dict(failed=fail, softened=soft, spalled=sp, surface=sp["mask"] & fail, bands=bnd, band_threshold=thr,
               cracks=cracks(np.where(rock, D, 0), lattice),
               symmetry_damage=None if axis_x is None else mirror_symmetry(np.where(rock, D, 0), lattice, axis_x),
               symmetry_plastic=None if axis_x is None else mirror_symmetry(np.where(rock, e, 0), lattice, axis_x),
               damaged_fraction=float(np.mean(D[rock] >= 1)), softened_fraction=float(np.mean(soft[rock])))
    if point is not None:
        near = rock & (np.hypot(*(lattice.x0 - np.asarray(point, float)).T) < point_radius)
        surface = opening_surface(lattice, in_opening)
        plastic = rock & (e >= thr)
        zone_fail = clusters_touching(fail, lattice, near & fail)
        gap_at = int(np.argmin(np.where(zone_fail, dist, np.inf))) if zone_fail.any() else None
        res.update(point_damaged=int(np.count_nonzero(near & (D >= 1))), point_softened=int(np.count_nonzero(near & soft)),
                   point_failed_reach=zone_fail & surface, point_failed_gap=None if gap_at is None else float(dist[gap_at]),
                   point_failed_gap_at=gap_at,
                   point_plastic_reach=clusters_touching(plastic, lattice, near & plastic) & surface)
    return res


def flaw_end_cracks(damage, plastic_strain, soft_end, lattice, toe, tip, radius):
    """Cracks grown from the two ends of a flaw (segment toe–tip [m], e.g. a flaw under vertical
    compression), measured on the initial positions: per end ("toe", "tip") a dict with
      damaged:   a particle with D ≥ 1 within `radius` [m] of the end (the crack has started there);
      wing:      length [m] of the tensile crack (D ≥ 1 cluster seeded within `radius` of the end) on the
                 side away from the flaw vertically (above the upper end, below the lower end): the
                 largest distance of its particles from the flaw segment — the wing crack of Fig. 12;
      anti_wing: the same on the other side (below the upper end, above the lower end);
      shear:     the same for the softened cluster (ε̄p ≥ soft_end), either side;
      boundary:  the D ≥ 1 or softened cluster of this end touches the lattice's outer row (the crack
                 has run through to a face of the specimen).
    Returns dict(toe=..., tip=..., wing, anti_wing, shear: the larger of the two ends [m])."""
    D, e = np.asarray(damage, float), np.asarray(plastic_strain, float)
    x0 = lattice.x0
    a, b = np.asarray(toe, float), np.asarray(tip, float)
    dist = distance_to_segment(x0, a, b)
    outer = (lattice.i == 0) | (lattice.j == 0) | (lattice.i == lattice.shape[0] - 1) | (lattice.j == lattice.shape[1] - 1)
    cracked, soft = D >= 1.0, e >= soft_end
    res = {}
    for name, end, other in (("toe", a, b), ("tip", b, a)):
        near = np.hypot(*(x0 - end).T) < radius
        up = 1.0 if end[1] >= other[1] else -1.0                 # the wing side: away from the flaw vertically
        tens = clusters_touching(cracked, lattice, near & cracked)
        shear = clusters_touching(soft, lattice, near & soft)
        side = (x0[:, 1] - end[1]) * up
        ext = lambda m: float(dist[m].max()) if m.any() else 0.0
        res[name] = dict(damaged=bool((near & cracked).any()), wing=ext(tens & (side > 0)), anti_wing=ext(tens & (side < 0)),
                         shear=ext(shear), boundary=bool(((tens | shear) & outer).any()))
    for k in ("wing", "anti_wing", "shear"):
        res[k] = max(res["toe"][k], res["tip"][k])
    return res
