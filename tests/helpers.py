"""Small scene builders shared by the foundation tests, and where the shipped scripts are."""
import glob
import os

import numpy as np
import yade_mpm as ym



def bar_2d(cells_x=64, cells_y=4, length=1.0, mat=None, ppc=2):
    """A bar [0, length] × [0, cells_y·l] filling the grid between fixed ends (x) and slip faces (y):
    one-dimensional strain, so waves travel at √((K + 4G/3)/ρ)."""
    h = length / cells_x
    s = ym.Solver2D((-2 * h, 0.0), h, (cells_x + 4, cells_y))
    m = mat or ym.ElasticMat(young=1e9, poisson=0.25, density=1000.0)
    ym.add_region(s, m, (0.0, 0.0), (length, cells_y * h), ppc=ppc)
    s.addBoundaryPlane(0, -1, 0.0, "fixed")
    s.addBoundaryPlane(0, 1, length, "fixed")
    s.addBoundaryPlane(1, -1, 0.0, "slip")
    s.addBoundaryPlane(1, 1, cells_y * h, "slip")
    return s, m


def set_velocity(s, fn):
    """Velocity field fn(pos (N, D)) -> (N, D) written into the live views."""
    d = 2 if isinstance(s, ym.Solver2D) else 3
    pos = np.column_stack([s.view(f"x{a}") for a in range(d)])
    v = fn(pos)
    for a in range(d):
        s.view(f"v{a}")[:] = v[:, a]
    s.requestSort()


def total_momentum(s, d=2):
    m = s.view("mass")
    return np.array([np.sum(m * s.view(f"v{a}")) for a in range(d)])


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def script_path(name):
    """A shipped script by file name, wherever its purpose folder keeps it (scripts/paper, scripts/studies,
    scripts/tools, scripts/, examples/)."""
    found = sorted(glob.glob(os.path.join(ROOT, "scripts", "**", name), recursive=True) + glob.glob(os.path.join(ROOT, "examples", name)))
    assert len(found) == 1, f"script {name!r}: {found}"
    return found[0]



class CentredEnergy:
    """The energy the explicit step conserves: ½ Σ m v^n·v^(n+1) + U(x^n). Velocities stand half a step from the
    positions (x^(n+1) = x^n + Δt v^(n+1)), and for a linear elastic body this sum is the update's invariant; the
    plain ½ m v² + U at one instant swings by O(C) of the energy in the fastest modes (±1 % and more through an impact
    at C = 1). `potential(s)` gives U (elastic + gravity) [J]; call step() after every step; `values` per step, the
    first one at the start (index 0: ½ Σ m v^0·v^1 + U(x^0))."""

    def __init__(self, s, potential):
        from yade_mpm.fields import get, id_order
        self._get, self._order, self.s, self.potential, self.values = get, id_order, s, potential, []
        self.v, self.u = self._state()

    def _state(self):
        o = self._order(self.s)
        self.m = self._get(self.s, "mass", o)
        return self._get(self.s, "momentum", o) / self.m[:, None], self.potential(self.s)

    def step(self):
        v, u = self._state()
        self.values.append(0.5 * np.sum(self.m[:, None] * self.v * v) + self.u)
        self.v, self.u = v, u
        return self.values[-1]

    def max_gain(self):
        """Largest rise above the first value, relative to it."""
        return max(self.values) / self.values[0] - 1
