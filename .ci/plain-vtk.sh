#!/bin/bash
# Plain VTK stays supported: builds SDFCage against Debian's own VTK 9.1 (libvtk9-dev,
# python3-vtk9; no ParaView, -DSDFCAGE_USE_PARAVIEW=OFF) in a brand-new Debian 12 root, makes a
# cage of the built-in shape with the program (exit code 0 only for a verified cage), checks the
# cage file, and imports the Python package. Debian's VTK 9.1 and ParaView's VTK 9.2 cannot be
# installed in one root, so this runs in a root of its own, made by the fresh-machine tool
# (../shared/tools/fresh-machine/fresh.sh, or $SDFCAGE_FRESH); it needs root and the Debian
# archive. Called by .ci/test.sh. SDFCAGE_PLAIN_VTK=skip skips it (for a run that is itself inside
# such a root, where a root in a root is not possible).
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${SDFCAGE_PLAIN_VTK:-}" = skip ]; then
  echo "plain-vtk: skipped (SDFCAGE_PLAIN_VTK=skip)"
  exit 0
fi
fresh=${SDFCAGE_FRESH:-../shared/tools/fresh-machine/fresh.sh}
if [ ! -f "$fresh" ]; then
  echo "plain-vtk: NOT CHECKED: the fresh-machine tool ($fresh) is not on this machine;" \
       "set SDFCAGE_FRESH to its path to build against plain VTK here"
  exit 0
fi

# the same packages as .ci/setup.sh, with Debian's VTK in place of ParaView's
packages="cmake ninja-build g++ libeigen3-dev libtbb-dev libopenvdb-dev libboost-iostreams-dev
  libvtk9-dev python3-vtk9 python3-dev"
start=$(date +%s)
log=$(mktemp)
carry=$(mktemp -d)
trap 'rm -rf "$log" "$carry"' EXIT
# Core has no VTK: when the main build (.ci/build.sh, build/) has made it from this same tree, the
# root links that libSDFCageCore.a (passed in as the tool's /shared folder) and compiles only
# what touches VTK: the module, the program and the Python wrapping. Without it, Core is
# compiled there too (SDFCAGE_PLAIN_VTK_CORE=compile forces that).
core_option=""
if [ "${SDFCAGE_PLAIN_VTK_CORE:-reuse}" = reuse ] && [ -f build/lib/libSDFCageCore.a ] &&
  [ -z "$(find Core -newer build/lib/libSDFCageCore.a -name '*.[ch]*' -print -quit)" ]; then
  cp build/lib/libSDFCageCore.a "$carry/"
  core_option="-DSDFCAGE_CORE_LIBRARY=/shared/libSDFCageCore.a"
  echo "plain-vtk: linking the main build's Core (build/lib/libSDFCageCore.a)"
else
  echo "plain-vtk: compiling Core in the root too (no up-to-date build/lib/libSDFCageCore.a)"
fi
code=0
FRESH_SHARED="$carry" bash "$fresh" . "set -e
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends $(echo $packages) >/dev/null
  cmake -S . -B build-vtk -G Ninja -DCMAKE_BUILD_TYPE=Release -DSDFCAGE_USE_PARAVIEW=OFF \
    -DSDFCAGE_BUILD_TESTING=OFF -DPython3_EXECUTABLE=/usr/bin/python3 $core_option >/dev/null
  cmake --build build-vtk -j2 | tail -n 2
  build-vtk/bin/sdfcage -n 200 -o /tmp/builtin_cage.vtp
  python3 -c \"
import sys, glob
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
r = vtkXMLPolyDataReader(); r.SetFileName('/tmp/builtin_cage.vtp'); r.Update()
n = r.GetOutput().GetNumberOfPoints()
print('plain-vtk: the cage file has', n, 'points')
sys.exit(0 if n == 200 else 1)\"
  PYTHONPATH=build-vtk/lib/python3/dist-packages python3 -c \"
import sdfcage
f = sdfcage.vtkSDFCageFilter()
print('plain-vtk: import sdfcage:', sdfcage.__file__, f.GetClassName())\"
" 2>&1 | tee "$log" || code=$?
if [ "$code" != 0 ] && ! grep -q "^fresh.sh: running in a fresh" "$log"; then
  # the tool could not make its root here (no debootstrap, no mount or chroot rights, no archive):
  # nothing of SDFCage ran, so nothing of it failed
  echo "plain-vtk: NOT CHECKED: the fresh-machine tool could not make a Debian root on this machine" \
       "(exit code $code; its messages are above)"
  exit 0
fi
if [ "$code" != 0 ]; then
  echo "plain-vtk: FAILED (exit code $code) after $(( $(date +%s) - start )) s"
  exit "$code"
fi
echo "plain-vtk: passed in $(( $(date +%s) - start )) s"
