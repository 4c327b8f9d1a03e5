#!/usr/bin/env bash
# Checks that includes inside src/render run one way: a file includes headers of its own room and of
# the rooms below it, never of a room above or beside it (docs/render.md, "Rooms"). Rooms, lowest
# first; stream and film stand side by side, neither knowing the other. Exit 1 lists each include
# that runs the wrong way.
set -euo pipefail
cd "$(dirname "$0")/.."
declare -A rank=([bricks]=0 [scene]=1 [stream]=2 [film]=2 [transport]=3 [integrators]=4)
status=0
while IFS= read -r file; do
  room=${file#src/render/}
  room=${room%%/*}
  if [[ -z ${rank[$room]+x} ]]; then
    echo "check-rooms: $file is not in a room of src/render (${!rank[*]})" >&2
    status=1
    continue
  fi
  while IFS=: read -r line include; do
    target=${include#*\"src/render/}
    target=${target%%/*}
    if [[ -z ${rank[$target]+x} ]]; then
      echo "check-rooms: $file:$line includes src/render/$target, which is not in a room" >&2
      status=1
    elif [[ $target != "$room" ]] && ((rank[$target] >= rank[$room])); then
      echo "check-rooms: $file:$line: $room/ includes from $target/, a room above or beside it" >&2
      status=1
    fi
  done < <(grep -n '#include "src/render/' "$file" | cut -d: -f1,2- || true)
done < <(find src/render -name '*.h' -o -name '*.cpp' | sort)
if ((status == 0)); then echo "check-rooms: every include in src/render runs down or within its room"; fi
exit $status
