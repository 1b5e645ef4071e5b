"""Named rock parameter sets, each written once here with its source; scripts, tests and benchmarks
import them instead of repeating the numbers.

Raw dicts (keyword arguments of ``ElasticMat`` / ``DpGkMat``; SI units, angles in radians):

=====================  ==========================================================================
``GRANITE``            elastic rock of the circular opening, paper Sec. 3.1 (granite-like):
                       E = 22.41 GPa, ν = 0.2313, ρ = 2500 kg/m³
``GRANITE_DPGK``       the same rock with the plasticity and damage of the penny-shaped crack,
                       paper Sec. 3.2: φ = 32.5°, ψ (dilationAngle) = 8.125°, c₀ = 24.8 MPa, ε̄p,crit = 0.1,
                       k = 1.1798e29 m⁻³, m = 7.5
``RAYMOND2019_DAMAGE`` damage parameters of Raymond et al. (2019), used by the paper in Secs. 3.3
                       and 4: ε̄p,crit = 0.1, k = 7.0e35 m⁻³, m = 9.0
``MIAO2018_SANDSTONE`` sandstone of the uniaxial tests of Miao et al. (2018), paper Sec. 3.3:
                       E = 9.87 GPa, ν = 0.22, ρ = 2520 kg/m³, φ = 38°, ψ = 9.5°, c₀ = 13 MPa,
                       with ``RAYMOND2019_DAMAGE``
``PAN2020_SANDSTONE``  sandstone of the tunnel tests of Pan et al. (2020b), paper Sec. 4:
                       E = 18.4 GPa, ν = 0.12, ρ = 2364 kg/m³, φ = 39°, ψ = 9.75°, c₀ = 25 MPa,
                       with ``RAYMOND2019_DAMAGE``
``CEMENT_GROUT``       hardened cement grout (w/c = 1 by weight), elastic, for the grout-filled flaw
                       of the tunnel (beyond the paper): E = 10.8 GPa (secant E50), ν = 0.22,
                       ρ = 1500 kg/m³ — Zhu, Zhang, Zhang & Hui (2018), Comparative study of soil
                       grouting with cement slurry and cement–sodium silicate slurry, Adv. Mater. Sci.
                       Eng. 2018:1893195, doi:10.1155/2018/1893195, Table 3 (UCS 5.9 MPa)
=====================  ==========================================================================

Material constructors (keyword overrides replace single values, e.g. ``pan2020_sandstone(damage=False)``;
unknown names and out-of-range values raise before any work):
``granite()``, ``cement_grout()`` (ElasticMat), ``granite_dpgk()``, ``miao2018_sandstone()``, ``pan2020_sandstone()`` (DpGkMat),
and ``elastic(params)`` for the elastic part of any set.
"""
import math

from .materials import DpGkMat, ElasticMat

ELASTIC_KEYS = ("young", "poisson", "density")

# Paper Sec. 3.1 (circular opening; also the elastic part of Sec. 3.2)
GRANITE = dict(young=22.41e9, poisson=0.2313, density=2500.0)

# Paper Sec. 3.2 (penny-shaped crack): plasticity and damage of the same rock
GRANITE_DPGK = dict(GRANITE, frictionAngle=math.radians(32.5), dilationAngle=math.radians(8.125), cohesion=24.8e6,
                    critPlasticStrain=0.1, weibullK=1.1798e29, weibullM=7.5)

# Raymond et al. (2019), used by the paper for both sandstones (Secs. 3.3 and 4)
RAYMOND2019_DAMAGE = dict(critPlasticStrain=0.1, weibullK=7.0e35, weibullM=9.0)

# Miao et al. (2018), paper Sec. 3.3 (uniaxial compression with a flaw)
MIAO2018_SANDSTONE = dict(young=9.87e9, poisson=0.22, density=2520.0, frictionAngle=math.radians(38.0),
                          dilationAngle=math.radians(9.5), cohesion=13.0e6, **RAYMOND2019_DAMAGE)

# Pan et al. (2020b), paper Sec. 4 (arch-shaped tunnel)
PAN2020_SANDSTONE = dict(young=18.4e9, poisson=0.12, density=2364.0, frictionAngle=math.radians(39.0),
                         dilationAngle=math.radians(9.75), cohesion=25.0e6, **RAYMOND2019_DAMAGE)

# Zhu et al. (2018), Table 3: hardened cement slurry, w/c = 1 (the grout-filled flaw of the tunnel)
CEMENT_GROUT = dict(young=10.8e9, poisson=0.22, density=1500.0)

SETS = {
    "granite": (GRANITE, "paper Sec. 3.1, circular opening (elastic)"),
    "granite_dpgk": (GRANITE_DPGK, "paper Sec. 3.2, penny-shaped crack (DP-GK)"),
    "miao2018_sandstone": (MIAO2018_SANDSTONE, "Miao et al. 2018 / Raymond et al. 2019, paper Sec. 3.3 (DP-GK)"),
    "pan2020_sandstone": (PAN2020_SANDSTONE, "Pan et al. 2020b / Raymond et al. 2019, paper Sec. 4 (DP-GK)"),
    "cement_grout": (CEMENT_GROUT, "Zhu et al. 2018, hardened cement grout w/c = 1 (elastic), tunnel grout_flaw"),
}


def elastic(params, **overrides):
    """ElasticMat from the elastic part (E, ν, ρ) of a parameter set, e.g. ``elastic(PAN2020_SANDSTONE)``."""
    return ElasticMat(**dict({k: params[k] for k in ELASTIC_KEYS}, **overrides))


def granite(**overrides):
    """Elastic rock of the circular opening, paper Sec. 3.1 (ElasticMat)."""
    return ElasticMat(**dict(GRANITE, **overrides))


def granite_dpgk(**overrides):
    """DP–GK rock of the penny-shaped crack, paper Sec. 3.2 (DpGkMat)."""
    return DpGkMat(**dict(GRANITE_DPGK, **overrides))


def miao2018_sandstone(**overrides):
    """Sandstone of Miao et al. 2018 with Raymond et al. 2019 damage, paper Sec. 3.3 (DpGkMat)."""
    return DpGkMat(**dict(MIAO2018_SANDSTONE, **overrides))


def pan2020_sandstone(**overrides):
    """Sandstone of Pan et al. 2020b with Raymond et al. 2019 damage, paper Sec. 4 (DpGkMat)."""
    return DpGkMat(**dict(PAN2020_SANDSTONE, **overrides))


def cement_grout(**overrides):
    """Hardened cement grout of Zhu et al. 2018 (ElasticMat), the filling of the tunnel's grout_flaw case."""
    return ElasticMat(**dict(CEMENT_GROUT, **overrides))
