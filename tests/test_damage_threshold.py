"""Grady–Kipp damage threshold (paper Eqs. 35–37) and its options: the readings of V in Eq. 37, the
regularised threshold, the strain measure of Eq. 36, the Benz–Asphaug flaw population, and the stress
a fully damaged (D = 1) particle carries. Expected values are computed here from the geometry and the
formulas, not with the code under test."""
import math

import numpy as np
import pytest

import yade_mpm as ym
from yade_mpm import rocks

K, M_W = rocks.GRANITE_DPGK["weibullK"], rocks.GRANITE_DPGK["weibullM"]
E, NU = rocks.GRANITE["young"], rocks.GRANITE["poisson"]
LAM = E * NU / ((1 + NU) * (1 - 2 * NU))
G = E / (2 * (1 + NU))
PMOD = LAM + 2 * G                      # K + 4G/3


def eq37(V):
    return (V * K) ** (-1.0 / M_W)


def block(spacing, size=0.2, dim=2, **mat):
    """Solver with a [0, size]^dim block, 2 particles per cell per axis; returns (solver, dp)."""
    s = ym.make_solver((0,) * dim, (size,) * dim, spacing, margin=2)
    ym.add_region(s, rocks.granite_dpgk(**mat), (0,) * dim, (size,) * dim, ppc=2)
    return s, spacing / 2


@pytest.mark.parametrize("spacing", [0.04, 0.02])
def test_threshold_volume_readings_give_eq37(spacing):
    """V = particle area × 1 m (literal, default), dp³ and l²·dp: every particle's ε_D⁰ is (Vk)^(−1/m)."""
    dp = spacing / 2
    s, _ = block(spacing)
    assert s.view("eps0") == pytest.approx(np.full(s.numParticles, eq37(dp * dp * 1.0)), rel=1e-12)   # default
    for reading, V in [("particle", dp * dp * 1.0), ("cube", dp ** 3), ("cell", spacing ** 2 * dp)]:
        s, _ = block(spacing, thresholdVolume=reading)
        eps0 = s.view("eps0")
        assert eps0 == pytest.approx(np.full(s.numParticles, eq37(V)), rel=1e-12), reading
    # the readings differ by fixed factors: dp³ raises ε_D⁰ by (1 m/dp)^(1/m) over area × 1 m
    assert eq37(dp ** 3) / eq37(dp * dp) == pytest.approx((1.0 / dp) ** (1 / M_W), rel=1e-12)
    # paper grid (l = 0.02 m), literal reading: ε_D⁰ = 4.54e-4 (doc/reference/damage_growth_law.md)
    if spacing == 0.02:
        assert eq37(dp * dp) == pytest.approx(4.540e-4, rel=1e-3)


@pytest.mark.parametrize("dim", [2, 3])
def test_default_threshold_volume_is_the_particle_volume(dim):
    """Issue 18: by default V of Eq. 37 is the particle's own volume, as in the reference code of the paper's
    DP–GK model (Graphyt: vol = mass/density, emin = pow(vol·k, −1/m); 2D volume psep² per unit depth).
    V is taken here from each particle's mass and the rock density, not from the solver's volume arrays."""
    s, dp = block(0.04, size=0.16, dim=dim)
    assert s.material(0).thresholdVolume == "particle"
    V = s.view("mass") / rocks.GRANITE["density"]                    # [m³]; 2D: area × 1 m
    assert V == pytest.approx(np.full(s.numParticles, dp ** dim), rel=1e-12)
    assert s.view("eps0") == pytest.approx((V * K) ** (-1.0 / M_W), rel=1e-12)
    assert s.view("eps0")[0] == pytest.approx({2: 3.774e-4, 3: 6.358e-4}[dim], rel=1e-3)   # by hand: (dp^D k)^(−1/m), dp = 0.02 m


def test_threshold_volume_in_3d_is_the_particle_volume():
    s, dp = block(0.05, size=0.1, dim=3, thresholdVolume="particle")
    assert s.view("eps0") == pytest.approx(np.full(s.numParticles, eq37(dp ** 3)), rel=1e-12)
    s, dp = block(0.05, size=0.1, dim=3, thresholdVolume="cube")
    assert s.view("eps0") == pytest.approx(np.full(s.numParticles, eq37(dp ** 3)), rel=1e-12)


