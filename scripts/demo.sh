#!/usr/bin/env bash
# nave's main job, end to end, on the built-in default: installs what is missing, builds, generates the procedural
# abbey and preprocesses it into a brick store under a memory budget (streamed, no OBJ in between), verifies the
# store, renders the nave looking east on a June morning at Royaumont under a render memory budget (bricks are
# paged in and out: docs/pager.md), and writes the image.
#
#   bash scripts/demo.sh                 # -> out/abbey.png (tone-mapped sRGB) and out/abbey.exr (linear, spectral -> XYZ)
#
# Settings (environment variables):
#   NAVE_OUT=out          where the store and the images go
#   NAVE_DETAIL=1         abbey detail (1: ~1.5 M triangles; 9: ~8 M; 110: ~96 M; see docs/abbey.md)
#   NAVE_MEMORY=2G        preprocess memory budget
#   NAVE_BRICK_TRIANGLES=100000   target triangles per brick (detail 1 gives 16 bricks)
#   NAVE_RENDER_MEMORY=620M       render memory budget (at 960x640: 35 MiB of it for bricks, a quarter of the
#                                 132 MiB all bricks take; the rest is the film, ray queues, textures, process)
#   NAVE_RESOLUTION=960x640   render size
#   NAVE_MODE=photon          photon (progressive photon mapping, the best here; docs/render.md "The abbey's
#                             noise") or path (path tracing, NAVE_SPP=16 samples per pixel)
#   NAVE_TIME=120             photon mode: render this many seconds (configs/abbey.toml has the rest)
#   NAVE_NOISE=0              photon mode: stop sooner once the estimated relMSE reaches this (0: off)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${NAVE_OUT:-out}
detail=${NAVE_DETAIL:-1}
memory=${NAVE_MEMORY:-2G}
brick_triangles=${NAVE_BRICK_TRIANGLES:-100000}
render_memory=${NAVE_RENDER_MEMORY:-620M}
resolution=${NAVE_RESOLUTION:-960x640}
spp=${NAVE_SPP:-16}
mode=${NAVE_MODE:-photon}
seconds=${NAVE_TIME:-120}
noise=${NAVE_NOISE:-0}

bash scripts/build.sh release
nave=build/release/src/cli/nave
mkdir -p "$out"

echo "== 1/3 generate the abbey (detail $detail) and preprocess it into bricks (budget $memory)" >&2
"$nave" preprocess --generate "abbey:detail=$detail" --memory "$memory" --brick-triangles "$brick_triangles" \
  -o "$out/abbey.nave"
echo "== 2/3 verify every brick" >&2
"$nave" verify "$out/abbey.nave"
if [ "$mode" = photon ]; then
  echo "== 3/3 render (photon mapping for ${seconds} s, $resolution, memory budget $render_memory)" >&2
  how=(--time-limit "$seconds" --noise "$noise")
else
  echo "== 3/3 render (path tracing, $spp samples per pixel, $resolution, memory budget $render_memory)" >&2
  how=(--spp "$spp")
fi
"$nave" render "$out/abbey.nave" --config configs/abbey.toml --mode "$mode" "${how[@]}" \
  --resolution "$resolution" --memory "$render_memory" -o "$out/abbey.exr"
echo "nave demo: wrote $out/abbey.png and $out/abbey.exr" >&2
