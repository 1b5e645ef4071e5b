#!/bin/bash
# Installs the Debian packages yade-mpm needs (when missing), builds the C++ core and its Python
# module, and makes `import yade` and `import yade_mpm` work for /usr/bin/python3 and for `yade`.
set -euo pipefail
cd "$(dirname "$0")"
PKGS="yade libeigen3-dev libboost-python-dev libboost-numpy-dev python3-numpy python3-scipy python3-pytest python3-matplotlib python3-distributed cmake g++ make libopenmpi-dev openmpi-bin"
missing=""
for p in $PKGS; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
if [ -n "$missing" ]; then
	echo "[setup] installing:$missing"
	apt-get update -qq
	DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing >/dev/null
fi
# Debian's /usr/lib/python3/dist-packages/yade points to a missing directory; YADE's modules live in
# yade-double/py. .pth files in the site directory put both YADE and this checkout's py/ on sys.path.
site=$(/usr/bin/python3 -c 'import site; print([p for p in site.getsitepackages() if p.startswith("/usr/local")][0])')
mkdir -p "$site"
echo /usr/lib/x86_64-linux-gnu/yade-double/py > "$site/yade-double.pth"
echo "$(pwd)/py" > "$site/yade_mpm.pth"
exec 9>/tmp/yade-mpm-build.lock
flock 9   # several checkouts/processes may build at once
# The build is out of the source tree: the modules go to build/py/yade_mpm (py/yade_mpm/_build.py finds them);
# modules an older build left inside the package folder are removed.
rm -f py/yade_mpm/_core*.so
cmake -S . -B build -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
# The build's own exit status decides; its errors and warnings are shown, the rest is in build/setup.log.
if ! cmake --build build -j2 > build/setup.log 2>&1; then
	grep -E "error|Error" build/setup.log | head -40
	echo "[setup] build failed (full log: build/setup.log)"; exit 1
fi
grep -E "warning" build/setup.log || true
ls build/py/yade_mpm/_core*.so >/dev/null 2>&1 || { echo "[setup] build failed: build/py/yade_mpm/_core*.so missing"; exit 1; }
echo "[setup] ready: $(cd / && /usr/bin/python3 -c 'import yade, yade_mpm; print("yade", yade.__file__, "| yade_mpm", yade_mpm.__file__, "| core", yade_mpm._core.__file__)' 2>&1 | tail -1)"
