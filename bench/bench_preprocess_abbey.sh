#!/usr/bin/env bash
# End-to-end preprocess benchmark on the procedural abbey: triangles per second and peak memory at several
# detail levels. Usage: bench/bench_preprocess_abbey.sh [DETAIL...] (default: 1 9 64), from the source root
# after building the release preset. Prints one Markdown table row per detail (docs/preprocess.md).
set -euo pipefail
NAVE=${NAVE:-build/release/src/cli/nave}
OUT=${OUT:-$(mktemp -d)}
THREADS=${THREADS:-2}
details=("$@")
[ ${#details[@]} -eq 0 ] && details=(1 9 64)
echo "| detail | input triangles | bricks | duplicated | store size | bytes/triangle | time | triangles/s | peak memory |"
echo "|---|---|---|---|---|---|---|---|---|"
for d in "${details[@]}"; do
  log="$OUT/abbey-$d.log"
  /usr/bin/time -f "rss_kb=%M" "$NAVE" preprocess --generate "abbey:detail=$d" -o "$OUT/abbey-$d.nave" \
      --threads "$THREADS" >"$log" 2>&1
  input=$(sed -n 's/^input: *.*(\(.*\) triangles.*/\1/p' "$log")
  bricks=$(sed -n 's/^bricks: *\([0-9]*\) .*/\1/p' "$log")
  dup=$(sed -n 's/.*stored triangles, \(.*\) duplicated across cells (\(.*\)).*/\1 (\2)/p' "$log")
  disk=$(sed -n 's/^on disk: *\(.*\) (\(.*\) bytes per input triangle).*/\1|\2/p' "$log")
  time=$(sed -n 's/^time: *\([^(]*\) (.*), \(.*\) triangles\/s.*/\1|\2/p' "$log")
  rss=$(sed -n 's/^rss_kb=//p' "$log")
  echo "| $d | $input | $bricks | $dup | ${disk%%|*} | ${disk##*|} | ${time%%|*} | ${time##*|} | $((rss / 1024)) MiB |"
  rm -f "$OUT/abbey-$d.nave"
done
