"""Builds doc/validation/report.md from the output folders of the reference scripts: every case's figures
(copied to doc/figures/) and numbers, error against run time for the benchmarks, the stability table,
the uniaxial sweeps, the fidelity table (every claim of the paper about its results, measured; yade_mpm_paper.fidelity.table) and the
one-at-a-time variants behind it (scripts/paper/fidelity_variants.py).

    /usr/bin/python3 scripts/paper/report.py                       # reads out/<case>/, writes doc/validation/report.md
    /usr/bin/python3 scripts/paper/report.py --root out --doc doc
    /usr/bin/python3 scripts/paper/report.py --only convergence,ensemble,stability   # these alone: doc/validation/uncertainty.md

Folders read (each optional; a missing one is reported with the command that makes it):
    circular_opening/  scripts/paper/circular_opening.py --convergence
    penny_crack/       scripts/paper/penny_crack.py
    circular_opening_paper/, penny_crack_paper/   the elastic benchmarks at the paper's grid (0.01 m, 0.02 m)
    stability/         scripts/paper/stability.py
    uniaxial_flaw/     scripts/paper/uniaxial_flaw.py
    uniaxial_paper/    scripts/paper/uniaxial_flaw.py --paper   (paper grid, 0.5 mm: the whole sweep, one run per --runs entry)
    tunnel/            scripts/paper/tunnel_spalling.py            (default grid, all four cases)
    tunnel_paper/      scripts/paper/tunnel_spalling.py --paper    (paper grid)
    fidelity_variants/ scripts/paper/fidelity_variants.py          (variant screening; notes.md: how it was run)
    convergence/       scripts/paper/convergence.py                (error against run time, every reference case)
    ensemble/uniaxial/, ensemble/tunnel/, ensemble/circular_opening/, ensemble/penny_crack/
                       scripts/studies/sweep.py scripts/paper/{uniaxial,tunnel,circular,penny}_shifts.table ...
                       (the default grid shifted against the specimen: the spread of every fidelity number; the unshifted
                       run s0.00_0.00 is the default run when uniaxial_flaw/ or tunnel/ is absent)
    fidelity_notes.md  how the runs of the fidelity table were made (build, commands, wall times)
    fidelity_grids.md  the default and the paper grid compared: where they differ, which to trust and why

The document and its sections are in yade_mpm_paper.report (document, sections, fidelity_sections,
uncertainty_sections); this script
puts them in order.
"""
import argparse
import os
import time

from yade_mpm_paper.report.document import PARTS, Report, shown
from yade_mpm_paper.report.fidelity_sections import courant_section, fidelity_section, variant_matrix
from yade_mpm_paper.report.sections import circular, penny, readme_figure, stability, tunnel, uniaxial
from yade_mpm_paper.report.uncertainty_sections import ENSEMBLES, convergence_section, ensemble_section


ONLY = {"convergence": convergence_section, "ensemble": ensemble_section, "stability": stability}   # sections a page can hold alone


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", default="out", help="folder holding the output folders (default out)")
    ap.add_argument("--doc", default="doc", help="doc folder (default doc): writes validation/report.md and figures/")
    ap.add_argument("--dir", action="append", default=[], metavar="PART=DIR",
                    help=f"read PART from DIR instead of ROOT/PART (PART: {', '.join(PARTS)}); repeatable")
    ap.add_argument("--only", default=None, metavar="S1,S2",
                    help=f"write only these sections ({', '.join(ONLY)}) as their own page, doc/validation/PAGE "
                         "(the numerical-uncertainty runs can be refreshed without the long runs of the full report)")
    ap.add_argument("--page", default="uncertainty.md", help="page name for --only (default uncertainty.md)")
    a = ap.parse_args()
    if a.only is not None:
        only = [x for x in a.only.split(",") if x]
        bad = [x for x in only if x not in ONLY]
        if not only or bad:
            ap.error(f"--only {a.only!r}: expected a comma list of {', '.join(ONLY)}")
        if not a.page.endswith(".md") or os.sep in a.page or a.page == "report.md":
            ap.error(f"--page {a.page!r}: expected a file name ending in .md other than report.md")
    dirs = {}
    for d in a.dir:
        part, _, path = d.partition("=")
        if part not in PARTS or not path:
            ap.error(f"--dir {d!r}: expected PART=DIR with PART in {', '.join(PARTS)}")
        dirs[part] = path
    for part, scene in (("uniaxial_flaw", "uniaxial"), ("tunnel", "tunnel")):   # the ensemble's unshifted run is the default run
        unshifted = os.path.join(a.root, ENSEMBLES[scene][0], "s0.00_0.00")
        if part not in dirs and not os.path.isdir(os.path.join(a.root, part)) and os.path.isdir(unshifted):
            dirs[part] = unshifted
    R = Report(a.root, a.doc, dirs)
    if a.only is not None:
        R.path = os.path.join(a.doc, "validation", a.page)
        R.w("# Numerical uncertainty: error against run time, grid-cut spread, stability", "",
            f"Generated by `scripts/paper/report.py --only {','.join(only)} --page {a.page}` on "
            f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} from the output folders under `{shown(a.root)}/`; the full "
            "[validation report](report.md) holds the same sections once its long runs are made.", "")
        for x in only:
            ONLY[x](R)
        print(f"wrote {R.write()}")
        return
    R.w("# Validation report", "",
        f"Generated by `scripts/paper/report.py` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} from the output folders under "
        f"`{shown(a.root)}/`" + (" and " + ", ".join(f"`{shown(v)}` ({k})" for k, v in dirs.items()) if dirs else "") + ". Regenerate: run the commands named in each section, then `/usr/bin/python3 scripts/paper/report.py`.", "",
        "The scenes, their parameters and what each check means: [tunnel](tunnel.md), [uniaxial flaw](uniaxial_flaw.md), "
        "[circular opening](circular_opening.md), [penny crack](penny_crack.md), [model checks](model_checks.md), "
        "[stability](stability.md).", "")
    fidelity_section(R)
    courant_section(R)
    variant_matrix(R)
    tparts = [tunnel(R, "tunnel", "Arch tunnel spalling (paper Sec. 4), default grid"),
              tunnel(R, "tunnel_paper", "Arch tunnel at the paper's grid (l = 1 mm)", keys_intact=(), keys_flaw=())]
    if tparts[0] or tparts[1]:
        readme_figure(R, "tunnel" if tparts[0] else "tunnel_paper")
    convergence_section(R)
    ensemble_section(R)
    circular(R)
    penny(R)
    stability(R)
    uniaxial(R)
    uniaxial(R, "uniaxial_paper", "Uniaxial compression with a flaw at the paper's grid (0.5 mm)")
    print(f"wrote {R.write()}")


if __name__ == "__main__":
    main()
