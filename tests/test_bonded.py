"""yade_mpm_paper.validation.bonded (the JCFpm side of scripts/paper/compare_bonded.py): modulus of a stress–strain curve,
discs cut by a hole (against the exact point–polygon distance), Love–Weber stress against a hand
calculation, and bad micro-parameters refused."""
import math

import numpy as np
import pytest
import yade_mpm as ym
from yade_mpm_paper.validation import bonded

yade = pytest.importorskip("yade")


def test_apparent_modulus_skips_toe_and_post_peak():
    e = np.linspace(0, 0.01, 201)
    s = np.where(e < 0.001, 2e9 * e ** 2 / 0.002, 2e9 * (e - 0.0005))      # seating toe, then slope 2 GPa
    s = np.where(e > 0.006, s.max() - 5e9 * (e - 0.006), s)                  # softening after the peak
    s = np.minimum(s, 2e9 * (0.006 - 0.0005))
    assert bonded.apparent_modulus(e, s) == pytest.approx(2e9, rel=1e-9)
    with pytest.raises(ValueError, match="points between"):
        bonded.apparent_modulus([0, 1e-3], [0, 1e6])


def test_overlapping_discs():
    hole = ym.geometry.rotated_rectangle((0, 0), 0.02, 0.002, math.radians(30))
    xy = np.array([[0, 0], [0, 0.0015], [0, 0.003], [0.0105, 0], [0.013, 0]])
    r = np.full(5, 0.001)
    # centre inside; 1.5 mm above the axis: 0.3 mm from the band's edge (< r); 3 mm above: free;
    # the two points beyond the tip are checked against the exact distance to the rectangle
    exact = []
    v = hole.v
    for p, rr in zip(xy, r):
        d = min(np.linalg.norm(p - (v[i] + np.clip((p - v[i]) @ (v[(i + 1) % 4] - v[i]) / np.sum((v[(i + 1) % 4] - v[i]) ** 2), 0, 1)
                                    * (v[(i + 1) % 4] - v[i]))) for i in range(4))
        exact.append(hole.contains(p[None])[0] or d < rr)
    assert bonded.overlapping(hole, xy, r).tolist() == exact
    assert exact[:3] == [True, True, False]
    c = ym.Circle((0, 0), 0.01)
    assert bonded.overlapping(c, np.array([[0.0105, 0], [0.0115, 0]]), np.array([0.001, 0.001])).tolist() == [True, False]


def test_love_weber_two_discs():
    """Two bonded discs pulled apart by one contact force F along x: σ_xx = F·|l| / (π w² t)."""
    from yade import O, utils
    from yade.wrapper import (ForceResetter, InsertionSortCollider, Bo1_Sphere_Aabb, InteractionLoop, Ig2_Sphere_Sphere_ScGeom,
                              Ip2_JCFpmMat_JCFpmMat_JCFpmPhys, Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM, JCFpmMat,
                              NewtonIntegrator)
    O.reset()
    m = O.materials.append(JCFpmMat(young=1e9, poisson=0.3, tensileStrength=1e12, cohesion=1e12, density=1000))
    r = 0.01
    a = O.bodies.append(utils.sphere((0, 0, 0), r, material=m))
    b = O.bodies.append(utils.sphere((2 * r - 1e-6, 0, 0), r, material=m))   # bonded at a 1 µm overlap
    for k in (a, b):
        O.bodies[k].state.blockedDOFs = "xyzXYZ"
    O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),
                 InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_JCFpmMat_JCFpmMat_JCFpmPhys()],
                                 [Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM()]), NewtonIntegrator()]
    O.dt = 1e-6
    O.step()
    O.bodies[b].state.pos = (2 * r + 9e-6, 0, 0)        # stretch the bond by 10 µm
    O.step()
    i = O.interactions[a, b]
    F = -i.phys.normalForce[0]                         # tension: the bond pulls body 2 towards body 1
    assert F == pytest.approx(i.phys.kn * 1e-5, rel=1e-9)
    w, t = 0.03, 2 * r
    sig = bonded.love_weber(O, [[r, 0.0]], w, t)[0]
    assert sig[0] == pytest.approx(F * (2 * r + 9e-6) / (math.pi * w * w * t), rel=1e-9)   # tension positive
    assert sig[1] == pytest.approx(0, abs=1e-9 * abs(sig[0]))
    assert bonded.love_weber(O, [[1.0, 1.0]], w, t)[0].tolist() == [0, 0, 0]          # no contact in that window


def test_micro_parameters_refused_out_of_range():
    with pytest.raises(ValueError, match="ks_kn"):
        bonded.JcfpmMicro(young=1e9, ks_kn=1.5, tensile=1e6, cohesion=1e6, friction_deg=30)
    with pytest.raises(ValueError, match="young"):
        bonded.JcfpmMicro(young=-1, ks_kn=0.3, tensile=1e6, cohesion=1e6, friction_deg=30)
    with pytest.raises(ValueError, match="r_mean"):
        bonded.disc_packing((0, 0), (0.01, 0.01), 0.005)
