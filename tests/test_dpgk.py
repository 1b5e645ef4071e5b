"""Drucker–Prager + Grady–Kipp rock (paper Sec. 2.4, Eqs. 27–40) at a single material point, checked
against closed forms and an independent return-mapping calculation written here with full 3×3 tensors:
the parameters, the elastic trial, the cone and apex returns, softening (the Grady–Kipp damage of the same
point: tests/test_dpgk_damage.py, which imports the helpers below).
Stress components: 2D (plane strain) [xx, yy, zz, xy], 3D [xx, yy, zz, xy, xz, yz]; tension positive."""
import math

import numpy as np
import pytest

import yade_mpm as ym

P = ym.rocks.GRANITE_DPGK               # the paper's Sec. 3.2 rock
E, NU, RHO = P["young"], P["poisson"], P["density"]
K = E / (3 * (1 - 2 * NU))
G = E / (2 * (1 + NU))
M = K + 4 * G / 3
PHI, PSI, C0 = P["frictionAngle"], P["dilationAngle"], P["cohesion"]
WK, WM = P["weibullK"], P["weibullM"]


def mat(**kw):
    return ym.rocks.granite_dpgk(**kw)


def dp_coeffs(phi):
    """Eq. 31 / 33 written out again."""
    s = math.sin(phi)
    return 6 * s / (math.sqrt(3) * (3 - s)), 6 * math.cos(phi) / (math.sqrt(3) * (3 - s))


QPHI, KPHI = dp_coeffs(PHI)
QPSI, _ = dp_coeffs(PSI)


def full(v):
    v = list(v)
    if len(v) == 4:
        v += [0.0, 0.0]
    xx, yy, zz, xy, xz, yz = v
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


def compact(m, n):
    v = [m[0, 0], m[1, 1], m[2, 2], m[0, 1], m[0, 2], m[1, 2]]
    return np.array(v[:n])


def invariants(m):
    sm = np.trace(m) / 3
    s = m - sm * np.eye(3)
    return math.sqrt(0.5 * np.sum(s * s)), sm, s


def hooke(stress, de):
    """Eqs. 27–28 with full tensors."""
    e = full(de)
    return full(stress) + 2 * G * (e - np.trace(e) / 3 * np.eye(3)) + K * np.trace(e) * np.eye(3)


def cohesion(eps, ecrit=0.1, c0=C0):
    return max(c0 * (1 - eps / ecrit), 0.1 * c0)   # Eq. 34


def upd(m, stress, de, epsP=0.0, D=0.0, eps0=1.0, dt=1e-6):
    f = ym.materials.dpgkPointUpdate2D if len(stress) == 4 else ym.materials.dpgkPointUpdate3D
    s, sd, e, d, mode, dl = f(m, list(map(float, stress)), list(map(float, de)), epsP, D, eps0, dt)[:6]
    return np.array(s), np.array(sd), e, d, mode, dl


# dε̄p/dΔλ of DpGkMat.plasticStrainIncrement, written out again: the reference code's k̄φ (Graphyt,
# ConstitutiveModels.cpp, druckerPrager_Damage: acc_plastic_strain += dL·ξ) and the von Mises equivalent
# of the deviatoric plastic strain, √(2/3)‖Δε^p_dev‖ = √(2/3)·Δλ/√2 = Δλ/√3.
INCREMENTS = {"reference-code": KPHI, "von-mises": 1 / math.sqrt(3)}


def independent_return(trial, eps, ecrit=0.1, c0=C0, inc="reference-code"):
    """Independent DP cone return: root of F(σ(Δλ), c(ε̄p + r Δλ)) = 0 by bisection, r = INCREMENTS[inc],
    with σ(Δλ) = σ_tr − Δλ C:∂g/∂σ and g = τ + qψ σm (Eqs. 30–34). Returns (stress, Δλ, ε̄p) or None if
    the cone return is not admissible (τ would turn negative)."""
    rate = INCREMENTS[inc]
    tau, sm, s = invariants(trial)
    dgds = s / (2 * tau) + QPSI / 3 * np.eye(3)
    corr = 2 * G * (dgds - np.trace(dgds) / 3 * np.eye(3)) + K * np.trace(dgds) * np.eye(3)

    def F(dl):
        t2, m2, _ = invariants(trial - dl * corr)
        t2 = tau - G * dl  # signed τ along the path (the norm hides the sign past the apex)
        return t2 + QPHI * m2 - KPHI * cohesion(eps + rate * dl, ecrit, c0)

    lo, hi = 0.0, tau / G
    if F(hi) > 0:
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if F(mid) > 0 else (lo, mid)
    dl = 0.5 * (lo + hi)
    return trial - dl * corr, dl, eps + rate * dl


def yield_value(stress, eps, ecrit=0.1):
    tau, sm, _ = invariants(full(stress))
    return tau + QPHI * sm - KPHI * cohesion(eps, ecrit)


