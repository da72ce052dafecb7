#!/bin/bash
# Sanitizer tests: Core's unit tests and the filters' tests, built with clang, AddressSanitizer +
# UndefinedBehaviorSanitizer (LeakSanitizer on) into build-fuzz/ (.ci/sanitized-build.sh: the
# fuzzers' build, so Core is compiled once for both), run on the suite's fast part (below). Any
# sanitizer report, crash or failed test fails.
#   bash .ci/asan.sh                      build and run the fast part (called by .ci/test.sh)
#   SANITIZER_TESTS=all bash .ci/asan.sh  every test of those executables
set -euo pipefail
cd "$(dirname "$0")/.."
bash .ci/sanitized-build.sh SDFCageCoreTests SDFCageQualityTests SDFCageFiltersTests SDFCageQualityFilterTests

export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/Testing/Fuzz/lsan.supp:print_suppressions=0"
data="$PWD/../shared/data"
scratch="build-fuzz/Temporary"
mkdir -p "$scratch"

# The slow part is left to the ordinary build's ctest run: Core's tests that took 0.7 s or more
# there (measured 2026-12-02; ten times that or more under ASan) and the parameterized gap shapes
# (Gaps/*); the fast part that stays is about 140 tests, 18 s in the ordinary build. So are the
# filters' tests that run whole pipelines (their Core code is covered by Core's tests). The
# filters' tests that stay: error paths, parameters, the OFF reader and writer, the abort (cancel)
# paths, the quality filter on hand-made cages. SANITIZER_TESTS=all runs all.
filter_cases=(NoSurface EmptyInput Abort Parameters OFFRoundTrip OFFVariants OFFMalformed ActivePointsErrors)
quality_cases=(QualityGoodCube QualityBrokenCages QualityAbort QualityMixedCells)
slow_core=(Gaps/* Inputs/* AnyMeshWidening.* TopologyRepair.SelfCrossingInputRunsNoRound
  Optimization.MIPSReachesFifteenDegreesAndStaysTight Optimization.MIPSImprovesBadTriangles
  Optimization.CancelGivesAValidPartialCage ActivePointAnalysis.InputCoordinatesAndFields
  ActivePoints.ParallelPlatesOnlyOnTheFacingSides ActivePoints.SameResultForOneAndTwoThreads
  ActivePoints.SphereHasNone AnyMeshRepairs.ForcedRulesAreHonoured
  AnyMeshWidening.OffKeepsTheIsovalueOnReportsTheWiderEnvelope CageCoordinates.InsideTestsAgree
  CageErrors.OpenInputIsCagedAndReported Cancel.FromReportLateInTheRunGivesCancelled
  CancelActivePoints.StopsInsideTheEdgeGraphAndTheSampling CancelDistanceField.InsideOpenVDBsBandExpansion
  CancelSimplification.OutputsNothingOrAVerifiedCage CancelTree.BuildStopsAndLeavesAnEmptyTree
  CancelValidation.ChecksOftenAndOutputsNothingWhenCancelled CoarseFirst.KeepsWhatTheRequestedGridKeeps
  Envelope.LargerIsoValueExplicitAndExactClearance GapShapes.ClosedGenusZeroSelfIntersectionFree
  GapTopologyStrict.RequireTopologyGivesNoCage GenerateCage.OtherVertexCounts
  GenerateCage.TargetZeroKeepsTheEnvelope MemoryBudget.OverTheLimitStopsBeforeTheGridWithTheNeed
  NestedCages.BuiltinShapeLevelsAreExactAndStrictlyNested NestedCages.CancelKeepsTheFinishedLevels
  Optimization.CancelInsideGenerateCage Optimization.DeterministicAcrossThreadCounts
  Optimization.GuaranteesOnGeneratedShapes Optimization.SpacingConcentratesAroundTarget
  Progress.ReportsStagesWithinZeroToOne Results.CarryTheValuesOfARun
  ShapeAwareEnvelope.BuiltinKeepsItsTopologyOnlyWithActivePoints
  ShapeAwareEnvelope.PlatesStaySeparateAndEnclosed Simplification.CancelGivesAValidCoarserCage
  Simplification.CoarseTargetsAreReached Simplification.DebrisIsNeverSweptOut
  Simplification.DeterministicAcrossThreadCounts Simplification.ExactVertexCountsAndGuarantees
  Simplification.PlainQEMFailsWhereConstrainedPasses Simplification.ZeroTargetKeepsTheEnvelope
  TriangleIndex.ClosestPointMatchesBruteForce)
status=0
run() {
  local name="$1"
  shift
  local start=$SECONDS code=0
  "$@" >"build-fuzz/$name.log" 2>&1 || code=$?
  if [ $code = 125 ]; then
    echo "skipped: $name"
  elif [ $code = 0 ] && ! grep -q -E "ERROR:|runtime error:" "build-fuzz/$name.log"; then
    # (VTK's errors fail the filters' tests as in ctest: FAIL_REGULAR_EXPRESSION "ERROR:")
    echo "passed: $name ($((SECONDS - start)) s)"
  else
    echo "FAILED: $name (exit code $code, $((SECONDS - start)) s); the end of build-fuzz/$name.log:"
    tail -n 60 "build-fuzz/$name.log"
    status=1
  fi
}
if [ "${SANITIZER_TESTS:-fast}" = all ]; then
  slow_core=(None)
  filter_cases=(Sphere BuiltinShape OpenInput NoSurface EmptyInput Abort DistanceField Parameters OptimizeFilter
    OFFRoundTrip OFFVariants OFFMalformed ActivePointsBuiltin ActivePointsErrors)
  quality_cases=(QualityGoodCube QualityBrokenCages QualityOfSDFCage QualityAbort QualityMixedCells)
fi
# Which Core and quality tests: where the ordinary build's ctest has run (as in .ci/run, before this
# script), its measured times (build/Testing/Temporary/CTestCostData.txt) pick the tests that took
# under FAST_SECONDS (0.7 s) there, so a slow test added later is left out without editing a list
# (a test never run there is left out too). Without those times, the list above decides.
costs="build/Testing/Temporary/CTestCostData.txt"
fast_seconds="${FAST_SECONDS:-0.7}"
fast_tests() { # ctest prefix -> gtest filter of the tests under fast_seconds
  awk -v p="$1." -v t="$fast_seconds" 'index($1, p) == 1 && $3 > 0 && $3 < t { print substr($1, length(p) + 1) }' \
    "$costs" | paste -sd: -
}
if [ "${SANITIZER_TESTS:-fast}" = fast ] && [ -s "$costs" ] && [ -n "$(fast_tests core)" ]; then
  core_filter="$(fast_tests core)"
  quality_filter="$(fast_tests quality)"
  [ -n "$quality_filter" ] || quality_filter="-CageQuality.RealMeshScaledCopiesAgreeWithExact:CageQuality.GoodBoxAroundSphere"
  echo "asan: $(echo "$core_filter" | tr : '\n' | wc -l) Core and $(echo "$quality_filter" | tr : '\n' | wc -l) quality tests under ${fast_seconds} s in the ordinary build ($costs)"
else
  core_filter="-$(
    IFS=:
    echo "${slow_core[*]}"
  )"
  quality_filter="-CageQuality.RealMeshScaledCopiesAgreeWithExact:CageQuality.GoodBoxAroundSphere"
fi
run core build-fuzz/SDFCageCoreTests "--gtest_filter=$core_filter"
run quality build-fuzz/SDFCageQualityTests "--gtest_filter=$quality_filter"
for c in "${filter_cases[@]}"; do
  run "filters.$c" build-fuzz/SDFCageFiltersTests "$c" "$scratch" "$data"
done
for c in "${quality_cases[@]}"; do
  run "filters.$c" build-fuzz/SDFCageQualityFilterTests "$c" "$scratch"
done
exit $status
