"""The time-step study (issue 19 item 1): the same scenes at several Courant numbers C of Δt = C·l/(v_c +
max‖v‖) (Sec. 2.5), compared by accuracy. Reads the output folders of the scripts run at each C (layout of
scripts/regress.py: OUT/kirsch, OUT/sneddon, OUT/tunnel, OUT/uniaxial) and measures, besides what the
scripts print, the platen penetration: the penalty of Eq. 23 has κ_p = 2 m_p/Δt², so a longer step is a
softer contact. Penetration here = d0 − (platen face − particle centre) over the particles of the top row
(d0 = half the particle edge, the detection distance the contact pushes back to), from the VTU files.

    rows = collect({1.0: "out/courant/c1", 0.5: "out/courant/c0.5", 0.25: "out/courant/c0.25"})
    text = markdown(rows)
"""
import base64
import csv
import json
import os
import re

import numpy as np

from ..cases import TUNNEL_WIDTH, UNIAXIAL_HEIGHT
from ..cases.loading import PLATEN_SPEED
from yade_mpm.output import read_pvd

_TYPES = {"Float64": np.float64, "Int64": np.int64, "UInt8": np.uint8}


def read_vtu(path):
    """(points (N, 3), {name: array}) of a VTU file written by yade_mpm.output.write_vtu (inline binary
    base64, one UInt64 byte-count header per array)."""
    txt = open(path).read()
    points, data = None, {}
    for attrs, body in re.findall(r"<DataArray ([^>]*)>([^<]*)</DataArray>", txt):
        a = dict(re.findall(r'(\w+)="([^"]*)"', attrs))
        raw = base64.b64decode(body)
        n = int(np.frombuffer(raw[:8], np.uint64)[0])
        arr = np.frombuffer(raw[8:8 + n], _TYPES[a["type"]])
        nc = int(a.get("NumberOfComponents", 1))
        arr = arr.reshape(-1, nc) if nc > 1 else arr
        if "Name" not in a:
            points = arr
        else:
            data[a["Name"]] = arr
    return points, data


def platen_penetration(vtu, top, platen_disp, dp):
    """Penetration of the top particle row into the rigid platen [m]: mean and max over the row of
    d0 − (face − y_p), d0 = dp/2, face = top − platen_disp (the platen's lower face starts on the specimen
    top `top`). The row: particles within dp/2 of the highest one. Positive: closer than d0, inside the
    detection distance the penalty of Eq. 23 acts over — the contact's softness."""
    pts, _ = read_vtu(vtu)
    y = pts[:, 1]
    row = y > y.max() - dp / 2
    pen = dp / 2 - ((top - platen_disp) - y[row])
    return dict(mean_m=float(pen.mean()), max_m=float(pen.max()), particles=int(row.sum()))


def _penetration_series(folder, top, dp, times=None):
    """Penetration at every VTU of folder/particles.pvd (the platen moves at PLATEN_SPEED from t = 0)."""
    out = []
    for t, f in read_pvd(os.path.join(folder, "particles.pvd")):
        if t <= 0 or (times is not None and not any(abs(t - q) < 1e-5 for q in times)):
            continue
        p = platen_penetration(f, top, PLATEN_SPEED * t, dp)
        out.append(dict(time_s=t, **p))
    return out


def _load(path):
    return json.load(open(path)) if os.path.exists(path) else None


def tunnel_numbers(folder, case):
    """Axial stress at 0.5 / 1 / 1.5 / 2 mm, the whole curve, first crack, end, penetration of one tunnel case."""
    d = os.path.join(folder, case)
    cj = _load(os.path.join(d, "case.json"))
    if cj is None:
        return None
    with open(os.path.join(d, "axial_stress.csv")) as f:
        rows = [[float(x) for x in r] for r in list(csv.reader(f))[1:]]
    c = np.array(rows)                                  # time [s], displacement [mm], stress [MPa]
    s = _load(os.path.join(folder, "summary.json")) or {"cases": []}
    e = next((x for x in s["cases"] if x["case"] == case), {})
    fc = cj.get("first_crack")
    at = {m: float(np.interp(m, c[:, 1], c[:, 2])) for m in (0.5, 1.0, 1.5, 2.0) if m <= c[-1, 1] + 1e-6}
    return dict(curve=c, at=at, end_mm=float(c[-1, 1]), finished=cj.get("finished"), steps=e.get("steps"), wall_s=e.get("wall_time_s"),
                first_crack=fc and dict(time_ms=fc["time"] * 1e3, place=fc["location"], x_mm=fc["centroid"][0] * 1e3,
                                        y_mm=fc["centroid"][1] * 1e3),
                penetration=_penetration_series(d, TUNNEL_WIDTH, e["grid_spacing_m"] / 2) if "grid_spacing_m" in e else [])


