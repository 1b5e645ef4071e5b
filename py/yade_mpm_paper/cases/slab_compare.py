"""The 3D slab against 2D plane strain (issue 22, item 4; doc/validation/three_d.md): the uniaxial flaw specimen of
``uniaxial_flaw`` run once in 2D and once as a slab between slip planes (``slab_cells``), and the numbers
that compare their stress–strain curves. Written once for scripts/paper/uniaxial_flaw_3d.py and the tests."""
import numpy as np

from .uniaxial_results import peak_and_modulus

SMOOTH_TRAVEL = 1e-5     # window of the running mean of a curve [m of platen travel] (the tunnel's 0.01 mm)


def smooth(eps, sig, height, travel=SMOOTH_TRAVEL):
    """The stress averaged over every `travel` [m] of platen travel (strain bins of travel/height [-]):
    (bin-centre strains, mean stresses). The per-step reaction of the penalty contact rings at the step
    frequency; the bins average that ringing out, as the tunnel's curves do (doc/developer/scaling.md)."""
    eps, sig = np.asarray(eps, float), np.asarray(sig, float)
    k = np.floor(eps / (travel / height)).astype(int)
    keep = k >= 0
    k, e, s = k[keep], eps[keep], sig[keep]
    n = np.bincount(k)
    ok = n > 0
    return (np.bincount(k, e)[ok] / n[ok], np.bincount(k, s)[ok] / n[ok])


def compare(c2, c3, height, upto=1.0):
    """Compare the 3D slab's curve c3 with the 2D curve c2, each (strain [-], stress [Pa]) per step:
      E_2d, E_3d          Young's modulus [Pa] of each raw curve (peak_and_modulus: 10–40 % of its peak),
      E_rel               E_3d / E_2d − 1,
      peak_2d, peak_3d    peak stress [Pa] and strain_at_peak_2d/3d [-] of the raw curves,
      prepeak_max_rel     max |σ3 − σ2| / σ_peak,2d over the smoothed curves (``smooth``) at the 2D's bins up to
                          `upto` × the 2D strain at peak (σ3 interpolated linearly at the 2D bin strains),
      prepeak_max_rel_local  the same divided by the local σ2 (bins with σ2 > 10 % of the 2D peak),
      prepeak_at          strain [-] of the largest deviation."""
    e2, s2 = (np.asarray(a, float) for a in c2)
    e3, s3 = (np.asarray(a, float) for a in c3)
    k2, E2 = peak_and_modulus(e2, s2)
    k3, E3 = peak_and_modulus(e3, s3)
    b2, m2 = smooth(e2, s2, height)
    b3, m3 = smooth(e3, s3, height)
    sel = (b2 <= upto * e2[k2]) & (b2 >= b3.min()) & (b2 <= b3.max())
    d = np.interp(b2[sel], b3, m3) - m2[sel]
    j = int(np.argmax(np.abs(d)))
    big = m2[sel] > 0.1 * s2[k2]
    return dict(E_2d=float(E2), E_3d=float(E3), E_rel=float(E3 / E2 - 1), peak_2d=float(s2[k2]), peak_3d=float(s3[k3]),
                peak_rel=float(s3[k3] / s2[k2] - 1), strain_at_peak_2d=float(e2[k2]), strain_at_peak_3d=float(e3[k3]),
                prepeak_max_rel=float(np.abs(d).max() / s2[k2]), prepeak_at=float(b2[sel][j]),
                prepeak_max_rel_local=float(np.max(np.abs(d[big]) / m2[sel][big])) if big.any() else float("nan"),
                prepeak_bins=int(sel.sum()))
