"""Several materials per scene: each region keeps its own material (particle material index), the hot
loops switch on the index into the templated kernels, the time step uses the fastest material.

The physics check is a layered bar in one-dimensional strain (slip faces top and bottom): a step
pressure P enters layer 1 (stiff rock) and crosses the interface into layer 2 (soft grout). Elastic
wave theory gives the transmitted stress σ_T = P·2Z₂/(Z₁ + Z₂) with impedances Z = ρc, c = √(M/ρ),
M = K + 4G/3, and the front's arrival at a station x in layer 2 at L₁/c₁ + (x − L₁)/c₂."""
import numpy as np
import pytest
import yade_mpm as ym
from yade_mpm import rocks

L1 = L2 = 1.0   # layer lengths [m]
H_CELLS = 2
ROCK = ym.ElasticMat(young=10e9, poisson=0.25, density=2500.0)
GROUT = ym.ElasticMat(young=2.5e9, poisson=0.30, density=2000.0)


def p_modulus(m):
    return m.young * (1 - m.poisson) / ((1 + m.poisson) * (1 - 2 * m.poisson))


def layered_bar(l=0.01, first=ROCK, second=GROUT):
    h = H_CELLS * l
    s = ym.make_solver((0, 0), (L1 + L2, h), l, margin=2)
    ym.add_region(s, first, (0, 0), (L1, h))
    ym.add_region(s, second, (L1, 0), (L1 + L2, h))
    s.addBoundaryPlane(1, -1, 0.0, "slip")
    s.addBoundaryPlane(1, +1, h, "slip")
    return s


def test_layered_bar_transmitted_stress_and_arrival_time():
    P, ramp, l = 1e6, 20e-6, 0.01
    s = layered_bar(l)
    assert s.numMaterials == 2
    ym.apply_face_traction(s, 0, -1, 0.0, (P, 0.0))      # compression entering at x = 0
    s.tractionRampTime = ramp
    c1, c2 = (np.sqrt(p_modulus(m) / m.density) for m in (ROCK, GROUT))
    z1, z2 = ROCK.density * c1, GROUT.density * c2
    transmitted = 2 * z2 / (z1 + z2)                       # 0.643
    # Δt from the fastest material (rock), not from the soft layer or a mixed modulus/density
    assert s.waveSpeed() == pytest.approx(c1, rel=1e-12)
    xs = 1.4                                               # station in layer 2
    station = np.abs(ym.get(s, "pos")[:, 0] - xs) < 0.6 * l
    t, sig = [], []
    # until the reflection from the free far end returns to the station (L1/c1 + 3·(L2 − 0.4)... > 1.38 ms)
    while s.time < 1.3e-3:
        s.run(1)
        t.append(s.time)
        sig.append(-ym.get(s, "stress")[station, 0].mean() / P)
    t, sig = np.array(t), np.array(sig)
    plateau = sig[(t > 0.95e-3)].mean()
    assert plateau == pytest.approx(transmitted, rel=0.01)  # measured: 0.02 % off
    arrival = t[np.argmax(sig > 0.5 * transmitted)]         # half-height crossing of the front
    expected = L1 / c1 + (xs - L1) / c2 + ramp / 2
    assert arrival == pytest.approx(expected, rel=0.03)     # measured: 1 % late (front width ~ 2 cells)
    assert s.lastDt == pytest.approx(s.courant * l / (c1 + s.maxSpeed), rel=0.01)


def test_mixed_scene_one_and_two_threads_identical():
    out = []
    for threads in (1, 2):
        ym.setThreads(threads)
        s = layered_bar(0.02, rocks.granite_dpgk(), GROUT)
        ym.apply_face_traction(s, 0, -1, 0.0, (30e6, 0.0))
        s.run(40)
        out.append(np.concatenate([ym.get(s, k).ravel() for k in ("pos", "vel", "stress", "damage", "plastic_strain")]))
    ym.setThreads(2)
    assert np.array_equal(out[0], out[1])


