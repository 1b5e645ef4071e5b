"""Tunnel rows of the fidelity table (paper Figs. 17–19; ``fidelity_table.ROWS``): one measure per claim,
as a function of one grid's tunnel run ``t = dict(cases=[...], info={case: case.json})``."""
import numpy as np

from . import curve_shape
from .common import NOT_RUN, _f


# --------------------------------------------------------------------------------------------- tunnel
def _snap(t, case, key):
    return ((t["info"].get(case) or {}).get("snapshots") or {}).get(key)


def _curves(t):
    return {e["case"]: ([p["displacement_mm"] for p in e["axial_stress_MPa_at"]], [p["stress_MPa"] for p in e["axial_stress_MPa_at"]])
            for e in t["cases"]}


def t_ordering(t):
    c = _curves(t)
    if not all(k in c for k in ("intact", "open_flaw", "filled_flaw")):
        return NOT_RUN
    at = {k: dict(zip(*v)) for k, v in c.items()}
    ds = sorted(d for d in at["intact"] if d > 0 and d in at["open_flaw"] and d in at["filled_flaw"])
    ok = sum(at["open_flaw"][d] < at["intact"][d] < at["filled_flaw"][d] for d in ds)
    oi = sum(at["open_flaw"][d] < at["intact"][d] for d in ds)
    fi = sum(at["filled_flaw"][d] > at["intact"][d] for d in ds)
    last = ds[-1] if ds else None
    txt = (f"open < intact < filled at {ok} of {len(ds)} displacements (0.1 mm apart); open < intact at {oi}, filled > intact at {fi}"
           + (f"; at {last:g} mm: open {at['open_flaw'][last]:.1f} / intact {at['intact'][last]:.1f} / filled {at['filled_flaw'][last]:.1f} MPa" if last else ""))
    return txt, "agrees" if ds and ok == len(ds) else ("partly" if oi or fi else "differs")


def t_no_peak(t):
    sh = {k: curve_shape(*v) for k, v in _curves(t).items()}
    sh = {k: v for k, v in sh.items() if v}
    if not sh:
        return NOT_RUN
    txt = "; ".join(f"{k}: peak {v['peak']:.1f} MPa at {v['x_at_peak']:.2f} mm, end {v['end']:.1f} MPa at {v['x_end']:.2f} mm" for k, v in sh.items())
    n = sum(v["drop"] < 0.03 for v in sh.values())
    return txt, "agrees" if n == len(sh) else ("partly" if n else "differs")


def t_easing(t):
    sh = {k: curve_shape(*v) for k, v in _curves(t).items()}
    sh = {k: v for k, v in sh.items() if v and v["slope_middle"] and v["slope_last"] is not None}
    if not sh:
        return NOT_RUN
    txt = "slope of the last / middle third of the curve (easing: < 0.95): " + "; ".join(
        f"{k} {v['slope_last'] / v['slope_middle']:.2f}" for k, v in sh.items())
    n = sum(v["slope_last"] < 0.95 * v["slope_middle"] for v in sh.values())
    return txt, "agrees" if n == len(sh) else ("partly" if n else "differs")


def t_filled_initial(t):
    sh = {k: curve_shape(*v) for k, v in _curves(t).items()}
    if not all(sh.get(k) for k in ("intact", "filled_flaw")):
        return NOT_RUN
    txt = "slope over the first third [MPa/mm]: " + ", ".join(f"{k} {v['slope_first']:.1f}" for k, v in sh.items() if v)
    return txt, "agrees" if sh["filled_flaw"]["slope_first"] > sh["intact"]["slope_first"] else "differs"


def t_floor_first(t):
    e = next((e for e in t["cases"] if e["case"] == "intact"), None)
    fc = (t["info"].get("intact") or {}).get("first_crack")
    if not e:
        return NOT_RUN
    loc, sym = e["first_damage_location"], e["symmetry_damage"]
    txt = f"first D = 1 at: {loc or 'none'}" + (f" at {fc['time'] * 1e3:.2f} ms" if fc else "") + f"; damage symmetry at 8 ms {_f(sym, '{:.2f}')}"
    good = bool(loc) and "floor" in loc
    return txt, "agrees" if good and (sym or 0) >= 0.8 else ("partly" if good or (sym or 0) >= 0.8 else "differs")


def t_triangles(t):
    s = _snap(t, "intact", "08ms")
    if not s or "plastic_zones" not in s:
        return NOT_RUN
    z = s["plastic_zones"]
    txt = f"plastic-strain symmetry {_f(s['symmetry_plastic'], '{:.2f}')}; largest plastic zone (ε̄p ≥ 0.2 × p99) per side: " + (
        "; ".join(f"{k}: {v['area_mm2']:.0f} mm², fill of its box {v['fill']:.2f} (½ = triangle), at ({v['centroid_mm'][0]:.0f}, "
                  f"{v['centroid_mm'][1]:.0f}) mm" for k, v in sorted(z.items())) or "none")
    tri = [v for v in z.values() if 0.3 <= v["fill"] <= 0.65]
    sym = (s["symmetry_plastic"] or 0) >= 0.8
    return txt, "agrees" if sym and len(tri) == 2 else ("partly" if sym or tri else "differs")


def _bands(s):
    return ", ".join(f"{b['side']} {abs(b['angle_deg']):.0f}° ({b['length'] * 1e3:.0f} mm, {b['location']})" for b in (s or {}).get("bands", [])[:4]) or "none"


