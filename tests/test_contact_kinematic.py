"""The kinematic contact law (law="kinematic", pkg-mpm/KinematicContact.hpp): impulses at the contacting particles,
no penetration beyond closing an overlap in one step, Coulomb + cohesion as an impulse limit. Checked against the
exact incline acceleration g(sin θ − μ cos θ), a cohesive capacity A·c that holds at 1.1× the drive and gives way at
0.9×."""
import numpy as np
import pytest
import yade_mpm as ym
import test_contact as tc


@pytest.fixture
def kinematic(monkeypatch):
    orig = ym.contact_params
    monkeypatch.setattr(tc.ym, "contact_params", lambda *a, **k: orig(*a, law="kinematic", **k))


@pytest.mark.parametrize("d", [2, 3])
def test_incline_slides_with_coulomb_acceleration(kinematic, d):
    theta, mu = np.radians(30), 0.3
    s, _, t, l, _ = tc._block_on_incline(d, theta, mu)
    assert s.contactParams(0).law == "kinematic"
    h = tc._slide(s, d, 0.1, 0.03)
    tt = np.array([x[0] for x in h])
    v = np.array([x[2] @ t for x in h])
    late = tt > 0.03
    a = -np.polyfit(tt[late], v[late], 1)[0]
    exact = tc.G * (np.sin(theta) - mu * np.cos(theta))
    assert abs(a / exact - 1) < 0.03


def test_cohesion_holds_at_capacity_and_gives_way_below(kinematic):
    theta, moved = np.radians(30), {}
    for factor in (1.1, 0.9):
        s, _, t, l, m = tc._block_on_incline(2, theta, 0.0, cohesion=1.0)
        drive, A = m * tc.G * np.sin(theta), 0.2
        s, _, t, l, m = tc._block_on_incline(2, theta, 0.0, cohesion=factor * drive / A)
        tc._gravity_prestress(s, theta)
        x0 = tc._com(s, 2, "x")
        h = tc._slide(s, 2, 0.1, 0.0)
        moved[factor] = -(h[-1][1] - x0) @ t
    assert abs(moved[1.1]) < 0.01 * l        # measured 9e-5 of a cell (penalty law: 2.2e-4)
    assert moved[0.9] > 0.1 * l

