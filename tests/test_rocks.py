"""Named rock sets (yade_mpm.rocks) are the only place their numbers are written, and the scene
builders (yade_mpm_paper.cases) build what the paper describes."""
import math
import os
import re

import numpy as np
import pytest

import yade_mpm as ym
from yade_mpm import rocks
from yade_mpm_paper import cases

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_rock_numbers_are_written_once():
    """A copy of a rock set elsewhere in Python (scripts, tests, package) fails here: the moduli and
    Weibull constants of the sets may appear only in py/yade_mpm/rocks.py."""
    literals = [r"22\.41e9", r"9\.87e9", r"18\.4e9", r"1\.1798e29", r"7\.0?e35"]
    pat = re.compile(r"(?<![\w.])(" + "|".join(literals) + r")(?![\w.])")
    hits = []
    for sub in ("py", "scripts", "tests"):
        for dirpath, _, files in os.walk(os.path.join(ROOT, sub)):
            for f in files:
                path = os.path.join(dirpath, f)
                if not f.endswith(".py") or path == rocks.__file__ or path == os.path.abspath(__file__):
                    continue
                with open(path, encoding="utf-8") as fh:
                    for no, line in enumerate(fh, 1):
                        if pat.search(line):
                            hits.append(f"{os.path.relpath(path, ROOT)}:{no}: {line.strip()}")
    assert not hits, "rock parameters copied instead of imported from yade_mpm.rocks:\n" + "\n".join(hits)


def test_overrides_replace_one_value_and_refuse_unknown_names():
    m = rocks.pan2020_sandstone(cohesion=20e6, damage=False)
    assert m.cohesion == 20e6 and not m.damage
    assert m.young == rocks.PAN2020_SANDSTONE["young"] and m.weibullM == rocks.RAYMOND2019_DAMAGE["weibullM"]
    with pytest.raises(TypeError, match="cohesion"):
        rocks.granite(cohesion=1e6)                          # elastic rock: no cohesion
    with pytest.raises(ValueError, match="poisson"):
        rocks.miao2018_sandstone(poisson=0.6)
    assert rocks.elastic(rocks.MIAO2018_SANDSTONE).pWaveSpeed() == pytest.approx(
        math.sqrt(9.87e9 * (1 - 0.22) / ((1 + 0.22) * (1 - 2 * 0.22)) / 2520), rel=1e-12)


def test_arch_tunnel_geometry():
    """Particles missing from the 150 mm square = the arch opening's area, 40 × 25 mm + π·20²/2 mm²."""
    h = 1e-3
    s = cases.arch_tunnel_specimen(h, rocks.pan2020_sandstone())
    missing = (0.15 / (h / 2)) ** 2 - s.numParticles
    assert missing * (h / 2) ** 2 == pytest.approx(0.04 * 0.025 + math.pi * 0.02 ** 2 / 2, rel=0.01)
    pos = ym.get(s, "pos")
    inside = [(0.075, 0.06), (0.075, 0.095), (0.058, 0.079)]   # floor, crown, spandrel (all in the opening)
    for x, y in inside:
        assert np.min(np.hypot(pos[:, 0] - x, pos[:, 1] - y)) > 0.5 * h