def t_bands55(t):
    s12, s20 = _snap(t, "intact", "12ms"), _snap(t, "intact", "20ms")
    if not s12:
        return NOT_RUN
    near = lambda s: [b for b in (s or {}).get("bands", [])[:4] if abs(abs(b["angle_deg"]) - 55) <= 7]
    return (f"12 ms: {_bands(s12)}; 20 ms: {_bands(s20)}; softened (cohesion at its floor) at 12 ms: {100 * s12['softened_fraction']:.2f} %",
            "agrees" if near(s12) else ("partly: later, at 20 ms" if near(s20) else "differs"))


def t_new_shear(t):
    s12, s20 = _snap(t, "intact", "12ms"), _snap(t, "intact", "20ms")
    if not (s12 and s20):
        return NOT_RUN
    new = [b for b in s20["bands"] if all(np.hypot(*(np.subtract(b["centroid"], a["centroid"]))) > 5e-3 for a in s12["bands"])]
    txt = (f"softened rock {100 * s12['softened_fraction']:.2f} % at 12 ms → {100 * s20['softened_fraction']:.2f} % at 20 ms; "
           f"bands at 20 ms not at 12 ms: " + (", ".join(f"{b['side']} {abs(b['angle_deg']):.0f}° at {b['location']}" for b in new) or "none"))
    soft_new = s20["softened_fraction"] > s12["softened_fraction"]
    return txt, "agrees" if soft_new and new else ("partly: localised plastic bands, no softening" if new else "differs")


def t_waist(t):
    s = _snap(t, "intact", "20ms")
    if not s:
        return NOT_RUN
    w = lambda k: s.get(k) or {}
    txt = (f"spalled {s['spalled_area_mm2']:.0f} mm² at {s['spalling_at'] or 'none'}; by place: "
           + (", ".join(f"{k} {v:.0f}" for k, v in s.get("spalled_by_place_mm2", {}).items()) or "none")
           + f" mm²; waists moved in by {_f(w('left_waist_inward_mm').get('p90'), '{:.3f}')} / {_f(w('right_waist_inward_mm').get('p90'), '{:.3f}')} mm (left / right, p90)")
    at = s["spalling_at"] or ""
    return txt, "agrees" if "wall" in at else ("partly" if at else "differs")


def t_open_toe(t):
    s = _snap(t, "open_flaw", "20ms")
    if not s:
        return NOT_RUN
    toe = [b for b in s.get("bands", []) if b["location"] == "flaw toe"]
    txt = (f"within 4 mm of the toe: {s.get('toe_softened')} softened, {s.get('toe_damaged')} with D = 1; shear bands from the toe: "
           + (", ".join(f"{abs(b['angle_deg']):.0f}°, {b['length'] * 1e3:.0f} mm" for b in toe) or "none")
           + f"; damage symmetry {_f(s['symmetry_damage'], '{:.2f}')} (intact {_f((_snap(t, 'intact', '20ms') or {}).get('symmetry_damage'), '{:.2f}')})")
    return txt, "agrees" if s.get("toe_softened", 0) > 0 or toe else ("partly: tensile damage at the toe" if s.get("toe_damaged") else "differs")


def _hit(x):
    return bool(x) and any(w in x for w in ("corner", "wall", "spandrel"))


def t_toe_corner(t):
    s = _snap(t, "filled_flaw", "20ms")
    if not s:
        return NOT_RUN
    o = _snap(t, "open_flaw", "20ms") or {}
    txt = (f"failed zone (D = 1 or softened) from the filled flaw's toe reaches the opening at: {s.get('toe_link_to_opening') or 'nowhere'} "
           f"(open flaw: {o.get('toe_link_to_opening') or 'nowhere'}); plastic band from the toe: {s.get('toe_plastic_link_to_opening') or 'nowhere'}")
    if s.get("toe_failed_gap_mm") is not None:
        txt += f"; the failed zone grown from the toe ends {s['toe_failed_gap_mm']:.1f} mm from the opening, nearest its {s['toe_failed_nearest']}"
    return txt, "agrees" if _hit(s.get("toe_link_to_opening")) else ("partly: a plastic band, not a crack" if _hit(s.get("toe_plastic_link_to_opening")) else "differs")


def _left_spall(s):
    return sum(v for k, v in (s or {}).get("spalled_by_place_mm2", {}).items() if k.startswith("left"))


def t_left_spandrel(t):
    f, o = _snap(t, "filled_flaw", "20ms"), _snap(t, "open_flaw", "20ms")
    if not (f and o and "spalled_by_place_mm2" in f):
        return NOT_RUN
    sp = lambda s: s["spalled_by_place_mm2"].get("left spandrel", 0.0)
    txt = (f"spalled at the left spandrel {sp(f):.0f} mm² with the filler vs {sp(o):.0f} mm² open; whole left side {_left_spall(f):.0f} vs "
           f"{_left_spall(o):.0f} mm²")
    return txt, "agrees" if sp(f) > sp(o) else ("partly: worse on the left side, not at the spandrel" if _left_spall(f) > _left_spall(o) else "differs")


def t_left_waist(t):
    v = {c: ((_snap(t, c, "20ms") or {}).get("left_waist_inward_mm") or {}).get("p90") for c in ("intact", "open_flaw", "filled_flaw")}
    if v["filled_flaw"] is None:
        return NOT_RUN
    txt = "left waist moved into the opening (p90 of the rock within 3 mm of the left wall, 20 ms): " + ", ".join(
        f"{k} {_f(x, '{:.3f}')} mm" for k, x in v.items())
    big = v["filled_flaw"] > 2 * max(v["intact"] or 0, v["open_flaw"] or 0, 1e-9)
    return txt, "agrees" if big and v["filled_flaw"] > 0.2 else ("partly" if big else "differs")


# --------------------------------------------------------------------------------------------- the table