# ------------------------------------------------------------------ Eqs. 31, 33, 34, 37, 39
def test_parameters_match_the_printed_formulas():
    m = mat()
    assert m.qPhi() == pytest.approx(QPHI, rel=1e-14)
    assert m.kPhi() == pytest.approx(KPHI, rel=1e-14)
    assert m.qPsi() == pytest.approx(QPSI, rel=1e-14)
    # outer-apex match: in triaxial compression (σ1 = σ2 > σ3 in tension-positive order) DP equals MC
    s3 = -50e6
    s1 = (s3 * (1 - math.sin(PHI)) + 2 * C0 * math.cos(PHI)) / (1 + math.sin(PHI))  # MC: σ1 − σ3 = 2c cosφ − (σ1+σ3) sinφ
    tens = np.diag([s1, s1, s3])
    tau, sm, _ = invariants(tens)
    assert tau + QPHI * sm - KPHI * C0 == pytest.approx(0, abs=1e-9 * C0)
    assert m.cohesionAt(0.0) == C0
    assert m.cohesionAt(0.05) == pytest.approx(0.5 * C0, rel=1e-14)
    assert m.cohesionAt(0.09) == pytest.approx(0.1 * C0, rel=1e-12)
    assert m.cohesionAt(5.0) == 0.1 * C0
    assert m.activationStrain(1e-4) == pytest.approx((1e-4 * WK) ** (-1 / WM), rel=1e-14)
    mm = WM
    assert m.alpha() == pytest.approx(8 * math.pi * WK * (mm + 3) ** 2 / ((mm + 1) * (mm + 2)), rel=1e-14)
    # Eq. 39 α equals Benz & Asphaug's prefactor: (m+3)/3 · α_BA^(1/3) = ⅓ α^(1/3) for c_g = 1
    a_ba = 8 * math.pi * WK / ((mm + 1) * (mm + 2) * (mm + 3))
    assert (mm + 3) / 3 * a_ba ** (1 / 3) == pytest.approx(m.alpha() ** (1 / 3) / 3, rel=1e-12)
    assert m.effectiveCrackSpeed() == pytest.approx(0.4 * math.sqrt(M / RHO), rel=1e-14)


def test_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="dilatancyAngle"):
        mat(dilatancyAngle=math.radians(40))
    with pytest.raises(ValueError, match="critPlasticStrain"):
        mat(critPlasticStrain=1e-5)   # softening steeper than G
    with pytest.raises(ValueError, match="growthLaw"):
        mat(growthLaw=2)
    with pytest.raises(ValueError, match=r"DpGkMat.plasticStrainIncrement must be one of 'reference-code' or 'von-mises' \(got str vonMises\)"):
        mat(plasticStrainIncrement="vonMises")
    with pytest.raises(ValueError, match="plasticStrainIncrement must be one of"):
        mat(plasticStrainIncrement=1)          # no integer codes
    # the softening bound depends on the increment: k̄φ c₀ r/ε̄p,crit < G
    e_ok = 1.05 * KPHI * C0 * INCREMENTS["von-mises"] / G
    mat(critPlasticStrain=e_ok, plasticStrainIncrement="von-mises")
    with pytest.raises(ValueError, match="critPlasticStrain.*plasticStrainIncrement = 'reference-code'"):
        mat(critPlasticStrain=e_ok)
    with pytest.raises(ValueError, match="weibullM"):
        mat(weibullM=0.0)


# ------------------------------------------------------------------ elastic trial, Eqs. 27–29
@pytest.mark.parametrize("n", [4, 6])
def test_elastic_trial_inside_surface_is_returned_unchanged(n):
    m = mat(damage=False)
    s0 = np.array([-10e6, -12e6, -8e6, 1e6, 0.5e6, -0.3e6][:n])
    de = np.array([-1e-5, 2e-5, 0.0, 3e-6, -1e-6, 2e-6][:n])
    if n == 4:
        de[2] = 0.0          # plane strain
    s, sd, e, d, mode, dl = upd(m, s0, de, epsP=0.02)
    assert mode == 0 and dl == 0 and e == 0.02
    np.testing.assert_allclose(s, compact(hooke(s0, de), n), rtol=0, atol=1e-9 * 1e6)
    np.testing.assert_array_equal(s, sd)
    assert yield_value(s, 0.02) < 0


# ------------------------------------------------------------------ cone return, Eqs. 30–33
def test_default_increment_is_the_reference_codes():
    assert mat().plasticStrainIncrement == "reference-code"
    assert ym.DpGkMat(**P).plasticStrainIncrement == "reference-code"