def uniaxial_numbers(folder, run):
    """Peak, strain at peak, first D = 1 at a flaw end, wing > flaw, through-crack, penetration before the peak."""
    d = os.path.join(folder, "runs", run)
    r = _load(os.path.join(d, "run.json"))
    if r is None:
        return None
    ct = r.get("crack_times") or {}
    pen = _penetration_series(d, UNIAXIAL_HEIGHT, r["spacing_m"] / 2)
    before = [p for p in pen if p["time_s"] <= r["time_at_peak_s"] + 1e-9]
    return dict(peak_MPa=r["peak_stress_MPa"], strain_at_peak=r["strain_at_peak"], time_at_peak_ms=r["time_at_peak_s"] * 1e3,
                E_GPa=r["youngs_modulus_GPa"], steps=r["steps"], wall_s=r["wall_time_s"], end=r["end_reason"],
                first_tip_D1_ms=ct.get("first_tip_damage_s") and ct["first_tip_damage_s"] * 1e3,
                wing_ms=ct.get("wing_longer_than_flaw_s") and ct["wing_longer_than_flaw_s"] * 1e3,
                through_ms=ct.get("through_to_a_face_s") and ct["through_to_a_face_s"] * 1e3,
                penetration_before_peak=before[-1] if before else None)


def collect(folders):
    """{C: {"kirsch": ..., "sneddon": ..., "tunnel_<case>": ..., "uniaxial_<run>": ...}} from the folders by C."""
    out = {}
    for C, f in folders.items():
        row = {}
        k = _load(os.path.join(f, "kirsch", "summary.json"))
        if k:
            row["kirsch"] = {q: k[q] for q in k if q.startswith("l2_rel_error_s") and not q.endswith("_near")}
            row["kirsch"]["steps"] = k.get("steps")
        sn = _load(os.path.join(f, "sneddon", "summary.json"))
        if sn:
            row["sneddon"] = {q: sn[q] for q in ("uy_center_rel_error", "uy_l2_rel_error")}
        for case in ("intact", "filled_flaw", "open_flaw"):
            t = tunnel_numbers(os.path.join(f, "tunnel"), case)
            if t:
                row[f"tunnel_{case}"] = t
        for run in ("open", "filled_mu0.6_c0MPa", "intact", "filled_mu0.4_c0MPa"):
            u = uniaxial_numbers(os.path.join(f, "uniaxial"), run)
            if u:
                row[f"uniaxial_{run}"] = u
        out[C] = row
    return out


def _f(v, fmt):
    return "—" if v is None else fmt.format(v)


