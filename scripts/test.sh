#!/usr/bin/env bash
# Installs what is missing, builds and runs nave's default test suite (everything not labelled "slow").
# `scripts/test.sh asan` runs it under AddressSanitizer + UndefinedBehaviorSanitizer instead;
# `scripts/test.sh tsan` the threaded render tests under ThreadSanitizer (with a TSan-built TBB);
# `NAVE_TEST_LABEL=slow scripts/test.sh` runs only the long checks.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}
if [[ ${CI:-} == true && $preset == release ]]; then preset=ci; fi  # warnings are errors in CI
if [[ $preset == tsan ]]; then bash scripts/tsan-tbb.sh; fi
# The sanitizer build is clang's, so that the fuzz targets (libFuzzer ships with clang) come from it too.
if [[ $preset == asan ]]; then bash scripts/setup-debian.sh clang libclang-rt-14-dev; fi
bash scripts/build.sh "$preset"
if [[ -n ${NAVE_TEST_LABEL:-} ]]; then
  ctest --test-dir "build/$preset" --output-on-failure -j "$(nproc)" -L "$NAVE_TEST_LABEL"
else
  ctest --preset "$preset" -j "$(nproc)"
fi