@pytest.mark.parametrize("reading", ["particle", "cube", "cell"])
def test_regularised_threshold_scales_with_root_of_cell_size(reading):
    """thresholdCell = l_ref: on the l_ref grid ε_D⁰ is Eq. 37's; on any grid ε_D⁰·√l is the same."""
    lref = 0.02
    vals = {}
    for spacing in (0.08, 0.04, 0.02):
        s, _ = block(spacing, size=0.16, thresholdVolume=reading, thresholdCell=lref)
        e = s.view("eps0")
        assert np.ptp(e) == 0
        vals[spacing] = e[0]
    dp = lref / 2
    V = {"particle": dp * dp, "cube": dp ** 3, "cell": lref ** 2 * dp}[reading]
    assert vals[0.02] == pytest.approx(eq37(V), rel=1e-12)
    for spacing, e in vals.items():
        assert e * math.sqrt(spacing) == pytest.approx(eq37(V) * math.sqrt(lref), rel=1e-12)


def upd(stress, de, D=0.0, eps0=1.0, dt=1e-7, epsP=0.0, **mat):
    f = ym.materials.dpgkPointUpdate2D
    s, sd, e, d, mode, dl, nf = f(rocks.granite_dpgk(**mat), list(map(float, stress)), list(map(float, de)), epsP, D, eps0, dt)
    return np.array(s), np.array(sd), e, d


def test_eq36_strain_measures():
    """Equibiaxial in-plane strain e (plane strain): σxx = σyy = 2(λ + G)e, σzz = 2λe. Eq. 36 as printed
    gives ε̄ = σ1/(K + 4G/3); the principal-strain reading gives e itself. Damage starts exactly when
    ε̄ passes ε_D⁰ (Eq. 35)."""
    e = 3e-4
    sig = 2 * (LAM + G) * e
    printed, principal = sig / PMOD, e
    assert printed / principal == pytest.approx(2 * (LAM + G) / PMOD)      # 1/(1 − ν) with ν = λ/(2(λ + G))
    assert printed / principal == pytest.approx(1 / (1 - NU))
    de = [e, e, 0.0, 0.0]
    for measure, eb in [("uniaxial", printed), ("principal", principal)]:
        _, _, _, d_below = upd([0, 0, 0, 0], de, eps0=eb * (1 + 1e-9), damageStrain=measure, plasticity=False)
        _, _, _, d_above = upd([0, 0, 0, 0], de, eps0=eb * (1 - 1e-9), damageStrain=measure, plasticity=False)
        assert d_below == 0.0 and d_above > 0.0, measure
    # uniaxial strain: both readings coincide (σ1 = (K + 4G/3)ε)
    s, _, _, _ = upd([0, 0, 0, 0], [e, 0, 0, 0], eps0=1.0, plasticity=False)
    assert s[0] / PMOD == pytest.approx(e, rel=1e-12)


def test_fully_damaged_particle_carries_no_tension_keeps_compression():
    """D = 1: opening leaves no tensile stress in the state (nothing accumulates, no yielding at the DP
    apex); compression is carried elastically; mixed states keep only the compressive principal part."""
    e = 1e-3
    # pure opening, repeated: state stays zero, no plastic strain (an opening crack is not rock yielding)
    s = np.zeros(4)
    epsP = 0.0
    for _ in range(50):
        s, sd, epsP, d = upd(s, [e, 0.0, 0.0, 0.0], D=1.0, epsP=epsP)
        assert d == 1.0
    assert np.all(s == 0.0) and np.all(sd == 0.0) and epsP == 0.0
    # closing from zero: elastic compression, σxx = (λ + 2G)(−e), σyy = σzz = λ(−e)
    s, sd, epsP, _ = upd([0, 0, 0, 0], [-1e-4, 0, 0, 0], D=1.0)
    assert s == pytest.approx([-PMOD * 1e-4, -LAM * 1e-4, -LAM * 1e-4, 0.0], rel=1e-12)
    assert np.array_equal(s, sd) and epsP == 0.0
    # pure shear strain γ/2 = 1e-4 (xy): principal ±2G·1e-4 at 45°; the tensile one is removed
    s, sd, _, _ = upd([0, 0, 0, 0], [0, 0, 0, 1e-4], D=1.0)
    t = 2 * G * 1e-4
    assert s == pytest.approx([-t / 2, -t / 2, 0.0, t / 2], rel=1e-12, abs=1e-6)
    # the same increment on an intact particle is carried in full
    s0, _, _, _ = upd([0, 0, 0, 0], [0, 0, 0, 1e-4], D=0.0)
    assert s0 == pytest.approx([0, 0, 0, t], abs=1e-6)


