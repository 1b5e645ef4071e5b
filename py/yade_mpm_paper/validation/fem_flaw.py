"""An independent reference for the elastic uniaxial specimen with a flaw (paper Sec. 3.3 geometry): a plane-strain
linear finite-element solution (3-node triangles on a Delaunay mesh, SciPy sparse solve), written for this check.

The specimen [0, W] × [0, H] stands on a slip base (u_y = 0 at y = 0, u_x = 0 at the origin) and is pressed by a
frictionless rigid platen (u_y = −δ on y = H, u_x free). The flaw (a rectangle, ``uniaxial_flaw_geometry``) is
    "open"    a traction-free hole,
    "bonded"  a rigid inclusion tied to the rock (its boundary nodes move as one rigid body u = a + θ ẑ × (x − c),
              a and θ free: no net force or moment on it),
    "intact"  absent (the check of the solver: the modulus is E/(1 − ν²) to round-off).
The apparent modulus is (platen force / W) / (δ / H). A rigid filler in frictional contact lies between "open"
and "bonded"."""
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.linalg import spsolve
from scipy.spatial import Delaunay

from yade_mpm.geometry import Polygon


def mesh(width, height, h, hole=None):
    """Nodes (n, 2) and triangles (m, 3) over the specimen with `hole` (a Polygon, convex) cut out: a square
    lattice of spacing h, lattice points closer than h/2 to the hole removed, the hole's outline sampled at h/2."""
    nx, ny = int(round(width / h)), int(round(height / h))
    gx, gy = np.meshgrid(np.linspace(0, width, nx + 1), np.linspace(0, height, ny + 1), indexing="ij")
    pts = np.column_stack([gx.ravel(), gy.ravel()])
    if hole is not None:
        verts = np.asarray(hole.v, float)
        grown = Polygon(_offset(verts, 0.5 * h))
        pts = pts[~grown.contains(pts)]
        ring = []
        for a, b in zip(verts, np.roll(verts, -1, axis=0)):
            n = max(2, int(np.ceil(np.linalg.norm(b - a) / (0.5 * h))))
            ring.extend(a + (b - a) * t for t in np.arange(n) / n)
        pts = np.vstack([pts, np.array(ring)])
    tri = Delaunay(pts).simplices
    if hole is not None:
        cen = pts[tri].mean(axis=1)
        tri = tri[~hole.contains(cen)]
    a = pts[tri]
    area2 = (a[:, 1, 0] - a[:, 0, 0]) * (a[:, 2, 1] - a[:, 0, 1]) - (a[:, 2, 0] - a[:, 0, 0]) * (a[:, 1, 1] - a[:, 0, 1])
    tri[area2 < 0] = tri[area2 < 0][:, [0, 2, 1]]
    return pts, tri


def _offset(verts, d):
    """A convex polygon grown by d (each vertex moved along its corner's bisector)."""
    c = verts.mean(axis=0)
    out = []
    for i, v in enumerate(verts):
        e1, e2 = v - verts[i - 1], verts[(i + 1) % len(verts)] - v
        n1 = np.array([e1[1], -e1[0]]) / np.linalg.norm(e1)
        n2 = np.array([e2[1], -e2[0]]) / np.linalg.norm(e2)
        if np.dot(n1, v - c) < 0:
            n1, n2 = -n1, -n2
        m = n1 + n2
        out.append(v + d * m / max(np.dot(m, n1), 1e-12))
    return np.array(out)


def stiffness(pts, tri, young, poisson):
    """Plane-strain stiffness matrix (CSR) of P1 triangles."""
    lam, mu = young * poisson / ((1 + poisson) * (1 - 2 * poisson)), young / (2 * (1 + poisson))
    C = np.array([[lam + 2 * mu, lam, 0], [lam, lam + 2 * mu, 0], [0, 0, mu]])
    x, y = pts[tri, 0], pts[tri, 1]
    b = np.stack([y[:, 1] - y[:, 2], y[:, 2] - y[:, 0], y[:, 0] - y[:, 1]], axis=1)
    c = np.stack([x[:, 2] - x[:, 1], x[:, 0] - x[:, 2], x[:, 1] - x[:, 0]], axis=1)
    area = 0.5 * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])
    B = np.zeros((len(tri), 3, 6))
    B[:, 0, 0::2], B[:, 1, 1::2], B[:, 2, 0::2], B[:, 2, 1::2] = b, c, c, b
    B /= (2 * area)[:, None, None]
    Ke = np.einsum("eik,ij,ejl->ekl", B, C, B) * area[:, None, None]
    dof = np.stack([2 * tri, 2 * tri + 1], axis=2).reshape(len(tri), 6)
    rows, cols = np.repeat(dof, 6, axis=1).ravel(), np.tile(dof, (1, 6)).ravel()
    n = 2 * len(pts)
    return coo_matrix((Ke.ravel(), (rows, cols)), shape=(n, n)).tocsr()


def apparent_modulus(kind, width, height, hole, young, poisson, h, strain=1e-4):
    """(platen force / width) / strain of the specimen pressed to `strain` [-], plane strain, per unit thickness [Pa]."""
    if kind not in ("open", "bonded", "intact"):
        raise ValueError(f"kind = {kind!r} must be 'open', 'bonded' or 'intact'")
    pts, tri = mesh(width, height, h, None if kind == "intact" else hole)
    K = stiffness(pts, tri, young, poisson)
    n = len(pts)
    tol = 1e-9 * height
    bottom, top = np.nonzero(pts[:, 1] < tol)[0], np.nonzero(pts[:, 1] > height - tol)[0]
    corner = bottom[np.argmin(pts[bottom, 0])]
    u = np.zeros(2 * n)
    fixed = np.zeros(2 * n, bool)
    fixed[2 * bottom + 1] = True
    fixed[2 * corner] = True
    fixed[2 * top + 1] = True
    u[2 * top + 1] = -strain * height
    # reduced unknowns: the free dofs, the bonded hole's nodes through a, θ (P: reduced → full)
    ring = np.array([], int)
    if kind == "bonded":
        on = np.zeros(n, bool)
        on[np.unique(tri)] = True
        ring = np.nonzero(on & Polygon(_offset(np.asarray(hole.v, float), 1e-9 * h)).contains(pts))[0]
    free = ~fixed
    free[2 * ring], free[2 * ring + 1] = False, False
    idx = np.nonzero(free)[0]
    m = len(idx)
    rows, cols, vals = list(idx), list(range(m)), [1.0] * m
    if len(ring):
        cen = np.asarray(hole.v, float).mean(axis=0)
        r = pts[ring] - cen
        for k, node in enumerate(ring):               # u = a + θ ẑ × r: (a_x − θ r_y, a_y + θ r_x)
            rows += [2 * node, 2 * node, 2 * node + 1, 2 * node + 1]
            cols += [m, m + 2, m + 1, m + 2]
            vals += [1.0, -r[k, 1], 1.0, r[k, 0]]
    P = coo_matrix((vals, (rows, cols)), shape=(2 * n, m + (3 if len(ring) else 0))).tocsr()
    f = -(K @ u)
    q = spsolve((P.T @ K @ P).tocsc(), P.T @ f)
    u = u + P @ q
    force = (K @ u)[2 * top + 1].sum()                 # the platen's push on the rock (negative: down)
    return -force / width / strain, dict(nodes=n, triangles=len(tri), bonded_nodes=len(ring))
