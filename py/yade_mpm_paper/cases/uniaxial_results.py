"""The records of a uniaxial flaw run (paper Sec. 3.3, Figs. 10–15), written once for
scripts/paper/uniaxial_flaw.py and any study of the scene: the post-peak stop, the curve's peak and modulus,
the crack analytics at the end of a run, and the runs' summary read back from OUT/runs/NAME/run.json.
Quantities are SI inside; the JSON-able records name their units (MPa, GPa)."""
import glob
import json
import math
import os

import numpy as np

from yade_mpm import analysis
from yade_mpm._core import MpmSimulationError
from yade_mpm.fields import get as _get, fields as _fields
from .uniaxial import uniaxial_flaw_geometry

SUMMARY_KEYS = ("variant", "mu_con", "c_con_MPa", "peak_stress_MPa", "strain_at_peak", "youngs_modulus_GPa", "wall_time_s",
                "particles", "steps", "particle_steps_per_s")            # peaks.csv / peaks.md columns
RUN_KEYS = SUMMARY_KEYS + ("time_at_peak_s", "end_reason", "filler_motion", "damaged_fraction_end", "crack_times", "near_flaw_sigma_max",
                           "plastic_before_peak", "cracks_end", "flaw_end_cracks_end", "shear_bands_end",
                           "time_reached_s", "error", "reaction_spikes")   # summary.json runs
ROW_KEYS = ("variant", "mu_con", "c_con_MPa", "spacing_m", "peak_stress_MPa", "strain_at_peak", "time_at_peak_s",
            "youngs_modulus_GPa", "particles", "steps", "end_reason", "softened", "damaged_fraction_end")   # a study's row


def run_name(variant, mu, c_mpa):
    """The run's folder name under OUT/runs: intact, open, filled_mu0.4_c0MPa."""
    return variant if variant != "filled" else f"filled_mu{mu:g}_c{c_mpa:g}MPa"


def softened(curve, time):
    """Past the peak at time [s]: the stress below 60 % of a peak of ≥ 5 MPa, 20 % later than it
    (curve: [(t, ε, σ)])."""
    st = [q[2] for q in curve]
    k = int(np.argmax(st))
    return st[k] > 5e6 and st[-1] < 0.6 * st[k] and time > 1.2 * curve[k][0]


def stop_when_softened(curve):
    """A runner stop test: `softened` checked every 50 steps on the growing curve [(t, ε, σ)]."""
    return lambda solver: solver.steps % 50 == 0 and softened(curve, solver.time)


def field_snapshots(snaps, names=("pos", "damage", "plastic_strain"), dtype=None):
    """A runner output that stores the named particle fields, as columns, in snaps["<time>"]."""
    def snapshot(solver):
        f = _fields(solver, list(names))
        a = np.column_stack([f[n] for n in names])
        snaps[f"{solver.time:.6e}"] = a.astype(dtype) if dtype else a
    return snapshot


def compression_run(solver, scene, folder, end_time, progress, label, snapshot, snapshot_when, vtu_when, outputs=()):
    """The loading loop of a compression specimen, written once for the uniaxial scripts (2D, 3D slab, penny prism):
    the platen's curve (t, ε, σ) after every step, `snapshot` (e.g. field_snapshots) and VTU files into FOLDER when
    due (`snapshot_when`, `vtu_when`: runner.Output timing, e.g. dict(period=1e-3, at_end=True)), extra runner
    outputs, a stop after the peak (stop_when_softened). Steps through YADE (O.step: the platen is a YADE body).
    Writes FOLDER/curve.csv (time_s, axial_strain, axial_stress_MPa), also when the solver stops the run with an
    error after the first step (result.reason "error", result.error its message: what was measured stays) and when
    the run is interrupted (Ctrl-C or SIGTERM: result.reason "interrupted"). Returns dict(result = runner's, wall_s,
    t, eps, sig [Pa] arrays, peak = index of the peak, E = Young's modulus [Pa] by peak_and_modulus)."""
    import time
    from yade import O
    from yade_mpm import output, runner
    curve = []

    def record(s):
        curve.append((s.time, scene["axial_strain"](), scene["axial_stress"]()))

    t0 = time.time()
    softened = stop_when_softened(curve)
    try:
        with runner.SignalStop() as sig:             # SIGINT/SIGTERM (a kill of a background run): end after this step
            res = runner.run(solver, end_time=end_time, progress=progress, label=label, advance=O.step,
                             stop=lambda s: sig.requested or softened(s),
                             outputs=[runner.Output(record, steps=1), runner.Output(snapshot, **snapshot_when),
                                      runner.Output(output.VtuSeries(folder).write, **vtu_when)] + list(outputs),
                             on_interrupt="return")
        if sig.requested:
            res.reason = "interrupted"
    except (MpmSimulationError, RuntimeError) as e:   # the solver refused the state (through YADE: a RuntimeError):
        res = runner.RunResult("error", solver.steps, solver.time, time.time() - t0)   # keep the curve measured up to it
        res.error = str(e).split("ERROR:")[-1].strip().splitlines()[0]
        print(f"[{label}] stopped by the solver at t = {solver.time:.6g} s: {res.error}", flush=True)
        if not curve:
            raise
    wall = time.time() - t0
    t, eps, sig = np.array(curve).T
    output.write_csv(os.path.join(folder, "curve.csv"), ["time_s", "axial_strain", "axial_stress_MPa"], np.column_stack([t, eps, sig / 1e6]))
    k, E = peak_and_modulus(eps, sig)
    return dict(result=res, wall_s=wall, t=t, eps=eps, sig=sig, peak=k, E=E)


