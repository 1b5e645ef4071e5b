#!/bin/bash
# The main job on a fresh Debian 12 machine (as root): installs, builds and runs the arch-tunnel spalling
# of paper Sec. 4 — intact, open flaw, rigid-filled flaw, grout-filled flaw — on the default grid, writing
# the axial stress curves, field pictures, VTU series (.pvd) and summary.json to out/tunnel.
# Extra arguments go to scripts/paper/tunnel_spalling.py (e.g. --cases intact, --paper, --resume after Ctrl-C).
set -euo pipefail
cd "$(dirname "$0")"
./setup.sh
/usr/bin/python3 scripts/paper/tunnel_spalling.py --out out/tunnel "$@"
