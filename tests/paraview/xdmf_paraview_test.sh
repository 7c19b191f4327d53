#!/usr/bin/env bash
# The XDMF sidecars of `tomorig process` (results) and `tomorig reconstruct` (volumes) opened
# headless in ParaView's three XDMF readers (XDMFReader, Xdmf3ReaderS, Xdmf3ReaderT), every array
# of every set checked against h5dump (check_xdmf.py). Needs Debian's pvpython (package
# python3-paraview, in scripts/apt-packages.txt); without it the test is reported as skipped.
# usage: xdmf_paraview_test.sh <tomorig binary>
set -euo pipefail
tomorig="$1"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if ! command -v pvpython >/dev/null || ! command -v h5dump >/dev/null; then
  echo "SKIPPED: pvpython or h5dump not found; install python3-paraview and hdf5-tools (scripts/setup.sh test does)"
  exit 77
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
"$tomorig" simulate --sets 3 --ppp 0.05 --seed 11 -o s.h5 >/dev/null
# A small grid: 3 x 3 x 5 vectors per set, a few seconds.
"$tomorig" process s.h5 --calib truth --grid 32,32,48,0.0195 --window 16,16,16 --overlap 0.5 \
  --deformation-passes 1 -o r.h5 >/dev/null 2>&1
"$tomorig" reconstruct s.h5 --calib truth --grid 24,24,32,0.0195 --set 1 -o v.h5 >/dev/null 2>&1
pvpython --force-offscreen-rendering "$here/check_xdmf.py" results r.xdmf r.h5 volume v.xdmf v.h5
