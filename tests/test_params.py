"""The one-declaration parameter tables: every Python-visible parameter documents its unit and range,
setters check type and range, keyword constructors refuse unknown names, toDict/fromDict round-trip."""
import json
import math
import re

import pytest
import yade_mpm as ym

ROCK = ym.rocks.GRANITE_DPGK                                       # the paper's Sec. 3.2 rock
UNIT = re.compile(r"\[[^\]]+\]")                                    # "[Pa]", "[-]", "[kg/m³]"
RANGE = re.compile(r"range [\[(][^,]+, [^\])]+[\])]|True or False|one of '")  # "range (0, inf)", bools, named options


def _public_attributes(cls):
    """Data attributes a user sees on the class (properties), without methods and dunders."""
    return sorted(n for n in dir(cls) if not n.startswith("_") and isinstance(getattr(cls, n), property))


@pytest.mark.parametrize("cls", [ym.ElasticMat, ym.DpGkMat])
def test_every_visible_attribute_has_unit_and_range(cls):
    attrs = _public_attributes(cls)
    declared = {p["name"] for p in cls.paramTable()}
    # Python-visible properties are exactly the declared parameters (+ aliases, documented as such).
    aliases = {n for n in attrs if (getattr(cls, n).__doc__ or "").startswith("alias of ")}
    assert set(attrs) - aliases == declared
    for n in attrs:
        doc = getattr(cls, n).__doc__ or ""
        if n in aliases:
            target = doc.split()[-1]
            assert target in declared, n
            doc = getattr(cls, target).__doc__
        assert UNIT.search(doc), f"{cls.__name__}.{n}: no unit in {doc!r}"
        assert RANGE.search(doc), f"{cls.__name__}.{n}: no range in {doc!r}"
        assert n in cls.__doc__


def test_declared_ranges_are_enforced_at_the_ends():
    """Each numeric parameter: the open end is refused, the closed end accepted, on assignment."""
    for p in ym.DpGkMat.paramTable():
        if p["type"] not in ("float", "int"):
            continue
        m = ym.DpGkMat(**ROCK)
        for end, is_open in ((p["lo"], p["loOpen"]), (p["hi"], p["hiOpen"])):
            if math.isinf(end):
                continue
            val = int(end) if p["type"] == "int" else end
            if is_open:
                with pytest.raises(ValueError, match=re.escape(p["name"]) + ".*outside the allowed range"):
                    setattr(m, p["name"], val)
            else:
                setattr(m, p["name"], val)                  # the closed end is accepted


def test_round_trip_and_alias():
    m = ym.DpGkMat(**dict(ROCK, crackSpeed=1234.5, growthLaw="as-printed", residualCohesion=0.25))
    d = m.toDict()
    assert d["dilationAngle"] == ROCK["dilationAngle"] and "dilatancyAngle" not in d
    back = ym.DpGkMat.fromDict(json.loads(json.dumps(d)))     # through JSON, as a checkpoint is
    assert back.toDict() == d
    assert back.crackSpeed == 1234.5 and back.growthLaw == "as-printed" and back.residualCohesion == 0.25
    # alias: the paper's name writes the same field
    a = ym.DpGkMat(**{k: v for k, v in ROCK.items() if k != "dilationAngle"}, dilatancyAngle=0.1)
    assert a.dilationAngle == 0.1 and a.dilatancyAngle == 0.1
    # optional parameters of a switched-off part round-trip as None (unset), not as NaN
    e = ym.DpGkMat(young=1e9, poisson=0.2, density=2000.0, plasticity=False, damage=False)
    de = e.toDict()
    assert de["cohesion"] is None and de["weibullK"] is None
    assert ym.DpGkMat.fromDict(json.loads(json.dumps(de))).toDict() == de
    # solver hands back the material it was given
    s = ym.Solver2D((0, 0), 0.1, (4, 4))
    s._setMaterial(m)
    assert s.material(0).toDict() == d


@pytest.mark.parametrize("name, value, msg", [
    ("young", "a", r"DpGkMat.young must be a number \[Pa\] in \(0, inf\)"),
    ("young", None, r"young .*required"),
    ("poisson", [0.2], r"DpGkMat.poisson must be a number"),
    ("plasticity", 2, r"DpGkMat.plasticity must be True or False"),
    ("growthLaw", 0.5, r"DpGkMat.growthLaw must be one of 'benz-asphaug' or 'as-printed' \(got float 0.5\)"),
    ("growthLaw", 1, r"DpGkMat.growthLaw must be one of .*integer codes were replaced by these words"),
    ("thresholdVolume", "area", r"DpGkMat.thresholdVolume must be one of 'particle', 'cube' or 'cell' \(got str area\)"),
    ("weibullM", 1e-300, r"weibullM = 1e-300 \[-\] is outside the allowed range \[1, 50\]"),
    ("frictionAngle", math.nan, r"frictionAngle = nan \[rad\] is outside"),
    ("cohesion", math.inf, r"cohesion = inf \[Pa\] is outside"),
])
def test_setter_refuses_wrong_type_and_range(name, value, msg):
    m = ym.DpGkMat(**ROCK)
    before = m.toDict()
    with pytest.raises(ValueError, match=msg):
        setattr(m, name, value)
        m.validate()
    assert m.toDict() == before or value is None


