#!/usr/bin/env bash
# Render time of Sponza with and without its textures (configs/sponza.toml), and what the textures cost: bytes
# read from texture files, the tile cache's cap, peak memory. Needs ../shared/data/models/sponza. Usage, from
# the source root after building the release preset:
#   bench/bench_sponza_textures.sh [RESOLUTION] [SPP]      (default 480x320, 16)
# Prints one Markdown table row per variant (docs/textures.md).
set -euo pipefail
NAVE=${NAVE:-build/release/src/cli/nave}
MODEL=${MODEL:-../shared/data/models/sponza/sponza_merged.obj}
OUT=${OUT:-$(mktemp -d)}
RESOLUTION=${1:-480x320}
SPP=${2:-16}
if [ ! -f "$MODEL" ]; then
  echo "bench_sponza_textures: $MODEL not found (Sponza lives in ../shared/data/models/sponza)" >&2
  exit 2
fi
"$NAVE" -q preprocess "$MODEL" -o "$OUT/sponza.nave"
echo "| variant | time | rays/s | texture bytes read | texture cache cap | peak memory |"
echo "|---|---|---|---|---|---|"
for variant in textures no-textures; do
  flag=""
  [ "$variant" = no-textures ] && flag="--no-textures"
  log="$OUT/$variant.log"
  "$NAVE" render "$OUT/sponza.nave" -c configs/sponza.toml -o "$OUT/$variant.exr" --resolution "$RESOLUTION" \
      --spp "$SPP" $flag >"$log" 2>&1
  time=$(sed -n 's/^  time \([^,]*\), \([^ ]* [^ ]*\) rays\/s.*/\1|\2/p' "$log")
  peak=$(sed -n 's/.*peak memory \([^,]*\),.*/\1/p' "$log")
  tex=$(sed -n 's/^  textures: read \(.*\) through a \(.*\) tile cache.*/\1|\2/p' "$log")
  [ -z "$tex" ] && tex="-|-"
  echo "| $variant | ${time%%|*} | ${time##*|} | ${tex%%|*} | ${tex##*|} | $peak |"
done
echo "images: $OUT/textures.png $OUT/no-textures.png" >&2