SPIKE_SHARE = 0.5   # a reaction sample above both neighbours by more than this share of the curve's maximum so far


def reaction_spikes(sig):
    """Indices of one-sample spikes of a platen reaction recorded every step: a sample above both its neighbours by
    more than SPIKE_SHARE of the largest value before it. A specimen's reaction cannot jump and fall back within two
    steps (0.2 µs at the paper's grid); a lone fragment whose velocity diverges under the platen's edge makes it do
    so (doc/validation/uniaxial_flaw.md, "Reaction spikes")."""
    s = np.asarray(sig, float)
    if len(s) < 3:
        return np.zeros(0, int)
    before = np.maximum.accumulate(s)[:-2]          # the largest value before sample j (j = 1 … n − 2)
    excess = s[1:-1] - np.maximum(s[:-2], s[2:])
    return np.flatnonzero((before > 0) & (excess > SPIKE_SHARE * before)) + 1


def peak_and_modulus(eps, sig):
    """Index of the peak stress and Young's modulus [Pa]: the slope fitted between 10 and 40 % of the
    peak before it (NaN with fewer than 4 such points). The peak is sought before the first reaction spike
    (reaction_spikes), which is not a response of the specimen."""
    spikes = reaction_spikes(sig)
    k = int(np.argmax(sig[:spikes[0]] if len(spikes) else sig))
    pre = (sig > 0.1 * sig[k]) & (sig < 0.4 * sig[k]) & (np.arange(len(sig)) < k)
    return k, (np.polyfit(eps[pre], sig[pre], 1)[0] if pre.sum() > 3 else float("nan"))


def spike_record(t, sig):
    """What a run's record says of its reaction spikes (reaction_spikes): None, or their count, the time of the
    first and the largest spike [MPa]."""
    sp = reaction_spikes(sig)
    if not len(sp):
        return None
    return dict(count=int(len(sp)), first_time_s=float(t[sp[0]]), largest_MPa=float(np.max(np.asarray(sig)[sp]) / 1e6))


def peak_fields(t, eps, sig, k, E):
    """A run record's fields of its curve (t [s], ε, σ [Pa]) with the peak at index k and Young's modulus E [Pa]
    (peak_and_modulus), and its reaction spikes (spike_record)."""
    return dict(peak_stress_MPa=float(sig[k] / 1e6), strain_at_peak=float(eps[k]), time_at_peak_s=float(t[k]),
                youngs_modulus_GPa=float(E / 1e9), reaction_spikes=spike_record(t, sig))


def rescore(entry):
    """A run record written before reaction spikes were told apart (no "reaction_spikes" key): its peak, modulus,
    plastic share before the peak and spikes derived again from its curve.csv and snapshots.npz, and written back to
    its run.json. Returns True when the record changed."""
    if "reaction_spikes" in entry or not os.path.exists(os.path.join(entry["dir"], "curve.csv")):
        return False
    t, eps, sig = read_curve(entry, with_time=True)
    sig = sig * 1e6
    k, E = peak_and_modulus(eps, sig)
    entry.update(peak_fields(t, eps, sig, k, E))
    snaps = os.path.join(entry["dir"], "snapshots.npz")
    if "plastic_before_peak" in entry and os.path.exists(snaps):
        with np.load(snaps) as z:
            entry["plastic_before_peak"] = plastic_before({q: z[q] for q in z.files}, t[k])
    with open(os.path.join(entry["dir"], "run.json"), "w") as f:
        json.dump({q: v for q, v in entry.items() if q != "dir"}, f, indent=1)
    return True


def filler_motion(body):
    """The filler's in-plane displacement [m] and rotation about z [rad] (YADE's rot(), from refOri)."""
    p = body.state
    return dict(dx_m=float(p.displ()[0]), dy_m=float(p.displ()[1]), rotation_rad=float(p.rot()[2]))


def plastic_before(snaps, t_peak):
    """Share of the particles with ε̄p > 1e-4 (softening under way, Eq. 34) at the last snapshot before
    the peak (snaps: {time text: columns x, y, D, ε̄p, σ̃max})."""
    before = [k for k in snaps if float(k) <= t_peak]
    if not before:
        return None
    k = max(before, key=float)
    return dict(time_s=float(k), share=float(np.mean(snaps[k][:, 3] > 1e-4)))


