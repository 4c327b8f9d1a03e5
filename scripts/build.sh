#!/usr/bin/env bash
# Builds nave with a CMake preset (default: release): `scripts/build.sh [release|debug|asan|ci]`.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}
bash scripts/setup-debian.sh
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" -j "$(nproc)"
