"""Crack analytics (yade_mpm.analysis) on fields with known answers: a mirror-symmetric field and an
unrelated one, straight bands of known inclination, a block cut off an opening by a failed ring."""
import math

import numpy as np
import pytest

from yade_mpm import analysis

DP = 1e-3


def lattice(nx=60, ny=40, keep=None):
    x = (np.arange(nx) + 0.5) * DP
    y = (np.arange(ny) + 0.5) * DP
    X = np.stack(np.meshgrid(x, y, indexing="ij"), -1).reshape(-1, 2)
    if keep is not None:
        X = X[keep(X)]
    return X, analysis.Lattice(X, DP, origin=(0, 0))


def test_mirror_symmetry():
    x, lat = lattice()
    axis = 30 * DP
    f = np.exp(-((x[:, 0] - axis) ** 2 + (x[:, 1] - 0.02) ** 2) / 1e-4) + np.abs(x[:, 0] - axis)
    assert analysis.mirror_symmetry(f, lat, axis) == pytest.approx(1.0, abs=1e-12)
    rng = np.random.default_rng(1)
    assert abs(analysis.mirror_symmetry(rng.random(len(x)), lat, axis)) < 0.1
    one_sided = np.where(x[:, 0] < axis - 5 * DP, 1.0, 0.0)      # damage only on the left
    assert analysis.mirror_symmetry(one_sided, lat, axis) < 0
    assert analysis.mirror_symmetry(np.zeros(len(x)), lat, axis) is None


@pytest.mark.parametrize("angle", [55.0, -55.0, 30.0, 90.0])
def test_band_inclination(angle):
    x, lat = lattice(80, 80)
    c = np.array([0.04, 0.04])
    u = np.array([math.cos(math.radians(angle)), math.sin(math.radians(angle))])
    r = x - c
    along, across = r @ u, r @ np.array([-u[1], u[0]])
    mask = (np.abs(across) < 1.6 * DP) & (np.abs(along) < 0.025)
    speck = np.hypot(*(x - [0.005, 0.075]).T) < 1.2 * DP           # a few isolated sites: not a band
    b = analysis.bands(mask | speck, lat)
    assert len(b) == 1
    got = b[0]["angle_deg"]
    assert min(abs(got - angle), abs(abs(got - angle) - 180)) < 1.5
    assert b[0]["length"] == pytest.approx(0.05, rel=0.06)


def test_spalled_block_area_and_mass():
    # opening: x < 10 mm; a failed ring (one site wide) cuts a 10 × 8 mm block off its wall
    hole = lambda p: p[:, 0] < 10 * DP
    x, lat = lattice(60, 40, keep=lambda p: ~hole(p))
    i, j = lat.i, lat.j                                           # i = 10 is the first rock column
    ring = ((i == 20) & (j >= 10) & (j <= 19)) | (((j == 10) | (j == 19)) & (i >= 10) & (i <= 20))
    block = (i >= 10) & (i < 20) & (j > 10) & (j < 19)
    mass = np.full(len(x), 2.5e-3)
    r = analysis.spalled(ring, lat, hole, mass)
    assert r["fragments"] == np.count_nonzero(block) == 80
    assert r["failed_connected"] == np.count_nonzero(ring)
    assert r["area"] == pytest.approx((80 + np.count_nonzero(ring)) * DP ** 2)
    assert r["mass"] == pytest.approx(2.5e-3 * (80 + np.count_nonzero(ring)))
    assert not r["mask"][(i > 25)].any()                         # the main rock is not spalled
    # the same ring away from the opening cuts nothing off it
    ring2 = ((i == 45) & (j >= 10) & (j <= 19)) | (((j == 10) | (j == 19)) & (i >= 35) & (i <= 45)) | ((i == 35) & (j >= 10) & (j <= 19))
    assert analysis.spalled(ring2, lat, hole)["area"] == 0


def test_lattice_rejects_non_lattice():
    with pytest.raises(ValueError, match="share a site"):
        analysis.Lattice(np.array([[0.5e-3, 0.5e-3], [0.6e-3, 0.5e-3]]), DP)
