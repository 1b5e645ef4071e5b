"""DpGkMat.failedBulking: a failed particle (D = 1) bulks at most to failedBulking × its initial volume.

Without the limit (failedBulking = inf, the paper as printed) a failed fragment keeps the expansion rate of its affine
velocity field and nothing resists it (a crack carries no tension), so its volume grows without bound and, through
v_c at the lowest current density, Δt falls as 1/√J (doc/validation/stability.md, "Failed particles that keep
expanding"). The scene: a 2 × 2-cell block of fully damaged rock given a uniform expansion v = ε̇ (x − x_c)."""
import math

import numpy as np
import pytest

import yade_mpm as ym

RATE = 1000.0          # ε̇ [1/s]
L = 0.01               # grid spacing [m]


def expanding_failed_block(bulking, t_end):
    s = ym.make_solver((0.0, 0.0), (0.2, 0.2), L)
    mat = ym.rocks.granite_dpgk(failedBulking=bulking)
    ym.add_region(s, mat, (0.09, 0.09), (0.11, 0.11))
    s.view("v0")[:] = RATE * (s.view("x0") - 0.1)
    s.view("v1")[:] = RATE * (s.view("x1") - 0.1)
    s.view("damage")[:] = 1.0
    s.requestSort()
    while s.time < t_end:
        s.run(1)
    return s, mat


def expected_dt(s, mat, rho_min):
    """The paper's bound Δt = C·l/(v_c + max‖v‖) with v_c at the density rho_min [kg/m³], computed here."""
    v = np.hypot(np.asarray(s.view("v0")), np.asarray(s.view("v1"))).max()     # the particle velocities Δt reads
    return s.courant * L / (mat.pWaveSpeed() * math.sqrt(mat.density / rho_min) + v)


def test_failed_particles_stop_bulking_at_the_limit_and_the_step_stays():
    s, mat = expanding_failed_block(1.5, 1e-3)
    J = np.asarray(s.view("vol")) / np.asarray(s.view("vol0"))
    assert np.all(J <= 1.5 * (1 + 1e-15)) and np.all(J >= 1.5 * (1 - 1e-12)), J   # reached, never exceeded
    # Δt from the capped density ρ₀/1.5: √1.5 below the intact step, no further
    assert s.stableDt() == pytest.approx(expected_dt(s, mat, mat.density / 1.5), rel=1e-9)


def test_without_the_limit_the_volume_and_the_step_run_away():
    s, mat = expanding_failed_block(float("inf"), 1e-3)
    J = np.asarray(s.view("vol")) / np.asarray(s.view("vol0"))
    assert J.min() > 3.0                                 # grows on: nothing resists a failed particle's expansion
    assert s.stableDt() == pytest.approx(expected_dt(s, mat, mat.density / J.max()), rel=1e-9)
    assert s.stableDt() < 0.6 * expected_dt(s, mat, mat.density)


def test_the_limit_changes_nothing_below_it():
    """A run in which no failed particle reaches the limit gives the same bits with and without it."""
    a, _ = expanding_failed_block(1.5, 1e-4)
    b, _ = expanding_failed_block(float("inf"), 1e-4)
    assert np.asarray(b.view("vol")).max() / np.asarray(b.view("vol0")).min() < 1.5
    for name in ("x0", "x1", "v0", "v1", "vol", "sig0", "sig1", "sig2", "sig3", "damage"):
        assert np.array_equal(np.asarray(a.view(name)), np.asarray(b.view(name))), name


def test_bad_limit_named_with_its_range():
    with pytest.raises(ValueError, match=r"failedBulking = 0\.5 .*outside the allowed range \[1, inf\]"):
        ym.rocks.granite_dpgk(failedBulking=0.5)
