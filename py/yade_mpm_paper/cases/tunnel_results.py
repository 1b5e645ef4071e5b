"""The records of a tunnel run (paper Sec. 4, Figs. 17–19), written once for scripts/paper/tunnel_spalling.py
and any study of the scene: the first tensile crack, the field snapshots and their crack analytics
(``tunnel_report``), the case's summary entry and study row, and the Fig. 17 ordering of the curves.
Quantities are SI inside; the JSON-able records name their units (mm, MPa)."""
import os

import numpy as np

from yade_mpm.fields import fields as _fields, removed as _removed
from yade_mpm.output import sample_curve as _sample
from .tunnel import tunnel_report, tunnel_where

SNAPSHOT_FIELDS = ("pos", "damage", "plastic_strain", "max_principal_stress", "mass")
OLD_KEYS = {"epsP": "plastic_strain", "smax": "max_principal_stress"}   # snapshot names before ym.fields


def first_crack(solver, x0, displacement, flaw=None):
    """The first tensile crack (D = 1) of the state, or None: time, platen displacement, number of
    particles, their centroid and place (``tunnel_where``, positions x0 by id)."""
    d = solver.view("damage")
    if d.max() < 1.0:
        return None
    pts = x0[solver.view("id")[d >= 1.0]]
    return dict(time=solver.time, displacement=displacement, particles=len(pts), centroid=pts.mean(axis=0).tolist(),
                location=tunnel_where(pts, flaw))


def save_snapshot(solver, folder, displacement):
    """The fields of the pictures and the analysis (id order) as folder/snapshot_NNms.npz; returns the name."""
    f = _fields(solver, list(SNAPSHOT_FIELDS))
    name = f"snapshot_{int(round(solver.time * 1e3)):02d}ms.npz"      # 08ms, 12ms, 20ms (or where a run stopped)
    np.savez_compressed(os.path.join(folder, name), displacement=displacement, **f)
    return name


def analyse_snapshots(folder, names, lattice, flaw, soft_end, rock=None):
    """``tunnel_report`` of every snapshot: ({key: fields with "spalled"}, {"snapshots": {key: report}}),
    key "08ms" for snapshot_08ms.npz; each report adds time_ms and displacement_mm."""
    snaps, result = {}, {"snapshots": {}}
    for name in names:
        with np.load(os.path.join(folder, name)) as z:
            f = snaps[name[9:13]] = {OLD_KEYS.get(k, k): z[k] for k in z.files}
        rep, f["spalled"] = tunnel_report(f, lattice, flaw, soft_end, rock=rock)
        result["snapshots"][name[9:13]] = dict(time_ms=float(f["time"] * 1e3), displacement_mm=float(f["displacement"] * 1e3), **rep)
    return snaps, result


def sample_curve(curve, step_mm):
    """[{displacement_mm, stress_MPa}] every step_mm of a recorded curve [[time, displacement, stress]]."""
    c = np.array(curve) if curve else np.zeros((0, 3))
    return [{"displacement_mm": d, "stress_MPa": v / 1e6} for d, v in _sample(c[:, 1] * 1e3, c[:, 2], step_mm)]


def summary_entry(case, solver, state, result, curve_step_mm):
    """The case's entry of summary.json from its run record (``ResumableRun.state``) and analysis."""
    st, snap = state, result["snapshots"]
    c = np.array(st["curve"]) if st["curve"] else np.zeros((0, 3))
    sym_key = "08ms" if "08ms" in snap else (sorted(snap)[-1] if snap else None)
    fc = st["first_crack"]
    acc = _removed(solver)
    return {"case": case, "grid_spacing_m": solver.spacing, "particles": int(solver.numParticles), "steps": int(st.get("steps", solver.steps)),
            "wall_time_s": round(st["wall"], 2),
            "particle_steps_per_s": float(solver.numParticles * st["steps_run"] / st["wall"]) if st["wall"] > 0 else None,
            "final_displacement_mm": st.get("final_displacement", c[-1, 1] if len(c) else 0.0) * 1e3,
            "axial_stress_MPa_at": sample_curve(st["curve"], curve_step_mm),
            "symmetry_damage": snap[sym_key]["symmetry_damage"] if sym_key else None,
            "first_damage_location": fc["location"] if fc else None,
            "removed": {k: acc[k] for k in ("count", "mass", "kinetic_energy", "last_time", "faces")}}   # debris off the grid


def ordering(entries):
    """At equal displacement: open_flaw < intact < filled_flaw (paper Fig. 17)? Share of the samples of
    the summary entries (None without the three cases)."""
    by = {e["case"]: {p["displacement_mm"]: p["stress_MPa"] for p in e["axial_stress_MPa_at"]} for e in entries}
    if not all(k in by for k in ("intact", "open_flaw", "filled_flaw")):
        return None
    ds = sorted(set(by["intact"]) & set(by["open_flaw"]) & set(by["filled_flaw"]) - {0.0})
    ok = [by["open_flaw"][d] < by["intact"][d] < by["filled_flaw"][d] for d in ds]
    return dict(samples=len(ds), holds=int(sum(ok)), fraction=(sum(ok) / len(ds)) if ds else None)


def study_row(case, state, result, entry, params):
    """The case's row of OUT/summary.csv (a study's line, scripts/studies/study_report.py): the parameters
    (params: spacing, end_time, courant, flaw_angle, filler_mu, grout_young) and results, no wall time."""
    at = {p["displacement_mm"]: p["stress_MPa"] for p in entry["axial_stress_MPa_at"]}
    c = np.array(state["curve"])
    k = int(np.argmax(c[:, 2]))
    last = result["snapshots"][max(result["snapshots"])] if result["snapshots"] else {}
    fc, p = state["first_crack"], params
    return dict(case=case, spacing_m=p["spacing"], end_time_s=p["end_time"], courant=p["courant"],
                flaw_angle_deg=p["flaw_angle"] if case != "intact" else None,
                filler_mu=p["filler_mu"] if case == "filled_flaw" else None,
                grout_young_GPa=p["grout_young"] / 1e9 if case == "grout_flaw" else None,
                particles=entry["particles"], steps=entry["steps"], final_displacement_mm=entry["final_displacement_mm"],
                **{f"stress_MPa_at_{d:g}mm": at.get(d) for d in (0.5, 1.0, 1.5, 2.0)},
                peak_stress_MPa=float(c[k, 2] / 1e6), displacement_at_peak_mm=float(c[k, 1] * 1e3),
                first_damage_mm=fc["displacement"] * 1e3 if fc else None, first_damage_at=fc["location"] if fc else None,
                spalled_area_mm2=last.get("spalled_area_mm2"), damaged_fraction=last.get("damaged_fraction"),
                softened_fraction=last.get("softened_fraction"), spalling_at=last.get("spalling_at"))
