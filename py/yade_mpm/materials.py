"""Materials, named and parametrised the way YADE names its materials (``FrictMat``, ``JCFpmMat``).

Every attribute is declared once in the C++ core with its unit; these constructors only accept
keyword arguments, refuse unknown names and validate the values before any work is done.
Angles are in radians, as everywhere in YADE (use ``math.radians``).
"""
from . import _core

_ELASTIC_DOC = {
    "young": "Young's modulus E [Pa], > 0",
    "poisson": "Poisson's ratio ν [-], −1 < ν < 0.5",
    "density": "density ρ [kg/m³], > 0",
}
_DPGK_DOC = dict(_ELASTIC_DOC, **{
    "frictionAngle": "friction angle φ [rad], 0 ≤ φ < π/2 (Eqs. 30–31)",
    "dilatancyAngle": "dilatancy angle ψ [rad], 0 ≤ ψ ≤ φ (Eqs. 32–33)",
    "cohesion": "initial cohesion c₀ [Pa], > 0 (Eq. 34)",
    "critPlasticStrain": "critical accumulated plastic strain ε̄p,crit [-] (Eq. 34), default 0.1",
    "residualCohesion": "cohesion floor as a fraction of c₀ [-] (Eq. 34), default 0.1",
    "weibullK": "Weibull k [m⁻³] (Eqs. 37, 39)",
    "weibullM": "Weibull m [-] (Eqs. 37–39)",
    "crackSpeed": "crack growth speed c_g [m/s]; 0 (default) = 0.4 × P-wave speed (Eq. 38)",
    "growthLaw": "0 = Grady–Kipp/Benz–Asphaug dD^⅓/dt ∝ ε̄^(m/3) (default), 1 = Eq. 38 as printed ∝ ε̄^(1/3)",
    "plasticity": "Drucker–Prager return mapping on (default) / off",
    "damage": "Grady–Kipp damage on (default) / off",
})


def _build(cls, doc, kw):
    m = cls()
    for k, v in kw.items():
        if k not in doc:
            raise TypeError(f"{cls.__name__}: unknown parameter '{k}'; known: {', '.join(doc)}")
        setattr(m, k, v)
    m.validate()
    return m


def ElasticMat(**kw):
    """Linear elastic material (paper Eqs. 27–29). Parameters: """ 
    return _build(_core.ElasticMat, _ELASTIC_DOC, kw)


def DpGkMat(**kw):
    """Drucker–Prager plasticity + Grady–Kipp damage rock (paper Sec. 2.4)."""
    return _build(_core.DpGkMat, _DPGK_DOC, kw)


ElasticMat.__doc__ += "; ".join(f"{k}: {v}" for k, v in _ELASTIC_DOC.items())
DpGkMat.__doc__ += " Parameters: " + "; ".join(f"{k}: {v}" for k, v in _DPGK_DOC.items())
