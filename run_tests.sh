#!/bin/bash
# The whole test suite on a fresh Debian 12 machine (as root): installs, builds, runs C++ and Python tests.
set -euo pipefail
cd "$(dirname "$0")"
./setup.sh
(cd build && ctest --output-on-failure)
/usr/bin/python3 -m pytest tests -q "$@"