def test_constructor_refuses_unknown_and_positional():
    with pytest.raises(TypeError, match="unknown parameter 'friction'.*frictionAngle"):
        ym.DpGkMat(**ROCK, friction=0.5)
    with pytest.raises(ValueError, match="keyword arguments only"):
        ym.ElasticMat(1e9, 0.2, 2500.0)
    with pytest.raises(ValueError, match=r"young \[Pa\] is required"):
        ym.ElasticMat(poisson=0.2, density=2500.0)
    with pytest.raises(ValueError, match="cohesion .*required .*plasticity"):
        ym.DpGkMat(**{k: v for k, v in ROCK.items() if k != "cohesion"})
    # without plasticity the DP parameters are not needed
    ym.DpGkMat(**{k: v for k, v in ROCK.items() if k not in ("cohesion", "frictionAngle")}, plasticity=False)


def test_weibull_modulus_outside_physical_range_refused():
    """weibullM = 1e-300 used to pass and give ε_D⁰ = (Vk)^(−1/m) = 0: damage from the first step."""
    m = ym.DpGkMat(**ROCK)
    assert m.activationStrain(4e-4) == pytest.approx(3.77e-4, rel=2e-3)  # paper's k, m; V = (2 cm)²·1 m (Eq. 37 by hand)
    with pytest.raises(ValueError, match=r"weibullM = 1e-300 \[-\] is outside the allowed range \[1, 50\]"):
        ym.DpGkMat(**dict(ROCK, weibullM=1e-300))


@pytest.mark.parametrize("cls", [ym.Solver2D, ym.Solver3D])
def test_every_writable_solver_attribute_is_declared_with_unit_and_range(cls):
    """Settings and writable state (SolverSettings.hpp): every property a script can assign is declared
    once and documents its unit and range; no raw writable field is left (time, externalWork, autoDt …)."""
    writable = sorted(n for n in dir(cls) if not n.startswith("_") and isinstance(getattr(cls, n), property)
                      and getattr(cls, n).fset is not None)
    assert {"gravity", "damping", "courant", "autoDt", "fixedDt", "tractionRampTime", "sortPeriod", "trackEnergy",
            "time", "externalWork"} <= set(writable)
    for n in writable:
        doc = getattr(cls, n).__doc__ or ""
        assert UNIT.search(doc) and RANGE.search(doc), f"{cls.__name__}.{n}: {doc!r}"


@pytest.mark.parametrize("name, value, msg", [
    ("time", -1.0, r"Solver2D.time = -1 \[s\] is outside the allowed range \[0, inf\)"),   # reversed ramped tractions
    ("time", math.nan, r"Solver2D.time = nan \[s\] is outside"),                          # ran on with NaN time
    ("externalWork", math.inf, r"Solver2D.externalWork = inf \[J\] is outside"),
    ("autoDt", "yes", r"Solver2D.autoDt must be True or False \(got str"),                # Boost ArgumentError
    ("damping", "a", r"Solver2D.damping must be a number \[-\] in \[0, 1\)"),
    ("sortPeriod", 10 ** 20, r"Solver2D.sortPeriod = 100000000000000000000 is outside the allowed range \[1, 1000000000\]"),
    ("gravity", (0, math.nan), r"Solver2D.gravity\[1\] = nan \[m/s²\] is outside"),
])
def test_solver_settings_and_state_checked(name, value, msg):
    s = ym.make_solver((0, 0), (1, 1), 0.1)
    before = s.settings()
    with pytest.raises(ValueError, match=msg):
        setattr(s, name, value)
    assert s.settings() == before and s.time == 0


def test_solver_settings_round_trip_all_or_nothing():
    s = ym.make_solver((0, 0), (1, 1), 0.1)
    new = dict(s.settings(), damping=0.3, courant=0.25, gravity=(0.0, -9.81), autoDt=False, fixedDt=1e-6, sortPeriod=7)
    s.setSettings(new)
    t = ym.make_solver((0, 0), (1, 1), 0.1)
    t.setSettings(json.loads(json.dumps(s.settings())))      # through JSON, as a checkpoint is
    assert t.settings() == dict(new, gravity=(0.0, -9.81))
    with pytest.raises(ValueError, match=r"courant = 2 \[-\] is outside the allowed range \(0, 1\]"):
        t.setSettings({"damping": 0.1, "courant": 2.0})
    assert t.damping == 0.3                                     # the valid part was not applied either
    with pytest.raises(ValueError, match="unknown setting 'dampng'"):
        t.setSettings({"dampng": 0.1})


def test_check_setting_uses_the_declared_range():
    """Scripts check options against the solver's declaration instead of repeating the range."""
    assert ym.scene.check_setting("damping", 0.5) == 0.5
    with pytest.raises(ValueError, match=r"^--damping = 1 \[-\] is outside the allowed range \[0, 1\)"):
        ym.scene.check_setting("damping", 1.0, "--damping")
    with pytest.raises(ValueError, match=r"courant = 0 \[-\] is outside the allowed range \(0, 1\]"):
        ym.scene.check_setting("courant", 0.0)
    with pytest.raises(ValueError, match="unknown solver setting 'dampng'"):
        ym.scene.check_setting("dampng", 0.5)