def _quantities(rows):
    """(label, getter, format, tolerance text or None) of every compared number present in `rows`."""
    q = []
    have = set().union(*(r.keys() for r in rows.values())) if rows else set()
    if "kirsch" in have:
        q += [(f"Kirsch: L2 rel. error {c} on the {n}", (lambda c, n: lambda r: r["kirsch"][f"l2_rel_error_{c}_{n}"])(c, n), "{:.5f}",
               "rel ≤ 1e-3") for n in ("xline", "yline") for c in ("sxx", "syy")]
    if "sneddon" in have:
        q += [("Sneddon: u_y error at the centre", lambda r: r["sneddon"]["uy_center_rel_error"], "{:.5f}", "rel ≤ 1e-3"),
              ("Sneddon: u_y L2 error", lambda r: r["sneddon"]["uy_l2_rel_error"], "{:.5f}", "rel ≤ 1e-3")]
    for case in ("intact", "filled_flaw", "open_flaw"):
        k = f"tunnel_{case}"
        if k not in have:
            continue
        q += [(f"tunnel {case}: σ at {m:g} mm [MPa]", (lambda m, k: lambda r: r[k]["at"].get(m))(m, k), "{:.2f}", "rel ≤ 5e-3" if case == "intact" and m < 1.5 + 1e-9 and m != 1.5 else None)
              for m in (0.5, 1.0, 1.5, 2.0)]
        q += [(f"tunnel {case}: first D = 1 [ms], place", lambda r, k=k: r[k]["first_crack"] and (r[k]["first_crack"]["time_ms"], r[k]["first_crack"]["place"]),
               None, "time rel ≤ 0.02, same place" if case == "intact" else None),
              (f"tunnel {case}: platen penetration at 4 / 8 / 20 ms, row mean [µm]", lambda r, k=k: _pen(r[k]["penetration"]), None, None),
              (f"tunnel {case}: steps to the end, finished", lambda r, k=k: (r[k]["steps"], r[k]["finished"], r[k]["end_mm"]), None, None)]
    for run in ("open", "filled_mu0.6_c0MPa", "intact", "filled_mu0.4_c0MPa"):
        k = f"uniaxial_{run}"
        if k not in have:
            continue
        q += [(f"uniaxial {run}: peak [MPa]", lambda r, k=k: r[k]["peak_MPa"], "{:.2f}", "rel ≤ 0.01" if run != "filled_mu0.6_c0MPa" else None),
              (f"uniaxial {run}: strain at the peak", lambda r, k=k: r[k]["strain_at_peak"], "{:.5f}", None)]
        if run in ("open", "filled_mu0.6_c0MPa"):
            q += [(f"uniaxial {run}: first D = 1 at a flaw end / wing > flaw / through to a face [ms]",
                   lambda r, k=k: tuple(r[k][x] for x in ("first_tip_D1_ms", "wing_ms", "through_ms")), None, None),
                  (f"uniaxial {run}: platen penetration before the peak, row mean / max [µm]",
                   lambda r, k=k: r[k]["penetration_before_peak"] and (r[k]["penetration_before_peak"]["mean_m"] * 1e6, r[k]["penetration_before_peak"]["max_m"] * 1e6),
                   None, None)]
    return q


def _pen(series):
    at = {round(p["time_s"] * 1e3): p for p in series}
    return tuple(at[t]["mean_m"] * 1e6 if t in at else None for t in (4, 8, 20))


def _show(v, fmt):
    if v is None:
        return "—"
    if isinstance(v, tuple):
        return " / ".join(_show(x, "{:.3g}" if isinstance(x, float) else "{}") for x in v)
    if isinstance(v, bool):
        return "yes" if v else "no"
    return (fmt or "{}").format(v)


def markdown(rows, base=None):
    """The table quantity × C, with the relative change of each C against `base` (default: the solver's
    C, the default the study is about) where a number is compared."""
    from yade_mpm.scene import setting_default
    base = setting_default("courant") if base is None else base
    Cs = sorted(rows, reverse=True)
    others = [C for C in Cs if C != base]
    head = "| quantity | " + " | ".join(f"C = {C:g}" for C in Cs) + " | " + " | ".join(f"C = {C:g} vs {base:g}" for C in others) + " | regress tolerance |"
    out = [head, "|---|" + "---|" * (len(Cs) + len(others) + 1)]
    for label, get, fmt, tol in _quantities(rows):
        vals = {}
        for C in Cs:
            try:
                vals[C] = get(rows[C])
            except (KeyError, TypeError):
                vals[C] = None
        if all(v is None for v in vals.values()):
            continue
        ch = []
        first = lambda v: v[0] if isinstance(v, tuple) and v else v
        r = first(vals.get(base))
        for C in others:
            v = first(vals[C])
            ch.append(f"{(v - r) / abs(r):+.2%}" if isinstance(v, float) and isinstance(r, float) and r else "—")
        out.append(f"| {label} | " + " | ".join(_show(vals[C], fmt) for C in Cs) + " | " + " | ".join(ch) + f" | {tol or '—'} |")
    return "\n".join(out)