def test_flaw_population_statistics():
    """Benz–Asphaug flaws: the thresholds of a particle are a Poisson process in Λ = kVε^m, so the mean
    number of flaws activated at strain ε is kVε^m, and the fraction of particles with at least one
    activated flaw is 1 − exp(−kVε^m) (≈ kVε^m when small). The solver's ε_D⁰ is the first flaw's."""
    spacing = 0.01
    s, dp = block(spacing, size=0.7, flawCount=16, flawSeed=11)     # 19 600 particles
    n = s.numParticles
    V = dp * dp * 1.0                 # default reading (thresholdVolume = "particle": area × 1 m)
    scale = eq37(V)
    eps0 = s.view("eps0")
    for lam in (0.02, 0.1, 0.5, 1.0, 2.0):
        eps = (lam / (K * V)) ** (1 / M_W)
        frac = np.count_nonzero(eps0 <= eps) / n
        p = 1 - math.exp(-lam)
        assert abs(frac - p) < 4 * math.sqrt(p * (1 - p) / n) + 1e-12, (lam, frac, p)
    assert np.count_nonzero(eps0 <= (0.02 / (K * V)) ** (1 / M_W)) / n == pytest.approx(0.02, rel=0.15)
    # all 16 flaws of 4000 particles: mean count below ε equals kVε^m (Poisson), thresholds ascending
    mat = rocks.granite_dpgk(flawCount=16, flawSeed=11)
    ids = s.view("id")[:4000]
    thr = np.array([ym.materials.dpgkFlawThresholds(mat, scale, int(i), 16) for i in ids])
    assert np.all(np.diff(thr, axis=1) > 0)
    assert thr[:, 0] == pytest.approx(eps0[:4000], rel=1e-15)    # storage order == id order before a step
    for lam in (0.5, 1.0, 3.0):
        eps = scale * lam ** (1 / M_W)
        mean = np.mean(np.sum(thr <= eps, axis=1))
        assert abs(mean - lam) < 4 * math.sqrt(lam / len(ids)), (lam, mean)
    # the seed changes the population, the same seed reproduces it
    s2, _ = block(spacing, size=0.7, flawCount=16, flawSeed=11)
    s3, _ = block(spacing, size=0.7, flawCount=16, flawSeed=12)
    assert np.array_equal(s2.view("eps0"), eps0) and not np.array_equal(s3.view("eps0"), eps0)


def test_flaws_cap_damage_by_activated_fraction():
    """A particle whose strain passes 3 of its 8 flaw thresholds grows D to at most 3/8."""
    mat = rocks.granite_dpgk(flawCount=8, flawSeed=5, plasticity=False)
    vol0, l = 1e-4, 0.02
    scale = ym.materials.dpgkThresholdScale(mat, vol0, l, 2)
    assert scale == pytest.approx(eq37(vol0), rel=1e-12)           # default reading: V = vol0 (area × 1 m)
    thr = ym.materials.dpgkFlawThresholds(mat, scale, 42, 8)
    eb = 0.5 * (thr[2] + thr[3])                       # between the 3rd and 4th flaw
    e = eb * PMOD / (LAM + 2 * G)                      # uniaxial strain: ε̄ (Eq. 36) = e
    s, nf, d = [0.0] * 4, 0.0, 0.0
    s, _, _, d, _, _, nf = ym.materials.dpgkPointUpdate2D(mat, s, [e, 0, 0, 0], 0.0, d, thr[0], 1e-6, nFlaw=nf, vol0=vol0, id=42, spacing=l)
    assert nf == 3
    for _ in range(200):
        s, _, _, d, _, _, nf = ym.materials.dpgkPointUpdate2D(mat, s, [0, 0, 0, 0], 0.0, d, thr[0], 1e-6, nFlaw=nf, vol0=vol0, id=42, spacing=l)
    assert d == pytest.approx(3 / 8, rel=1e-12) and nf == 3
    # straining past the last flaw lets D reach 1
    e2 = (thr[7] * 1.01 - eb) * PMOD / (LAM + 2 * G)
    s, _, _, d, _, _, nf = ym.materials.dpgkPointUpdate2D(mat, s, [e2, 0, 0, 0], 0.0, d, thr[0], 1e-6, nFlaw=nf, vol0=vol0, id=42, spacing=l)
    for _ in range(200):
        s, _, _, d, _, _, nf = ym.materials.dpgkPointUpdate2D(mat, s, [0, 0, 0, 0], 0.0, d, thr[0], 1e-6, nFlaw=nf, vol0=vol0, id=42, spacing=l)
    assert nf == 8 and d == 1.0


def test_bad_damage_options_are_refused():
    for kw, word in [(dict(thresholdVolume=3), "thresholdVolume"), (dict(damageStrain=2), "damageStrain"),
                     (dict(thresholdVolume=1), r"thresholdVolume must be one of 'particle', 'cube' or 'cell'"),
                     (dict(damageStrain="eq36"), r"damageStrain must be one of 'uniaxial' or 'principal'"),
                     (dict(thresholdCell=-0.01), "thresholdCell"), (dict(flawCount=-1), "flawCount"),
                     (dict(flawSeed=-1), "flawSeed")]:
        with pytest.raises(ValueError, match=word):
            rocks.granite_dpgk(**kw)
