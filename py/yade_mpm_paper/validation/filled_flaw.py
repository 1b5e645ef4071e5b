"""The elastic uniaxial specimen with the paper's flaw (Sec. 3.3 geometry, Miao 2018 elasticity, no plasticity or
damage), open or filled by the free rigid YADE filler, pressed quasi-statically by the rigid platen: its apparent
modulus, to set against the plane-strain FEM of the same specimen (``fem_flaw``). A rigid filler in frictional
contact must lie between the FEM's open and bonded values; one whose cohesion never lets it slip must equal the
bonded value as the grid is refined (doc/validation/uniaxial_flaw.md; scripts/paper/filled_flaw_elastic.py)."""
import math
import time

import yade_mpm as ym
from yade_mpm import rocks

from .. import cases
from . import fem_flaw

STRAIN = 1e-4  # platen strain of the test [-]
# run: (flaw variant, μ_con [-], c_con [Pa]); c_con = 1e9 Pa: the filler never slips
RUNS = {"intact": ("intact", 0.0, 0.0), "open": ("open", 0.0, 0.0), "filled μ 0.6": ("filled", 0.6, 0.0),
        "filled, never slips": ("filled", 0.6, 1e9)}


def plane_strain_modulus():
    """E/(1 − ν²) of the Miao 2018 sandstone [Pa]."""
    m = rocks.MIAO2018_SANDSTONE
    return m["young"] / (1 - m["poisson"] ** 2)


def fem_modulus(kind, h):
    """Apparent modulus of the same specimen by the plane-strain FEM (``fem_flaw``): kind 'open', 'bonded' or
    'intact', mesh size h [m] [Pa]."""
    m = rocks.MIAO2018_SANDSTONE
    return fem_flaw.apparent_modulus(kind, cases.UNIAXIAL_WIDTH, cases.UNIAXIAL_HEIGHT, cases.uniaxial_flaw_geometry()["polygon"],
                                     m["young"], m["poisson"], h)[0]


def mpm_modulus(name, spacing, courant):
    """One MPM run (a YADE scene: O is reset): platen down at 0.1 m/s to a strain of 1e-4, then held with local
    damping 0.5 until the platen force changes by less than 1e-5 of itself over one P-wave transit of the
    specimen. Modulus two ways: platen force / width over platen travel / height, and over the specimen's own strain
    (mean displacement of the top particle row against the bottom row) [Pa]."""
    from yade import O
    from yade.minieigenHP import Vector3
    variant, mu, c = RUNS[name]
    m = rocks.MIAO2018_SANDSTONE
    rock = ym.ElasticMat(young=m["young"], poisson=m["poisson"], density=m["density"])
    s, sc = cases.uniaxial_flaw(variant, spacing, mu_con=mu, c_con=c, material=rock, label="mpm_elastic")
    s.courant = courant
    H = sc["height"]
    y0 = ym.get(s, "pos")[:, 1]
    top, bot = y0 > y0.max() - 1e-9, y0 < y0.min() + 1e-9
    t0 = time.time()
    while sc["axial_strain"]() < STRAIN:
        O.step()
    O.bodies[sc["platen"]].state.vel = Vector3(0, 0, 0)
    s.damping = 0.5
    c_p = math.sqrt(m["young"] * (1 - m["poisson"]) / ((1 + m["poisson"]) * (1 - 2 * m["poisson"]) * m["density"]))
    transit, last, settled = H / c_p, None, False
    while O.time < 0.01:
        t_end = O.time + transit
        while O.time < t_end:
            O.step()
        f = sc["axial_stress"]()
        if last is not None and abs(f - last) < 1e-5 * abs(f):
            settled = True
            break
        last = f
    y = ym.get(s, "pos")[:, 1]
    own = ((y0[top] - y[top]).mean() - (y0[bot] - y[bot]).mean()) / (y0[top].mean() - y0[bot].mean())
    sig = sc["axial_stress"]()
    return dict(run=name, spacing_m=spacing, courant=courant, platen_modulus_Pa=sig / sc["axial_strain"](),
                own_modulus_Pa=sig / own, settled=settled, steps=int(s.steps), particles=int(s.numParticles), wall_s=time.time() - t0)
