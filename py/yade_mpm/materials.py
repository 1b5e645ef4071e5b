"""Materials, named and parametrised the way YADE names its materials (``FrictMat``, ``JCFpmMat``).

Every parameter is declared once, in ``pkg-mpm/material/MaterialParams.hpp`` (name, type, default, unit,
range, doc, paper equation). The classes below are generated from that table in the C++ binding:

- keyword constructors, e.g. ``DpGkMat(young=..., poisson=..., ...)``: unknown names raise
  ``TypeError``; a wrong type or a value outside its range raises ``ValueError`` naming the parameter,
  its unit and its allowed range; the result is validated (required parameters set, ψ ≤ φ, ...);
- one property per parameter, with the same checks on assignment and the declaration as docstring;
- ``mat.toDict()`` and ``DpGkMat.fromDict(d)`` (exact round trip, for checkpoints);
- ``DpGkMat.paramTable()``: the declarations themselves (used by :func:`describe`).

Angles are in radians, as everywhere in YADE (use ``math.radians``). ``dilatancyAngle`` (the paper's
word) is an alias of ``dilationAngle`` (YADE's word, cf. ``JCFpmMat.jointDilationAngle``).
"""
from ._core import ElasticMat, DpGkMat
from ._core import dpgkPointUpdate2D, dpgkPointUpdate3D, dpgkFlawThresholds, dpgkThresholdScale  # noqa: F401  (the DP–GK point update alone, for tests and studies)

__all__ = ["ElasticMat", "DpGkMat", "describe", "markdown_table", "dpgkPointUpdate2D", "dpgkPointUpdate3D", "dpgkFlawThresholds",
           "dpgkThresholdScale"]


def describe(cls):
    """Table of the parameters of a material class as text (name, unit, range, default, equation)."""
    return "\n".join(f"{p['name']:18s} {p['describe']}" for p in cls.paramTable())


def markdown_table(cls):
    """The parameter table of a class (materials, ``ContactParams``) as Markdown, as doc/ pastes it
    (tests check the docs against it): name, symbol, unit, range or choices, default, meaning, equation."""
    def rng(p):
        if p["type"] == "bool":
            return "True / False"
        if p["type"] == "choice":
            return " / ".join(f"'{w}'" for w in p["choices"])
        def num(x):
            return "inf" if x == float("inf") else "-inf" if x == -float("inf") else f"{x:g}"
        return ("(" if p["loOpen"] else "[") + num(p["lo"]) + ", " + num(p["hi"]) + (")" if p["hiOpen"] else "]")

    def default(p):
        d = p["default"]
        return "required" if d is None else repr(bool(d)) if p["type"] == "bool" else f"'{d}'" if p["type"] == "choice" else f"{d:g}"
    rows = ["| name | symbol | unit | range | default | meaning | paper |", "|---|---|---|---|---|---|---|"]
    rows += [f"| `{p['name']}` | {p['symbol']} | {p['unit']} | {rng(p)} | {default(p)} | {p['doc']} | {p['eq']} |"
             for p in cls.paramTable()]
    return "\n".join(rows)