@pytest.mark.parametrize("inc", sorted(INCREMENTS))
@pytest.mark.parametrize("n", [4, 6])
def test_cone_return_lands_on_surface_along_q_psi(n, inc):
    m = mat(damage=False, plasticStrainIncrement=inc)
    s0 = np.array([-30e6, -30e6, -30e6, 0, 0, 0][:n])
    de = 3 * np.array([-2e-3, 1e-3, 0.0, 1.5e-3, 4e-4, -3e-4][:n])
    if n == 4:
        de[2] = 0.0
    trial = hooke(s0, de)
    s, _, e, _, mode, dl = upd(m, s0, de)
    assert mode == 1 and dl > 0
    # on the (softened) yield surface within 1e-8 relative
    assert abs(yield_value(s, e)) < 1e-8 * KPHI * C0
    # plastic flow direction from g = τ + qψ σm: the deviator keeps its direction, the mean stress drops
    # by K qψ Δλ while τ drops by G Δλ
    tt, mt, st = invariants(trial)
    tn, mn, sn = invariants(full(s))
    np.testing.assert_allclose(sn / tn, st / tt, atol=1e-12)
    assert tt - tn == pytest.approx(G * dl, rel=1e-10)
    assert mt - mn == pytest.approx(K * QPSI * dl, rel=1e-10)
    assert (mt - mn) / (tt - tn) == pytest.approx(K * QPSI / G, rel=1e-10)
    # ε̄p from the plastic deviatoric strain of the returned stress: ‖Δε^p_dev‖ = Δλ/√2
    dep_dev = (st - sn) / (2 * G)
    norm = math.sqrt(np.sum(dep_dev * dep_dev))
    if inc == "von-mises":
        assert e == pytest.approx(math.sqrt(2 / 3) * norm, rel=1e-10)    # von Mises equivalent
    else:
        assert e == pytest.approx(KPHI * math.sqrt(2) * norm, rel=1e-10)  # k̄φ Δλ
    # the independent bisection return agrees (its softening uses the same increment)
    ref = independent_return(trial, 0.0, inc=inc)
    assert ref is not None
    np.testing.assert_allclose(s, compact(ref[0], n), rtol=0, atol=1e-7 * C0)
    assert dl == pytest.approx(ref[1], rel=1e-9)
    assert e == pytest.approx(ref[2], rel=1e-9)
    # the other increment gives a different Δλ (softening depends on it): the test can tell them apart
    other = independent_return(trial, 0.0, inc=[k for k in INCREMENTS if k != inc][0])
    assert abs(other[1] - dl) > 1e-6 * dl


def test_associated_flow_when_psi_equals_phi():
    m = mat(damage=False, dilatancyAngle=PHI)
    s0, de = [-20e6, -20e6, -20e6, 0], [-9e-3, 6e-3, 0, 3e-3]
    s, _, e, _, mode, dl = upd(m, s0, de)
    tn, mn, _ = invariants(full(s))
    tt, mt, _ = invariants(hooke(s0, de))
    assert mode == 1
    assert (mt - mn) / (tt - tn) == pytest.approx(K * QPHI / G, rel=1e-10)


# ------------------------------------------------------------------ apex return
@pytest.mark.parametrize("inc", sorted(INCREMENTS))
def test_apex_return_for_tension_beyond_the_apex(inc):
    m = mat(damage=False, plasticStrainIncrement=inc)
    apex = KPHI * C0 / QPHI          # σm of the cone apex [Pa]
    # pure hydrostatic tension beyond the apex, plus a small shear: the cone return would need τ < 0
    s0 = [apex * 1.5, apex * 1.5, apex * 1.5, 1e6]
    s, _, e, _, mode, dl = upd(m, s0, [0, 0, 0, 0])
    assert mode == 2
    assert independent_return(full(s0), 0.0) is None      # the cone return is indeed inadmissible
    tau = invariants(full(s0))[0]
    assert e == pytest.approx(INCREMENTS[inc] * tau / G, rel=1e-12)   # Δλ = τ/G, the cone's measure
    c = cohesion(e)
    np.testing.assert_allclose(s, [KPHI * c / QPHI] * 3 + [0.0], rtol=1e-12, atol=1e-6)
    assert abs(yield_value(s, e)) < 1e-8 * KPHI * C0
    # exactly hydrostatic trial: no deviatoric plastic strain, stress lands on the apex, ε̄p unchanged
    s, _, e, _, mode, _ = upd(m, [2 * apex] * 3 + [0.0], [0, 0, 0, 0])
    assert mode == 2 and e == 0.0
    np.testing.assert_allclose(s, [apex] * 3 + [0.0], rtol=1e-12)