def end_analytics(solver, lattice, flaw, snaps, spacing):
    """Cracks and shear bands at the end of a run (``analysis.crack_report``), σ̃max within 2 particle rows
    of the flaw in every snapshot (Figs. 14–15) and the cracks at the flaw ends; flaw: the scene's
    flaw dict or None."""
    from ..fidelity import json_safe, near_segment_stress
    fl, soft = flaw, analysis.softening_end(solver)
    near = {k: near_segment_stress(lattice.x0, v[:, 4], fl["toe"], fl["tip"], fl["width"] / 2 + spacing)
            for k, v in snaps.items()} if fl else {}
    # every field but the material velocity, which needs a WLS fit at the current positions: a run the solver stopped
    # (a particle with no active stencil node, e.g. inside a body) must still report its cracks
    rep = analysis.crack_report(_fields(solver, exclude=("vel",)), lattice, fl and fl["polygon"], soft, flaw=fl and (fl["toe"], fl["tip"]), band_gap=2 * spacing)
    pick = lambda cs: [{k: c[k] for k in ("length", "angle_deg", "centroid")} for c in cs[:4]]
    return dict(damaged_fraction_end=float(np.mean(_get(solver, "damage") > 0.99)),
                cracks_end=pick(rep["cracks"]), shear_bands_end=pick(rep["bands"]),
                near_flaw_sigma_max=[dict(time_s=float(k), **v) for k, v in sorted(near.items(), key=lambda q: float(q[0])) if v],
                flaw_end_cracks_end=fl and json_safe(analysis.flaw_end_cracks(_get(solver, "damage"), _get(solver, "plastic_strain"), soft,
                                                                              lattice, fl["toe"], fl["tip"], 2 * spacing)))


# ------------------------------------------------------------------------------------- the runs' summary
def load_runs(out):
    """Every OUT/runs/*/run.json (and a study's OUT/*/runs/*/run.json), each with its folder as "dir"."""
    runs = []
    for f in sorted(glob.glob(os.path.join(out, "runs", "*", "run.json")) + glob.glob(os.path.join(out, "*", "runs", "*", "run.json"))):
        with open(f) as fh:
            e = json.load(fh)
        e["dir"] = os.path.dirname(f)
        runs.append(e)
    return runs


def find_run(runs, variant, mu=0.0, c=0.0):
    for e in runs:
        if e["variant"] == variant and abs(e["mu_con"] - mu) < 1e-9 and abs(e["c_con_MPa"] - c) < 1e-9:
            return e
    return None


def read_curve(e, with_time=False):
    """(axial strain, axial stress [MPa]) of a run's curve.csv; with_time: (time [s], strain, stress [MPa])."""
    c = np.loadtxt(os.path.join(e["dir"], "curve.csv"), delimiter=",", skiprows=1, ndmin=2)
    return (c[:, 0], c[:, 1], c[:, 2]) if with_time else (c[:, 1], c[:, 2])


def read_snapshot(e, t):
    """(time, columns x, y, D, ε̄p, σ̃max) of the run's snapshot nearest to t [s]."""
    z = np.load(os.path.join(e["dir"], "snapshots.npz"))
    k = min(sorted(z.files, key=float), key=lambda q: abs(float(q) - t))
    return float(k), z[k]


def has_snapshots(e):
    return bool(np.load(os.path.join(e["dir"], "snapshots.npz")).files)


def sort_runs(runs):
    """intact, open, then filled by c_con and μ_con (peaks.md order)."""
    order = {"intact": 0, "open": 1, "filled": 2}
    runs.sort(key=lambda e: (order[e["variant"]], e["c_con_MPa"], e["mu_con"]))
    return runs


def summary(runs, sigma_max_time):
    """summary.json of the runs: each with RUN_KEYS and the filler's rotation change [°] (YADE's rot() is
    measured from refOri = identity: the filler's initial angle subtracted)."""
    u = uniaxial_flaw_geometry()["direction"]
    for e in runs:
        fm = e.get("filler_motion")
        if fm:
            fm["rotation_change_deg"] = math.degrees(fm["rotation_rad"] - math.atan2(u[1], u[0]))
    return dict(case="uniaxial compression with a flaw, paper Sec. 3.3", spacing_m=runs[0]["spacing_m"], sigma_max_time_s=sigma_max_time,
                runs=[{k: e.get(k) for k in RUN_KEYS} for e in runs], total_wall_time_s=sum(e["wall_time_s"] for e in runs))


def peaks_markdown(runs):
    """peaks.md: one table row per run."""
    L = ["| variant | μ_con | c_con [MPa] | peak [MPa] | ε at peak | E [GPa] | wall [s] | particles | steps | M p-steps/s |",
         "|---|---|---|---|---|---|---|---|---|---|"]
    L += [f"| {e['variant']} | {e['mu_con']:g} | {e['c_con_MPa']:g} | {e['peak_stress_MPa']:.2f} | {e['strain_at_peak']:.4f} | "
          f"{e['youngs_modulus_GPa']:.2f} | {e['wall_time_s']:.0f} | {e['particles']} | {e['steps']} | {e['particle_steps_per_s'] / 1e6:.2f} |"
          for e in runs]
    return "\n".join(L) + "\n"
