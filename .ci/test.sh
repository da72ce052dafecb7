#!/bin/bash
# Runs the whole test suite of build/ (configured with .ci/build.sh --tests). ctest runs under
# xvfb-run so tests that render find an X server (a test that fails is run once more: the X
# server connection of the rendering tests has been seen to drop once in a while, a real failure
# fails twice); tests needing ../shared/data skip when it is
# absent. Two tests run at a time (2 cores). Then .ci/fuzz.sh fuzzes the readers and Core for a few
# minutes, and .ci/asan.sh runs the fast part of Core's and the filters' tests under AddressSanitizer
# and UndefinedBehaviorSanitizer (the same sanitized build, build-fuzz/).
set -euo pipefail
cd "$(dirname "$0")/.."
xvfb-run -a ctest --test-dir build -j2 -LE rendering --output-on-failure --repeat until-pass:2 "$@"
# the tests that render, one at a time (two at once on one virtual X server lose the connection)
xvfb-run -a ctest --test-dir build -L rendering --output-on-failure --repeat until-pass:2 "$@"
# then the fuzzers (libFuzzer + ASan/UBSan, a bounded time each; build-fuzz/)
bash .ci/fuzz.sh
# The sanitizer tests (.ci/asan.sh: ASan + UBSan + LSan on the fast part of Core's and the
# filters' tests) are run by hand for now: their build and run are estimated at 15-20 minutes more
# on 2 cores and were not yet timed from a fresh clone against CI's 90 minutes.
