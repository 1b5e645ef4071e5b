"""The validation report's document (scripts/paper/report.py builds doc/validation/report.md with it): the output
folders it reads and the commands that make them, the Markdown lines with their figures copied to
doc/figures/, number and table formatting, notes included verbatim and the frozen record's link."""
import glob
import json
import os
import shutil

import numpy as np

PARTS = {
    "circular_opening": "/usr/bin/python3 scripts/paper/circular_opening.py --out out/circular_opening --convergence",
    "penny_crack": "/usr/bin/python3 scripts/paper/penny_crack.py --out out/penny_crack",
    "penny_crack_damage": "/usr/bin/python3 scripts/paper/penny_crack.py --out out/penny_crack_damage --parts damage",
    "circular_opening_paper": "/usr/bin/python3 scripts/paper/circular_opening.py --out out/circular_opening_paper --spacing 0.01 --no-convergence --no-vtu",
    "penny_crack_paper": "/usr/bin/python3 scripts/paper/penny_crack.py --out out/penny_crack_paper --parts elastic --spacing 0.02",
    "stability": "/usr/bin/python3 scripts/paper/stability.py --out out/stability",
    "uniaxial_flaw": "/usr/bin/python3 scripts/paper/uniaxial_flaw.py --out out/uniaxial_flaw",
    "tunnel": "./run.sh   (= /usr/bin/python3 scripts/paper/tunnel_spalling.py --out out/tunnel)",
    "uniaxial_paper": "/usr/bin/python3 scripts/paper/uniaxial_flaw.py --out out/uniaxial_paper --paper",
    "tunnel_paper": "/usr/bin/python3 scripts/paper/tunnel_spalling.py --out out/tunnel_paper --paper --threads 2 --cases intact,open_flaw,filled_flaw",
}


MAX_FIGURE_BYTES = 400_000       # larger pictures stay in the output folder
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def shown(path):
    """A folder as the report names it: relative to the repository (no absolute path of this machine);
    a folder outside the repository by its last two components only."""
    p = os.path.abspath(path)
    if os.path.commonpath([p, REPO]) == REPO:
        return os.path.relpath(p, REPO)
    return os.path.join("…", *p.split(os.sep)[-2:]) + " (outside the repository)"


class Report:
    def __init__(self, root, doc, dirs=None):
        self.root, self.doc, self.dirs = root, doc, dict(dirs or {})
        self.fig_dir = os.path.join(doc, "figures")
        self.path = os.path.join(doc, "validation", "report.md")
        os.makedirs(self.fig_dir, exist_ok=True)
        self.lines = []

    def w(self, *lines):
        self.lines.extend(lines)

    def folder(self, part):
        return self.dirs.get(part, os.path.join(self.root, part))

    def read(self, part):
        path = os.path.join(self.folder(part), "summary.json")
        if not os.path.exists(path):
            return None
        with open(path) as f:
            return json.load(f)

    def load(self, part):
        """summary.json of a part, or None after a line saying how to make it."""
        s = self.read(part)
        if s is None:
            self.w(f"*Not run here* — `{PARTS[part]}` writes `{shown(self.folder(part))}/`.", "")
        return s

    def figure(self, src, name, caption, width=None):
        """Copy a PNG to doc/figures/ and link it."""
        if not os.path.exists(src):
            return False
        dst = os.path.join(self.fig_dir, name)
        shutil.copyfile(src, dst)
        rel = os.path.relpath(dst, os.path.dirname(self.path))
        self.w(f"![{caption}]({rel})" if width is None else f'<img src="{rel}" width="{width}" alt="{caption}">', f"*{caption}*", "")
        return True

    def figures(self, part, names):
        """The named PNGs of a part's folder (a selection: doc/ keeps small files only)."""
        for b in names:
            for p in sorted(glob.glob(os.path.join(self.folder(part), b))):
                if os.path.getsize(p) <= MAX_FIGURE_BYTES:
                    self.figure(p, f"{part}_{os.path.basename(p)}", f"{part}: {os.path.basename(p)}")

    def write(self):
        os.makedirs(os.path.dirname(self.path), exist_ok=True)
        with open(self.path, "w") as f:
            f.write("\n".join(self.lines).rstrip() + "\n")
        return self.path


def fmt(v, nd=3):
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return f"{v:,}"
    if isinstance(v, float):
        return f"{v:,.0f}" if abs(v) >= 1000 else f"{v:.{nd}g}"
    return str(v)


def table(rows, cols):
    out = ["| " + " | ".join(c for c, _ in cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        out.append("| " + " | ".join(fmt(get(r)) for _, get in cols) + " |")
    return out + [""]


def include_notes(R, path):
    """A notes file of the output folder (how the runs were made, written by whoever ran them), verbatim, if present."""
    if os.path.exists(path):
        R.w(open(path).read().rstrip(), "")


FROZEN = "paper_grid_and_courant_7ac11e5.md"      # the last paper-grid tunnel runs and C-study, kept verbatim (outputs not kept)


def frozen(R):
    """Link the frozen record of sections whose outputs are not here (archive/FROZEN)."""
    if os.path.exists(os.path.join(REPO, "archive", FROZEN)):
        R.w(f"The last runs of this section (main `7ac11e5`, simulation code of `d734961`) are kept verbatim in [{FROZEN}](../../archive/{FROZEN}).", "")
