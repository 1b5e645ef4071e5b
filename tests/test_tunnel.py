"""The arch-tunnel scene of paper Sec. 4 (yade_mpm_paper.cases.arch_tunnel) on a coarse grid: the flaw cut,
the rigid filler fitting it without touching a particle, the grout filling it; the platen's first
stress is the 1D impact stress ρ c_p v (plane strain, slip walls) until the wave returns from the
opening; the intact scene stays mirror symmetric; a filled-flaw run resumes bitwise from a checkpoint."""
import math

import numpy as np
import pytest
import yade_mpm as ym
from yade_mpm.fields import views
from yade_mpm import analysis, checkpoint, rocks
from yade_mpm_paper import cases

yade = pytest.importorskip("yade")
pytest.importorskip("yade_mpm.bodies")   # rigid-body contact (platen, filler)
L = 0.0025                        # coarsest grid the 2 mm flaw allows (two particle rows)


def test_flaw_cut_filler_and_grout():
    s_int, _ = cases.arch_tunnel("intact", L)
    n_int = s_int.numParticles
    s, b = cases.arch_tunnel("filled_flaw", L)
    f, dp = b["flaw"], L / 2
    assert (n_int - s.numParticles) * dp ** 2 == pytest.approx(f["length"] * f["width"], rel=0.2)
    assert np.allclose(f["toe"], (0.045, 0.08)) and f["angle"] == pytest.approx(math.radians(60))
    # the filler is the flaw (the domain of the filling), over no particle centre; registered with
    # d0 = "initial": the particles within one lattice layer of it touch it at their initial distance
    from yade import O
    box = O.bodies[b["filler"]]
    hl, hw = box.shape.extents[0], box.shape.extents[1]
    assert hl == pytest.approx(f["length"] / 2, abs=1e-15) and hw == pytest.approx(f["width"] / 2, abs=1e-15)
    r = ym.get(s, "pos") - f["center"]
    along, across = np.abs(r @ f["direction"]), np.abs(r @ f["normal"])
    gap = np.hypot(np.maximum(along - hl, 0), np.maximum(across - hw, 0))
    assert gap.min() >= 0 and np.all((along > hl) | (across > hw))
    d0 = b["rigid"].initial_d0(b["rigid"].groups[-1])
    face = (along < hl - dp) & (gap < dp * np.abs(f["normal"]).max())      # first layer along the long faces
    assert face.sum() > 2 * 0.9 * f["length"] * np.abs(f["normal"]).max() / dp
    np.testing.assert_allclose(d0[face], gap[face], atol=1e-12)
    O.step()
    assert np.all(b["rigid"].force(b["filler"]) == 0)   # in contact everywhere, at zero force
    assert b["filler"] in b["rigid"].ids and b["platen"] in b["rigid"].ids
    s_g, b_g = cases.arch_tunnel("grout_flaw", L)
    assert s_g.numParticles == n_int                 # the grout fills the cut exactly
    with pytest.raises(ValueError, match="case"):
        cases.arch_tunnel("half_flaw", L)
    with pytest.raises(ValueError, match="spacing"):
        cases.arch_tunnel("open_flaw", 0.004)     # the flaw would cut no full row of particles
    with pytest.raises(ValueError, match="spacing"):
        cases.arch_tunnel("intact", 1.5 * cases.TUNNEL_INTACT_MAX_SPACING)


@pytest.mark.parametrize("update", ["pic", "flip"])
def test_platen_impact_stress_and_symmetry(update):
    """The 1D impact stress ρ c v under the platen, for both particle velocity updates (under 'flip' the strain is
    built from the constrained grid velocity Σ ψ_i v_i, not from the particles' FLIP velocities, which gave 0.90 ρ c v)."""
    from yade import O
    s, b = cases.arch_tunnel("intact", L)
    s.velocityUpdate = update
    rb, pid, W = b["rigid"], b["platen"], b["width"]
    m = rocks.pan2020_sandstone()
    rho_c_v = m.density * m.pWaveSpeed() * cases.PLATEN_SPEED     # 1D (confined) impact stress [Pa]
    sig, t = [], []
    while s.time < 31e-6:          # the wave reaches the crown (50 mm) at 17.6 µs and is back at 35 µs
        O.step()
        if s.time > 11e-6:
            sig.append(rb.force(pid)[1] / W), t.append(s.time)
    dev = np.abs(np.array(sig) / rho_c_v - 1)
    assert np.mean(sig) == pytest.approx(rho_c_v, rel=0.01)
    # Since the positive lumping at cut stencils (issue 17) the platen reaction rings for ~5 µs after the
    # first contact: up to 6.2 % at 11–16 µs and 2.0 % at 16 µs (before: 2 % from 11 µs on), after 20 µs within 0.3 %.
    # (Cut-stencil lumping η with ψ⁺, doc/reference/algorithm.md: after 20 µs 0.67 % measured; with |ψ| instead of ψ⁺ it was 1.6 %.)
    assert np.max(dev[np.array(t) > 20e-6]) < 0.01
    assert np.max(dev) < 0.07
    lat = analysis.Lattice(ym.get(s, "pos"), L / 2, origin=(0, 0))
    assert analysis.mirror_symmetry(ym.get(s, "stress")[:, 1], lat, W / 2) > 0.999999
    assert analysis.mirror_symmetry(ym.get(s, "vel")[:, 0], lat, W / 2) < -0.999999   # v_x antisymmetric


def test_filled_flaw_resumes_bitwise(tmp_path):
    from yade import O

    def state(s, b):
        bs = [O.bodies[i].state for i in (b["platen"], b["filler"])]
        return ({k: np.array(v) for k, v in views(s).items()},
                [(tuple(x.pos), tuple(x.vel), tuple(x.ori), tuple(x.angVel)) for x in bs], (O.iter, O.time, s.time))

    N = 40
    s, b = cases.arch_tunnel("filled_flaw", L)
    O.run(N, True)
    ref = state(s, b)
    s, b = cases.arch_tunnel("filled_flaw", L)
    O.run(N // 2 + 3, True)
    checkpoint.save(tmp_path / "t.ckpt", meta={"case": "filled_flaw"})
    s, b = cases.arch_tunnel("filled_flaw", L)
    checkpoint.load(tmp_path / "t.ckpt", meta={"case": "filled_flaw"})
    O.run(N - N // 2 - 3, True)
    got = state(s, b)
    for k in ref[0]:
        np.testing.assert_array_equal(ref[0][k], got[0][k], err_msg=k)
    assert ref[1] == got[1] and ref[2] == got[2]
    s, b = cases.arch_tunnel("open_flaw", L)
    with pytest.raises(checkpoint.CheckpointError, match="another scene"):
        checkpoint.load(tmp_path / "t.ckpt")
