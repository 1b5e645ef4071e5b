#!/bin/bash
# The main job with sensible defaults on a fresh Debian 12 machine (as root): installs, builds and runs
# the circular-opening reference case (Kirsch), writing CSV/PNG/VTU and summary.json to out/circular_opening.
set -euo pipefail
cd "$(dirname "$0")"
./setup.sh
/usr/bin/python3 scripts/circular_opening.py --out out/circular_opening "$@"
echo "results in $(pwd)/out/circular_opening"
