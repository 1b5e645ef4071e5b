"""The elastic uniaxial specimen with the paper's flaw (Sec. 3.3 geometry, Miao 2018 elasticity, no plasticity or
damage), open or filled by the free rigid YADE filler, pressed quasi-statically by the rigid platen: the apparent
modulus at several Courant numbers, against an independent plane-strain FEM solution of the open and of the bonded
(tied rigid inclusion) flaw (yade_mpm_paper.validation.fem_flaw). A rigid filler in frictional contact must lie
between the two FEM values; one whose cohesion never lets it slip must equal the bonded value.

    /usr/bin/python3 scripts/paper/filled_flaw_elastic.py --out out/filled_flaw_elastic
    ... --spacings 0.002,0.001 --courants 1,0.5,0.25,0.125 --fem-spacings 0.001,0.0005,0.00025

Each MPM run: yade_mpm_paper.validation.filled_flaw.mpm_modulus. Outputs: OUT/summary.json (after every run),
OUT/table.md."""
import argparse
import json
import math
import os

import numpy as np

import yade_mpm as ym
from yade_mpm_paper import uncertainty
from yade_mpm_paper.validation.filled_flaw import RUNS, fem_modulus, mpm_modulus, plane_strain_modulus


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--out", default="out/filled_flaw_elastic")
    ap.add_argument("--spacings", default="0.002", help="MPM grid spacings [m], comma list (default %(default)s)")
    ap.add_argument("--courants", default="1,0.5,0.25,0.125", help="Courant numbers, comma list (default %(default)s)")
    ap.add_argument("--fem-spacings", default="0.001,0.0005,0.00025", help="FEM mesh spacings [m], each half the last (default %(default)s)")
    ap.add_argument("--runs", default=";".join(RUNS), help="MPM runs, a ';' list of: " + "; ".join(RUNS) + " (default: all)")
    a = ap.parse_args()
    names = [x.strip() for x in a.runs.split(";") if x.strip()]
    bad = [x for x in names if x not in RUNS]
    if bad or not names:
        raise SystemExit(f"--runs: {bad or 'none given'}; choose from: {', '.join(RUNS)}")
    spacings = [float(x) for x in a.spacings.split(",")]
    courants = [ym.scene.check_courant(float(x)) for x in a.courants.split(",")]
    fem_h = [float(x) for x in a.fem_spacings.split(",")]
    os.makedirs(a.out, exist_ok=True)
    plane = plane_strain_modulus()
    fem = {}
    for kind in ("open", "bonded"):
        vals = [fem_modulus(kind, h) for h in fem_h]
        rich = uncertainty.richardson(fem_h, vals) if len(vals) >= 3 else dict(limit=None, order=None)
        fem[kind] = dict(spacings_m=fem_h, modulus_Pa=vals, limit_Pa=rich["limit"] or vals[-1], order=rich["order"])
        print(f"[fem] {kind}: " + ", ".join(f"{v / plane:.5f}" for v in vals) + f" × E/(1−ν²); limit {fem[kind]['limit_Pa'] / plane:.5f}", flush=True)
    runs, failed = [], []
    for l in spacings:
        for name in names:
            for C in courants:
                try:   # a failed run is recorded with its reason and the next one runs
                    r = mpm_modulus(name, l, C)
                except Exception as e:   # noqa: BLE001 (the reason goes to summary.json)
                    failed.append(dict(run=name, spacing_m=l, courant=C, reason=f"{type(e).__name__}: {e}"))
                    print(f"[mpm] {name} l = {l * 1e3:g} mm C = {C:g}: FAILED ({failed[-1]['reason']})", flush=True)
                    continue
                runs.append(r)
                print(f"[mpm] {name} l = {l * 1e3:g} mm C = {C:g}: platen {r['platen_modulus_Pa'] / plane:.5f}, own strain "
                      f"{r['own_modulus_Pa'] / plane:.5f} × E/(1−ν²) (settled {r['settled']}, {r['wall_s']:.0f} s)", flush=True)
                json.dump(dict(plane_strain_modulus_Pa=plane, fem=fem, runs=runs, failed=failed), open(os.path.join(a.out, "summary.json"), "w"),
                          indent=1)   # after every run: an interrupted study keeps what it has
    json.dump(dict(plane_strain_modulus_Pa=plane, fem=fem, runs=runs, failed=failed), open(os.path.join(a.out, "summary.json"), "w"), indent=1)
    lo, hi = fem["open"]["limit_Pa"], fem["bonded"]["limit_Pa"]
    lines = [f"FEM (P1, Richardson over {', '.join(f'{h * 1e3:g}' for h in fem_h)} mm): open {lo / plane:.5f}, bonded {hi / plane:.5f} × E/(1−ν²).", "",
             "E′ = E/(1 − ν²). *÷ intact*: the modulus over the same grid's and C's intact specimen (the FEM intact is E′ exactly), which "
             "takes out what the platen contact and the grid do to every specimen alike.", "",
             "| run | l [mm] | C | platen modulus / E′ | own-strain modulus / E′ | ÷ intact | FEM open … bonded | spread over C |",
             "|---|---|---|---|---|---|---|---|"]
    for r in runs:
        same = [x["platen_modulus_Pa"] for x in runs if x["run"] == r["run"] and x["spacing_m"] == r["spacing_m"]]
        ref = [x["platen_modulus_Pa"] for x in runs if x["run"] == "intact" and x["spacing_m"] == r["spacing_m"] and x["courant"] == r["courant"]]
        rel = r["platen_modulus_Pa"] / ref[0] if ref else math.nan
        lines.append(f"| {r['run']} | {r['spacing_m'] * 1e3:g} | {r['courant']:g} | {r['platen_modulus_Pa'] / plane:.5f} | {r['own_modulus_Pa'] / plane:.5f} | "
                     f"{rel:.5f} | {lo / plane:.4f} … {hi / plane:.4f} | {np.ptp(same) / np.mean(same):.2%} |")
    lines += [f"\nFailed: {f['run']} l = {f['spacing_m'] * 1e3:g} mm C = {f['courant']:g}: {f['reason']}" for f in failed]
    open(os.path.join(a.out, "table.md"), "w").write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
