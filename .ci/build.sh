#!/bin/bash
# Configures SDFCage into build/ with Ninja (and ccache, picked up by CMakeLists.txt when
# installed) and builds it with at most two jobs.
#   bash .ci/build.sh           the library, filters, Python module, ParaView plugin, program
#   bash .ci/build.sh --tests   the same plus the tests
set -euo pipefail
cd "$(dirname "$0")/.."

testing=OFF
case "${1:-}" in
  "") ;;
  --tests) testing=ON ;;
  *) echo "usage: $0 [--tests]" >&2; exit 2 ;;
esac

# /usr/bin/python3 is the interpreter that sees ParaView's VTK (python3-paraview); a python3
# earlier on PATH (e.g. pyenv) would not.
cmake -S . -B build -G Ninja \
  -DCMAKE_BUILD_TYPE=Release \
  -DPython3_EXECUTABLE=/usr/bin/python3 \
  -DSDFCAGE_BUILD_TESTING="$testing"
cmake --build build -j2
if command -v ccache >/dev/null; then
  ccache --show-stats | grep -E "Hits|Misses|hit rate" || true
fi