# ------------------------------------------------------------------ softening, Eq. 34
@pytest.mark.parametrize("inc", sorted(INCREMENTS))
def test_softening_reaches_the_floor_exactly_and_stays(inc):
    ecrit = 0.01
    m = mat(damage=False, critPlasticStrain=ecrit, plasticStrainIncrement=inc)
    s = np.array([-40e6, -40e6, -40e6, 0.0])
    eps, prev_eps, floor_hit = 0.0, 0.0, None
    de = np.array([-4e-4, 4e-4, 0, 3e-4])    # plane-strain shear with a little compression
    for k in range(400):
        s, _, eps, _, mode, _ = upd(m, s, de, epsP=eps)
        assert eps >= prev_eps
        prev_eps = eps
        c = m.cohesionAt(eps)
        if mode:
            assert abs(yield_value(s, eps, ecrit)) < 1e-8 * KPHI * C0
        if c == 0.1 * C0 and floor_hit is None:
            floor_hit = k
    assert floor_hit is not None and floor_hit < 399
    assert eps > 0.9 * ecrit
    assert m.cohesionAt(eps) == 0.1 * C0                 # exactly the floor, and it stays there
    # residual state: τ = k̄φ·0.1c₀ − qφ σm
    tau, sm, _ = invariants(full(s))
    assert tau == pytest.approx(KPHI * 0.1 * C0 - QPHI * sm, rel=1e-8)


@pytest.mark.parametrize("inc", sorted(INCREMENTS))
def test_floor_crossing_step_matches_independent_return(inc):
    ecrit = 0.01
    m = mat(damage=False, critPlasticStrain=ecrit, plasticStrainIncrement=inc)
    eps0 = 0.0085                                       # 0.0005 before the floor at 0.009
    s0 = np.array([-20e6, -20e6, -20e6, 0.0])
    de = np.array([-2e-3, 2e-3, 0, 2e-3])
    s, _, e, _, mode, dl = upd(m, s0, de, epsP=eps0)
    ref = independent_return(hooke(s0, de), eps0, ecrit, inc=inc)
    assert mode == 1 and e > 0.009
    np.testing.assert_allclose(s, compact(ref[0], 4), rtol=0, atol=1e-7 * C0)
    assert e == pytest.approx(ref[2], rel=1e-9)


# ------------------------------------------------------------------ plane-strain compression path
@pytest.mark.parametrize("inc", sorted(INCREMENTS))
def test_plane_strain_compression_path_against_independent_integration(inc):
    """Biaxial plane-strain compression: σxx held at −5 MPa by solving for Δεxx each increment,
    εyy shortened in 400 increments, εzz = 0. The MPM point update and an independent integration
    (Hooke + bisection return written above) must give the same path; before yield the path must
    match plane-strain elasticity, σyy − σxx0 = E/(1 − ν²)·εyy."""
    ecrit = 0.02
    m = mat(damage=False, critPlasticStrain=ecrit, plasticStrainIncrement=inc)
    conf = -5e6
    s = np.array([conf, conf, conf, 0.0])        # start hydrostatic (σzz = confinement too)
    r = full(s)
    eps = eps_r = 0.0
    dyy = -2e-5
    path = []
    for k in range(400):
        # Δεxx keeping σxx = conf: elastic guess, then two secant corrections on the MPM update
        lam = K - 2 * G / 3
        dxx = (conf - s[0] - lam * dyy) / (lam + 2 * G)
        for _ in range(30):
            t, _, _, _, _, _ = upd(m, s, [dxx, dyy, 0, 0], epsP=eps)
            t2, _, _, _, _, _ = upd(m, s, [dxx + 1e-9, dyy, 0, 0], epsP=eps)
            slope = (t2[0] - t[0]) / 1e-9
            step = (conf - t[0]) / slope
            dxx += step
            if abs(step) < 1e-16:
                break
        s_new, _, eps_new, _, mode, _ = upd(m, s, [dxx, dyy, 0, 0], epsP=eps)
        # independent integration with the same strain increment
        tr = hooke(compact(r, 4), [dxx, dyy, 0, 0])
        if yield_value(compact(tr, 4), eps_r, ecrit) > 0:
            rr = independent_return(tr, eps_r, ecrit, inc=inc)
            r, eps_r = rr[0], rr[2]
        else:
            r = tr
        np.testing.assert_allclose(s_new, compact(r, 4), rtol=0, atol=1e-6 * C0)
        assert eps_new == pytest.approx(eps_r, rel=1e-8, abs=1e-15)
        s, eps = s_new, eps_new
        path.append((s[1], eps, mode))
    syy = np.array([p[0] for p in path])
    modes = [p[2] for p in path]
    assert modes[0] == 0 and max(modes) == 1 and eps > 0
    first_plastic = modes.index(1)
    # elastic part: σyy − conf = (E/(1−ν²))·(εyy) with σxx fixed (plane-strain elasticity)
    k_el = first_plastic - 1
    assert syy[k_el] - conf == pytest.approx(E / (1 - NU ** 2) * dyy * (k_el + 1), rel=1e-9)
    assert abs(s[0] - conf) < 1e-3
