#!/usr/bin/env bash
# Fails, listing the files, when C++ sources are not as clang-format (Debian 12's, 14) and .clang-format
# lay them out. `scripts/check-format.sh --fix` formats them instead.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-debian.sh clang-format git
mapfile -t files < <(git ls-files '*.cpp' '*.h')
if ((${#files[@]} == 0)); then
  # clang-format with no file reads its standard input: it would pass whatever the sources are.
  echo "nave: check-format found no C++ source through git ls-files (run it in a git checkout)" >&2
  exit 1
fi
if [[ ${1:-} == --fix ]]; then
  clang-format -i "${files[@]}"
  exit 0
fi
if ! clang-format --dry-run -Werror "${files[@]}" 2>/tmp/nave-format.$$; then
  grep -o '^[^:]*:' /tmp/nave-format.$$ | sort -u | sed 's/:$//; s/^/  /' >&2
  rm -f /tmp/nave-format.$$
  echo "nave: these files are not formatted; run scripts/check-format.sh --fix" >&2
  exit 1
fi
rm -f /tmp/nave-format.$$
