"""The 3D-only case of doc/validation/three_d.md (``cases.prism3d``): the disc flaw's geometry against its analytical
volume and frame, and the prism's symmetric models (slip planes through its centre) against the whole
prism: the same platen stress to roundoff for the intact prism on a coarse grid."""
import math

import numpy as np
import pytest
import yade_mpm as ym
from yade_mpm_paper.cases import prism3d

pytest.importorskip("yade")
pytest.importorskip("yade_mpm.bodies")


def test_disc_volume_and_frame():
    fl = prism3d.penny_flaw()
    a, t = fl["radius"], fl["thickness"]
    assert a == pytest.approx(0.01) and t == pytest.approx(0.002) and math.degrees(fl["angle"]) == pytest.approx(30)
    h = 2.5e-4                                      # a lattice of 0.25 mm: the disc's volume π a² t within 0.5 %
    ax = [np.arange(c - 0.011 + h / 2, c + 0.011, h) for c in fl["center"]]
    x = np.stack(np.meshgrid(*ax, indexing="ij"), -1).reshape(-1, 3)
    assert fl["disc"].contains(x).sum() * h ** 3 == pytest.approx(math.pi * a * a * t, rel=0.005)
    rho, phi, hh = prism3d.disc_coordinates(np.array(fl["rim"]), fl)
    np.testing.assert_allclose(rho, a, rtol=1e-12)
    np.testing.assert_allclose(np.abs(phi), [0, 180], atol=1e-9)
    np.testing.assert_allclose(hh, 0, atol=1e-15)
    assert fl["rim"][0][1] > fl["rim"][1][1]       # φ = 0 is the upper rim point (the 2D flaw's upper tip)
    side = fl["center"] + a * np.array([0, 0, 1.0])
    assert prism3d.disc_coordinates(side[None], fl)[1][0] == pytest.approx(90)


@pytest.mark.parametrize("law, rtol", [("penalty", 1e-9), ("kinematic", 2e-4)])
@pytest.mark.parametrize("h, steps, models", [(0.004, 40, ("z",)), (0.0025, 15, ("z", "xz"))])
def test_symmetric_models_match_the_whole_prism(h, steps, models, law, rtol):
    # penalty (a per-particle force): the same numbers to roundoff. kinematic: the impulses of the platen's contact
    # layer come from an iterative solve (projected Gauss–Seidel to 1e-6 of the contact speed) whose sweep order
    # differs between the models: measured 8.8e-5 (z, 4 mm).
    # the quarter (xz) is checked on the run's grid, 2.5 mm: on a 4 mm grid (5 cells between its plane and the free
    # face) it differs from the whole prism by 2 % from the second step (doc/validation/three_d.md, not understood)
    from yade import O
    rec = {}
    for sym in ("none",) + models:
        s, sc = prism3d.penny_prism("intact", h, symmetry=sym, contact_law=law)
        rec[sym] = []
        for _ in range(steps):
            O.step()
            rec[sym].append(sc["axial_stress"]())
        rec[sym] = np.array(rec[sym])
        assert s.numParticles == round(8 * 0.04 * 0.08 * 0.04 / h ** 3) // {"none": 1, "z": 2, "xz": 4}[sym]
    assert rec["none"][-1] > 1e5
    for sym in models:
        np.testing.assert_allclose(rec[sym], rec["none"], rtol=rtol, atol=rtol * rec["none"].max())


def test_penny_prism_bad_input():
    with pytest.raises(ValueError, match="symmetry"):
        prism3d.penny_prism("penny", 0.004, symmetry="xz")
    with pytest.raises(ValueError, match="spacing"):
        prism3d.penny_prism("penny", 0.005)
    with pytest.raises(ValueError, match="variant"):
        prism3d.penny_prism("filled", 0.004)
    with pytest.raises(ValueError, match="flaw_nodes"):
        prism3d.penny_prism("penny", 0.004, flaw_nodes="none")
