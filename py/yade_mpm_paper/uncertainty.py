"""Numerical uncertainty of the reference results: how a number moves with the grid spacing, the time step and
where the grid cuts the scene.

Grid shifts: an ensemble of runs that differ only in the sub-cell position of the grid against the scene
(``yade_mpm.make_solver``'s `shift`). A slip plane must lie on a node line or halfway between two, so an
axis bounded by slip planes takes the shifts 0 and ½ only; a free axis takes any fraction.

Convergence: for a sequence of results q₁, q₂, q₃ at spacings h, h/r, h/r², the observed order
p = ln((q₁ − q₂)/(q₂ − q₃)) / ln r (monotone sequences only) and the Richardson estimate of the limit
q∞ = q₃ + (q₃ − q₂)/(rᵖ − 1)."""
import math
import re

import numpy as np

# Sub-cell grid shifts (fx, fy) of the ensembles, the unshifted run first (each scene's scripts/paper/*_shifts.table).
# The uniaxial specimen stands on a slip base (y = 0: fy ∈ {0, ½}) with free sides (any fx); the tunnel has slip walls
# left, right and below (fx, fy ∈ {0, ½}); the circular opening's block has no plane (any fx, fy); the line crack's
# block has slip faces at y = 0, L (fy ∈ {0, ½}).
SHIFTS = {
    "uniaxial": ((0.0, 0.0), (0.2, 0.0), (0.4, 0.5), (0.6, 0.0), (0.8, 0.5)),
    "tunnel": ((0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.5, 0.5)),   # and the grids of 74 and 76 cells across (scripts/paper/tunnel_shifts.table)
    "circular_opening": ((0.0, 0.0), (0.2, 0.6), (0.4, 0.2), (0.6, 0.8), (0.8, 0.4)),
    "penny_crack": ((0.0, 0.0), (0.2, 0.0), (0.4, 0.5), (0.6, 0.0), (0.8, 0.5)),
}


def shift_option(ap):
    """Adds --grid-shift to a script's parser (text "fx,fy"; parsed by :func:`parse_shift`)."""
    ap.add_argument("--grid-shift", default=None, metavar="FX,FY",
                    help="move the grid against the scene by these fractions of a cell, each in [0, 1) (default: none); an axis "
                         "with slip planes takes 0 or 0.5 only")


def parse_shift(text, option="--grid-shift"):
    """'fx,fy' → (fx, fy) floats in [0, 1), or None for None/''; ValueError naming the option otherwise."""
    if text in (None, ""):
        return None
    try:
        f = tuple(float(x) for x in str(text).split(","))
    except ValueError:
        raise ValueError(f"{option} = {text!r}: expected two numbers 'fx,fy'") from None
    if len(f) != 2 or not all(0.0 <= x < 1.0 for x in f):
        raise ValueError(f"{option} = {text!r}: expected two fractions of a cell 'fx,fy', each in [0, 1)")
    return None if f == (0.0, 0.0) else f


def shift_name(shift):
    """Folder name of a shift: s0.00_0.00."""
    fx, fy = shift or (0.0, 0.0)
    return f"s{fx:.2f}_{fy:.2f}"


def spread(values):
    """mean, min, max, coefficient of variation (std/|mean|, population) and n of the finite values; None if none."""
    v = np.asarray([x for x in values if x is not None and np.isfinite(x)], float)
    if v.size == 0:
        return None
    m = float(v.mean())
    cv = float(v.std() / abs(m)) if m != 0 and v.size > 1 else 0.0
    return dict(mean=m, min=float(v.min()), max=float(v.max()), cv=cv, n=int(v.size))


def observed_order(h, e):
    """Orders between successive points of an error sequence e(h): ln(e_i/e_{i+1}) / ln(h_i/h_{i+1}) (None where
    an error is zero or the sign changes)."""
    out = []
    for (h1, e1), (h2, e2) in zip(zip(h, e), zip(h[1:], e[1:])):
        ok = e1 and e2 and e1 * e2 > 0 and h1 != h2
        out.append(math.log(abs(e1 / e2)) / math.log(h1 / h2) if ok else None)
    return out


MIN_ORDER = 0.5   # smallest observed order extrapolated: below it the changes barely shrink and q∞ runs away


def richardson(h, q):
    """Richardson extrapolation of the last three results of q(h) (h decreasing by a constant ratio r):
    dict(order p, limit q∞, monotone) — p and q∞ None unless the sequence is monotone and converging (each
    change smaller than the last; no extrapolation then); q∞ None also when p < MIN_ORDER (the elastic tunnel at
    C = 0.5, 53.02 / 52.78 / 52.54 MPa, has p = 0.05 and would extrapolate to 45.3 MPa)."""
    if len(q) < 3:
        return dict(order=None, limit=None, monotone=False)
    (h1, h2, h3), (q1, q2, q3) = h[-3:], q[-3:]
    r = h1 / h2
    if not (abs(h2 / h3 - r) < 1e-6 * r and r > 1):
        raise ValueError(f"richardson: spacings {h[-3:]} do not fall by a constant ratio")
    d1, d2 = q1 - q2, q2 - q3
    if d1 == 0 or d2 == 0 or d1 * d2 < 0 or abs(d2) >= abs(d1):
        return dict(order=None, limit=None, monotone=d1 * d2 > 0)
    p = math.log(d1 / d2) / math.log(r)
    return dict(order=p, limit=q3 + (q3 - q2) / (r ** p - 1) if p >= MIN_ORDER else None, monotone=True)


# ------------------------------------------------------------------------- verdicts and numbers over an ensemble
NUMBER = re.compile(r"(?<![\w.])([-+−]?\d+(?:\.\d+)?(?:e[-+]?\d+)?)")


def merge_texts(texts):
    """The measured text of one fidelity row over an ensemble (the unshifted run first): where every run's text has
    the same words, each number that differs between the runs becomes "v [min–max]" (v: the first run's); otherwise
    the first run's text and how many of the runs read differently."""
    texts = [t for t in texts if t is not None]
    if not texts:
        return None
    parts = [NUMBER.split(t) for t in texts]
    if any(len(p) != len(parts[0]) or p[0::2] != parts[0][0::2] for p in parts[1:]):
        n = sum(1 for t in texts[1:] if t != texts[0])
        return f"{texts[0]} [the words differ in {n} of the {len(texts) - 1} shifted runs]"
    out = list(parts[0])
    for i in range(1, len(out), 2):
        vals = [float(p[i].replace("−", "-")) for p in parts]
        if max(vals) != min(vals):
            out[i] = f"{parts[0][i]} [{_short(min(vals))}–{_short(max(vals))}]"
    return "".join(out)


def _short(v):
    return f"{v:.4g}"


def combined_verdict(verdicts):
    """The rule of the fidelity table's verdict over an ensemble: a verdict (agrees, partly, differs, ...) holds when
    every run gives it; when the runs give different verdicts the row reads "within uncertainty" with the counts."""
    vs = [v.split(":")[0] for v in verdicts if v is not None]
    if not vs:
        return "not run"
    if all(v == vs[0] for v in vs):
        return verdicts[0]
    counts = {}
    for v in vs:
        counts[v] = counts.get(v, 0) + 1
    return "within uncertainty (" + ", ".join(f"{k} {n}" for k, n in sorted(counts.items(), key=lambda kv: -kv[1])) + f" of {len(vs)})"
