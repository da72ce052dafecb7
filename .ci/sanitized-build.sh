#!/bin/bash
# Configures and builds the sanitized build in build-fuzz/ (clang; AddressSanitizer +
# UndefinedBehaviorSanitizer, LeakSanitizer on at run time; libFuzzer's coverage instrumentation):
# the project Testing/Fuzz, which compiles Core once for the fuzz harnesses (.ci/fuzz.sh) and for
# the sanitizer tests of Core and the filters (.ci/asan.sh). Arguments: the targets to build
# (default: all).
#   bash .ci/sanitized-build.sh
#   bash .ci/sanitized-build.sh SDFCageCoreTests
set -euo pipefail
cd "$(dirname "$0")/.."
flags="-O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined"
flags+=" -fsanitize-ignorelist=$PWD/Testing/Fuzz/ubsan_ignore.txt"

CC=clang CXX=clang++ cmake -S Testing/Fuzz -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=None \
  "-DCMAKE_C_FLAGS=$flags" "-DCMAKE_CXX_FLAGS=$flags" -DSDFCAGE_SANITIZER_TESTS=ON
targets=()
for t in "$@"; do
  targets+=(--target "$t")
done
cmake --build build-fuzz -j2 "${targets[@]}"
