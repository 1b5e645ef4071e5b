"""Grady–Kipp damage of the DP–GK rock (paper Sec. 2.4, Eqs. 35–40) at a single material point: growth by the
selected law against its closed form, D within [0, 1] and never decreasing, the damaged stress (tension scaled by
1 − D in the principal frame, compression kept) in 2D and 3D, and the damage state exported from an MPM block.
The rock's parameters and the point update are those of tests/test_dpgk.py (plasticity of the same material).
Stress components: 2D (plane strain) [xx, yy, zz, xy], 3D [xx, yy, zz, xy, xz, yz]; tension positive."""
import math

import numpy as np
import pytest

import yade_mpm as ym
from test_dpgk import C0, M, RHO, WK, WM, full, mat, upd


# ------------------------------------------------------------------ GK damage, Eqs. 35–40
def rate_closed_form(eb, law, m_=WM, k=WK):
    a = 8 * math.pi * k * (m_ + 3) ** 2 / ((m_ + 1) * (m_ + 2))
    cg = 0.4 * math.sqrt(M / RHO)
    return cg * a ** (1 / 3) / 3 * (eb ** (m_ / 3) if law == "benz-asphaug" else eb ** (1 / 3))


@pytest.mark.parametrize("law", ["benz-asphaug", "as-printed"])
def test_damage_growth_follows_the_selected_law(law):
    m = mat(plasticity=False, growthLaw=law)
    eps0 = m.activationStrain(1e-4)
    dt = 1e-8 if law == "benz-asphaug" else 1e-15
    sxx = 1.2 * eps0 * M                             # ε̄ = σ̃max/(K + 4G/3) = 1.2 ε_D⁰ (Eq. 36)
    s, sd, _, d, _, _ = upd(m, [sxx, 0, 0, 0], [0, 0, 0, 0], D=0.0, eps0=eps0, dt=dt)
    assert d == pytest.approx((rate_closed_form(1.2 * eps0, law) * dt) ** 3, rel=1e-10)
    # below the threshold nothing grows (Eq. 35)
    _, _, _, d2, _, _ = upd(m, [0.99 * eps0 * M, 0, 0, 0], [0, 0, 0, 0], D=0.3, eps0=eps0, dt=1.0)
    assert d2 == 0.3


def test_damage_stays_in_unit_interval_and_never_decreases():
    rng = np.random.default_rng(3)
    m = mat(plasticity=False)
    eps0 = m.activationStrain(1e-4)
    s, d = np.zeros(4), 0.0
    hist = []
    for k in range(3000):
        de = rng.normal(0, 1.5e-4, 4)
        de[2] = 0
        s, sd, _, d_new, _, _ = upd(m, s, de, D=d, eps0=eps0, dt=2e-6)
        assert 0.0 <= d_new <= 1.0 and d_new >= d
        d = d_new
        hist.append(d)
    assert hist[-1] == 1.0 and hist[0] < 1.0


def test_fully_damaged_point_carries_compression_but_no_tension():
    m = mat(plasticity=False)
    s0 = np.array([30e6, -40e6, -5e6, 12e6])
    _, sd, _, d, _, _ = upd(m, s0, [0, 0, 0, 0], D=1.0, eps0=1.0)
    assert d == 1.0
    w0, v0 = np.linalg.eigh(full(s0))
    w1, v1 = np.linalg.eigh(full(sd))
    # tensile principal stresses are zero; compressive ones and their directions are unchanged
    np.testing.assert_allclose(sorted(w1), sorted(np.where(w0 > 0, 0.0, w0)), atol=1e-6)
    for k in range(3):
        if w0[k] < 0:
            j = int(np.argmin(np.abs(w1 - w0[k])))
            assert abs(abs(v0[:, k] @ v1[:, j]) - 1) < 1e-12
    # partially damaged: tensile principal scaled by (1 − D) (Eq. 40)
    _, sd, _, _, _, _ = upd(m, s0, [0, 0, 0, 0], D=0.25, eps0=1.0)
    w2 = np.linalg.eigvalsh(full(sd))
    np.testing.assert_allclose(sorted(w2), sorted(np.where(w0 > 0, 0.75 * w0, w0)), atol=1e-6)
    # pure compression is untouched even at D = 1
    _, sd, _, _, _, _ = upd(m, [-1e6, -2e6, -3e6, 0.5e6], [0, 0, 0, 0], D=1.0, eps0=1.0)
    np.testing.assert_allclose(sd, [-1e6, -2e6, -3e6, 0.5e6], atol=1e-6)


def test_3d_damage_rotation_back():
    m = mat(plasticity=False)
    s0 = np.array([10e6, -3e6, 2e6, 4e6, -1e6, 3e6])
    _, sd, _, _, _, _ = upd(m, s0, [0] * 6, D=0.5, eps0=1.0)
    w0, v0 = np.linalg.eigh(full(s0))
    ref = v0 @ np.diag(np.where(w0 > 0, 0.5 * w0, w0)) @ v0.T
    np.testing.assert_allclose(full(sd), ref, atol=1e-6)


# ------------------------------------------------------------------ state export from an MPM block
def test_particle_fields_export_damage_state():
    import yade_mpm.output as out
    s = ym.make_solver((0, 0), (0.2, 0.2), 0.05)
    s.courant = 0.5   # every particle yields in the one step: its unloading from the free faces grows as Δt², and at
                      # C = 0.75 / 1 it takes 16 / 32 of the 64 particles back inside the yield surface
    ym.add_region(s, mat(), (0, 0), (0.2, 0.2))
    ym.set_initial_stress(s, (-40e6, 60e6, 0.0, 0.0))   # beyond both criteria: yields and damages
    s.run(1)
    _, f = out.particle_fields(s)
    for k in ("damage", "plastic_strain", "cohesion", "max_principal_stress", "tensile_crack", "shear_crack"):
        assert k in f and len(f[k]) == s.numParticles
    assert np.all(f["plastic_strain"] > 0)
    assert np.all(f["cohesion"] < C0)
    assert np.all((f["damage"] >= 0) & (f["damage"] <= 1))
