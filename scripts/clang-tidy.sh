#!/usr/bin/env bash
# Runs clang-tidy (Debian 12's, 14) with the checks of .clang-tidy on the .cpp files this branch changed since it
# left BASE (default main; committed, staged, unstaged and new files alike), compiled as the release build compiles
# them (build/release/compile_commands.json, configured here if missing). `scripts/clang-tidy.sh --all` checks
# every .cpp file in the build. Fails when clang-tidy reports anything; prints the findings and a count per check.
#
#   bash scripts/clang-tidy.sh            # what this branch changed since main
#   bash scripts/clang-tidy.sh HEAD~3     # since another base
#   bash scripts/clang-tidy.sh --all      # the whole tree
#   JOBS=4 bash scripts/clang-tidy.sh     # files checked at once (default: the number of cores)
#   NAVE_TIDY_BUILD=build/ci bash scripts/clang-tidy.sh HEAD~10   # another build's compile commands (CI's)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-debian.sh clang-tidy
base=${1:-main}
build=${NAVE_TIDY_BUILD:-build/release}
if [[ ! -f $build/compile_commands.json ]]; then
  cmake --preset "$(basename "$build")" >/dev/null
fi

# Only files the build compiles have compile commands (fuzz targets and benchmarks off in release are skipped).
mapfile -t compiled < <(python3 -c '
import json, os, sys
for entry in json.load(open(sys.argv[1])):
    print(os.path.relpath(os.path.join(entry["directory"], entry["file"])))
' "$build/compile_commands.json" | sort -u)
if [[ $base == --all ]]; then
  candidates=("${compiled[@]}")
else
  # From where this branch left BASE: what BASE gained since is not this branch's change.
  fork=$(git merge-base "$base" HEAD)
  mapfile -t candidates < <({ git diff --name-only --diff-filter=d "$fork" -- '*.cpp'
                              git ls-files --others --exclude-standard -- '*.cpp'; } | sort -u)
fi
declare -A in_build
for f in "${compiled[@]}"; do in_build[$f]=1; done
files=()
for f in "${candidates[@]}"; do
  if [[ -n ${in_build[$f]:-} ]]; then files+=("$f"); fi
done
if ((${#files[@]} == 0)); then
  echo "nave clang-tidy: no compiled .cpp file changed since $base" >&2
  exit 0
fi
echo "nave clang-tidy: checking ${#files[@]} files" >&2

# Generated headers come from the build: check after building, not before.
out=$(mktemp)
trap 'rm -f "$out"' EXIT
printf '%s\n' "${files[@]}" |
  xargs -P "${JOBS:-$(nproc)}" -I{} sh -c 'clang-tidy-14 --quiet --extra-arg=-Wno-unknown-warning-option -p "$1" "$2" 2>/dev/null || true' _ "$build" {} \
  >"$out"
if ! grep -qE '^[^ ]+:[0-9]+:[0-9]+: (warning|error):' "$out"; then
  echo "nave clang-tidy: no findings" >&2
  exit 0
fi
# A header's findings come once per file that includes it: each place is listed and counted once.
grep -E '^[^ ]+:[0-9]+:[0-9]+: (warning|error):' "$out" | sed "s|^$PWD/||" | sort -u
echo "nave clang-tidy: findings per check:" >&2
grep -E '^[^ ]+:[0-9]+:[0-9]+: (warning|error):' "$out" | sed "s|^$PWD/||" | sort -u |
  sed -E 's/.*\[([^]]+)\]$/\1/' | sort | uniq -c | sort -rn >&2
exit 1
