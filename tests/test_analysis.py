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


# ---- the scene-independent entry points: regions, shear bands, cracks, zones from a point, the one-call report
from yade_mpm.geometry import Box, Circle  # noqa: E402


def test_region_test_accepts_shapes_lists_and_callables():
    pts = np.array([[0.5, 0.5], [2.0, 2.0], [3.0, 0.5]])
    box, disc = Box((0, 0), (1, 1)), Circle((2, 2), 0.1)
    assert analysis.region_test(box)(pts).tolist() == [True, False, False]
    assert analysis.region_test([box, disc])(pts).tolist() == [True, True, False]
    assert analysis.region_test(lambda p: p[:, 0] > 2.5)(pts).tolist() == [False, False, True]
    for bad in (3.0, [], ["box"], None):
        with pytest.raises(ValueError, match="opening must be a shape"):
            analysis.region_test(bad, "opening")


def test_distances():
    p = np.array([[0.0, 1.0], [2.0, 0.0], [-3.0, 4.0], [5.0, 0.0]])
    d = analysis.distance_to_segment(p, (0, 0), (4, 0))
    assert d.tolist() == pytest.approx([1.0, 0.0, 5.0, 1.0])
    # opening x < 10 mm: a rock particle in column i (i ≥ 10) is i − 9 sites from the last hole column
    hole = Box((0, 0), (10 * DP, 1.0))
    x, lat = lattice(40, 10, keep=lambda q: ~hole.contains(q))
    assert analysis.opening_distance(lat, hole) == pytest.approx((lat.i - 9) * DP)


@pytest.mark.parametrize("angle", [35.0, -60.0])
def test_shear_band_angle_within_one_cell(angle):
    """A 40 mm band of ε̄p = 0.02 in a field of ε̄p ≤ 1e-3 (and a hot strip near the 'opening', excluded by
    the zone): one band, inclination within one lattice site over its length, threshold as declared."""
    x, lat = lattice(90, 90)
    rng = np.random.default_rng(3)
    e = 1e-3 * rng.random(len(x))
    c = np.array([0.05, 0.045])
    u = np.array([math.cos(math.radians(angle)), math.sin(math.radians(angle))])
    r = x - c
    band = (np.abs(r @ np.array([-u[1], u[0]])) < 1.1 * DP) & (np.abs(r @ u) < 0.02)
    e[band] = 0.02
    e[x[:, 0] < 5 * DP] = 0.05                                    # plastic rim of an opening at the left edge
    zone = x[:, 0] > 8 * DP
    b, thr = analysis.shear_bands(e, lat, zone, fraction=0.5, floor=5e-4)
    assert thr == pytest.approx(0.5 * np.percentile(e[zone], 99))
    assert len(b) == 1 and b[0]["sites"] == np.count_nonzero(band)
    tol = math.degrees(math.atan(DP / 0.04))                      # one site over the band's length
    assert abs(b[0]["angle_deg"] - angle) <= tol
    assert b[0]["length"] == pytest.approx(0.04, abs=2 * DP)
    assert b[0]["centroid"] == pytest.approx(c, abs=DP)


def test_crack_length_and_orientation():
    x, lat = lattice(80, 40)
    D = np.zeros(len(x))
    crack = (lat.j == 20) & (lat.i >= 10) & (lat.i < 60)          # a horizontal crack of 50 sites
    D[crack] = 1.0
    D[(lat.i == 70) & (lat.j == 5)] = 1.0                          # one isolated damaged particle: not a crack
    c = analysis.cracks(D, lat)
    assert len(c) == 1 and c[0]["length"] == pytest.approx(50 * DP) and abs(c[0]["angle_deg"]) < 1e-9
    assert analysis.cracks(np.where(crack, 0.5, 0.0), lat) == []   # D < 1 is not a crack ...
    assert len(analysis.cracks(np.where(crack, 0.5, 0.0), lat, level=0.5)) == 1   # ... unless asked


def test_zone_from_a_point_reaches_the_opening():
    hole = Box((0, 0), (10 * DP, 1.0))
    x, lat = lattice(60, 40, keep=lambda q: ~hole.contains(q))
    i, j = lat.i, lat.j
    path = ((j == 20) & (i >= 10) & (i <= 40)) | ((i == 40) & (j >= 20) & (j <= 30))   # from the wall to (40, 30)
    other = (i == 50) & (j < 10)                                                       # failed, not connected
    toe = x[(i == 40) & (j == 30)][0]
    z = analysis.zone_from(toe, path | other, lat, x, radius=1.5 * DP)
    assert np.array_equal(z, path)
    reach = z & analysis.opening_surface(lat, hole)
    assert np.array_equal(np.nonzero(reach)[0], np.nonzero(path & (i == 10))[0])
    assert not analysis.zone_from(x[(i == 55) & (j == 35)][0], path, lat, x, 1.5 * DP).any()


def test_crack_report_on_a_constructed_scene():
    """An opening x < 10 mm; a failed ring cutting an 80-site block off its wall; a shear band of
    ε̄p past the softening end inclined 45°; mirror symmetry about the lattice's middle column."""
    hole = Box((0, 0), (10 * DP, 1.0))
    x, lat = lattice(60, 40, keep=lambda q: ~hole.contains(q))
    i, j = lat.i, lat.j
    ring = ((i == 20) & (j >= 10) & (j <= 19)) | (((j == 10) | (j == 19)) & (i >= 10) & (i <= 20))
    D = np.where(ring, 1.0, 0.0)
    e = np.zeros(len(x))
    band = (np.abs((i - 40) - (j - 20)) <= 1) & (np.abs(i - 40) <= 12)    # 45°, 3 sites wide, away from the ring
    e[band] = 0.01
    mass = np.full(len(x), 2.5e-3)
    r = analysis.crack_report(dict(damage=D, plastic_strain=e, mass=mass), lat, hole, soft_end=0.005,
                              axis_x=35 * DP, point=x[(i == 20) & (j == 15)][0], band_gap=3 * DP)
    n_ring = int(ring.sum())
    assert r["spalled"]["area"] == pytest.approx((80 + n_ring) * DP ** 2)
    assert r["spalled"]["mass"] == pytest.approx(2.5e-3 * (80 + n_ring))
    assert np.array_equal(r["surface"], ring)                             # the failed part of the spalled rock
    assert np.array_equal(r["failed"], ring | band) and np.array_equal(r["softened"], band)
    assert len(r["bands"]) == 1 and abs(r["bands"][0]["angle_deg"] - 45) <= math.degrees(math.atan(1 / 24))
    assert r["cracks"][0]["sites"] == n_ring
    assert r["damaged_fraction"] == pytest.approx(n_ring / len(x))
    assert r["softened_fraction"] == pytest.approx(band.sum() / len(x))
    assert r["symmetry_damage"] < 0.5                                     # the ring is on one side only
    assert r["point_damaged"] > 0 and np.array_equal(np.nonzero(r["point_failed_reach"])[0],
                                                     np.nonzero(ring & (i == 10))[0])
