#!/bin/bash
# Runs the whole test suite of build/ (configured with .ci/build.sh --tests). ctest runs under
# xvfb-run so tests that render find an X server (a test that fails is run once more: the X
# server connection of the rendering tests has been seen to drop once in a while, a real failure
# fails twice); tests needing ../shared/data skip when it is
# absent. Two tests run at a time (2 cores). Then .ci/fuzz.sh fuzzes the readers and Core for a few
# minutes, .ci/asan.sh runs the sanitizer tests and .ci/plain-vtk.sh builds against plain VTK
# (each while it fits in CI's time: see below).
set -euo pipefail
cd "$(dirname "$0")/.."
xvfb-run -a ctest --test-dir build -j2 -LE rendering --output-on-failure --repeat until-pass:2 "$@"
# the tests that render, one at a time (two at once on one virtual X server lose the connection)
xvfb-run -a ctest --test-dir build -L rendering --output-on-failure --repeat until-pass:2 "$@"
# then the fuzzers (libFuzzer + ASan/UBSan, a bounded time each; build-fuzz/)
bash .ci/fuzz.sh

# Then two stages, while they fit in CI's time: the sanitizer tests (.ci/asan.sh) and the build
# against Debian's plain VTK 9.1 in a brand-new root (.ci/plain-vtk.sh, 9 minutes at load 4-6: it links the main build's Core). A stage starts only if the time it may need is left before
# SDFCAGE_CI_MINUTES (80) after the start of .ci/run (SDFCAGE_CI_START, else this script's start);
# one that does not start says so in capitals; one that starts must pass within the time left.
start="${SDFCAGE_CI_START:-$(date +%s)}"
limit=$((${SDFCAGE_CI_MINUTES:-80} * 60))
stage() {
  local name="$1" need="$2"
  shift 2
  local used=$(($(date +%s) - start))
  local left=$((limit - used))
  if [ "$left" -lt "$need" ]; then
    echo "ci: $name NOT RUN: $((used / 60)) min used of $((limit / 60)), it may need $((need / 60)) min"
    return 0
  fi
  echo "ci: $name (at $((used / 60)) min of $((limit / 60)))"
  local t0=$SECONDS
  timeout "$left" "$@"
  echo "ci: $name passed in $((SECONDS - t0)) s"
}
# The sanitizer tests first (their build adds the test programs to the fuzzers' build-fuzz/, then
# the fast part of Core's and the filters' tests; measured from a fresh clone at load 7-13: about 9
# minutes of build, 514 s of tests), then plain VTK, each only while it fits.
stage "sanitizer tests (.ci/asan.sh)" 1200 bash .ci/asan.sh
stage "plain VTK build (.ci/plain-vtk.sh)" 1200 bash .ci/plain-vtk.sh