def test_regions_keep_their_own_material_and_damage_thresholds():
    rock = rocks.granite_dpgk()
    s = ym.make_solver((0, 0), (0.4, 0.2), 0.01)
    ids_rock = ym.add_region(s, rock, (0, 0), (0.2, 0.2))
    eps0_before = s.view("eps0")[np.argsort(s.view("id"))].copy()
    ids_grout = ym.add_region(s, GROUT, (0.2, 0), (0.4, 0.1))
    mat = ym.get(s, "material")
    assert s.numMaterials == 2 and list(s._materialKinds) == [1, 0]
    assert np.all(mat[ids_rock] == 0) and np.all(mat[ids_grout] == 1)
    # the rock keeps its parameters and its particles their Eq. 37 thresholds ε_D⁰ = (V k)^(−1/m)
    assert s.material(0).toDict() == rock.toDict()
    eps0 = s.view("eps0")[np.argsort(s.view("id"))]
    v = (0.01 / 2) ** 2 * 1.0                              # V = particle area × 1 m (default thresholdVolume = "particle")
    assert np.allclose(eps0[ids_rock], (v * rock.weibullK) ** (-1 / rock.weibullM), rtol=1e-12)
    assert np.array_equal(eps0[ids_rock], eps0_before[ids_rock])
    assert np.all(eps0[ids_grout] == 0)
    # an identical material is reused, not duplicated
    more = ym.add_region(s, ym.ElasticMat(**GROUT.toDict()), (0.2, 0.1), (0.4, 0.2))
    assert s.numMaterials == 2 and np.all(ym.get(s, "material")[more] == 1)
    # cohesion only where the material is DP–GK
    c = ym.get(s, "cohesion")
    assert np.all(c[ids_rock] == rock.cohesion) and np.all(np.isnan(c[ids_grout]))
    # setMaterial would replace one of two materials: refused
    with pytest.raises(ValueError, match="setMaterial: this solver holds 2 materials"):
        s._setMaterial(GROUT)
    with pytest.raises(ValueError, match="material"):
        s._addParticles(np.array([[0.05, 0.05]]), np.array([1e-4]), np.array([0.25]), material=2)


def test_material_view_is_read_only_and_set_particle_material_gives_the_new_threshold():
    """Writing the material index through the view kept the old ε_D⁰ (a grout particle turned rock kept
    ε_D⁰ = 0, i.e. damaged at the first tension): the view is read-only, setParticleMaterial sets the index
    with the new material's Eq. 37 threshold and refuses bad input before any change."""
    rock = rocks.granite_dpgk()
    s = ym.make_solver((0, 0), (0.4, 0.2), 0.01)
    ids_rock = ym.add_region(s, rock, (0, 0), (0.2, 0.2))
    ids_grout = ym.add_region(s, GROUT, (0.2, 0), (0.4, 0.2))
    with pytest.raises(ValueError, match="read-only"):
        s.view("material")[0] = 1
    slot = np.argsort(s.view("id"))                        # slot of particle id
    g, r = slot[ids_grout[:5]], slot[ids_rock[:3]]
    assert np.all(s.view("eps0")[g] == 0)
    s.setParticleMaterial(g, 0)                            # grout → rock
    v = (0.01 / 2) ** 2 * 1.0                              # V = particle area × 1 m (default thresholdVolume = "particle")
    assert np.all(s.view("material")[g] == 0)
    assert np.allclose(s.view("eps0")[g], (v * rock.weibullK) ** (-1 / rock.weibullM), rtol=1e-12)
    s.setParticleMaterial(r, 1)                            # rock → grout: no damage threshold
    assert np.all(s.view("material")[r] == 1) and np.all(s.view("eps0")[r] == 0)
    weak = s._addMaterial(rocks.granite_dpgk(weibullK=1.0))  # V·k < 1: ε_D⁰ > 1, damage could never start
    before = (s.view("material").copy(), s.view("eps0").copy())
    for args, msg in (((r, weak), r"damage threshold eps0 .* outside the allowed range \(0, 1\)"),
                      ((r, 3), r"material = 3 is not a material index of this solver: allowed range \[0, 2\]"),
                      (([s.numParticles], 0), rf"particle index {s.numParticles} is outside the allowed range"),
                      (([-1], 0), "particle index -1 is negative"),
                      (([0.5], 0), "setParticleMaterial: indices must be a 1-D array of integer particle slots")):
        with pytest.raises(ValueError, match=msg):
            s.setParticleMaterial(*args)
    assert np.array_equal(s.view("material"), before[0]) and np.array_equal(s.view("eps0"), before[1])
    s.run(1)


def test_one_material_scene_runs_the_single_material_path():
    """A one-material scene has one material and every particle index 0 (the compile-time path)."""
    s = ym.make_solver((0, 0), (0.2, 0.2), 0.01)
    ym.add_region(s, GROUT, (0, 0), (0.2, 0.1))
    ym.add_region(s, GROUT, (0, 0.1), (0.2, 0.2))
    assert s.numMaterials == 1 and np.all(s.view("material") == 0)
    s._setMaterial(ROCK)                                     # old scripts: replaces the only material
    assert s.material(0).toDict() == ROCK.toDict()
    assert s.waveSpeed() == pytest.approx(np.sqrt(p_modulus(ROCK) / GROUT.density), rel=1e-12)
