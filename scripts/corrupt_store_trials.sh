#!/usr/bin/env bash
# Flips one bit at every STRIDE-th byte of a store and renders each damaged copy with `nave render`
# (a tiny image, one thread). Each must end in exit code 1 with a message naming the store, or exit 0
# with the very image of the undamaged store; a crash (a signal), another exit code or a render that
# outlives the timeout is a failure. The default suite samples positions in-process
# (tests/render/corrupt_store_render_test.cpp); this goes through the executable and every byte.
#
#   scripts/corrupt_store_trials.sh [STORE [CONFIG [STRIDE]]]
#
# Default STORE: tests/fixtures/models/cylinder_on_box.obj preprocessed; default CONFIG: a 16 x 16
# view of it under a uniform sky. Needs build/release (scripts/build.sh). About a second per flip.
set -euo pipefail
cd "$(dirname "$0")/.."
nave=build/release/src/cli/nave
[[ -x $nave ]] || { echo "corrupt_store_trials.sh: build first (scripts/build.sh)" >&2; exit 2; }
work=$(mktemp -d "${TMPDIR:-/tmp}/nave_corrupt.XXXXXX")
trap 'rm -rf "$work"' EXIT

store=${1:-}
if [[ -z $store ]]; then
  store=$work/cylinder_on_box.nave
  "$nave" preprocess tests/fixtures/models/cylinder_on_box.obj -o "$store" -q
fi
config=${2:-}
if [[ -z $config ]]; then
  config=$work/view.toml
  cat >"$config" <<'EOF'
[camera]
position = [4.0, -5.0, 3.0]
look_at = [0.0, 0.0, 1.0]
up = [0, 0, 1]
fov_deg = 40
resolution = [16, 16]
[sky]
radiance = 1.0
[materials.default]
reflectance = 0.5
[render]
spp = 1
max_depth = 2
seed = 3
threads = 1
EOF
fi
stride=${3:-1}

"$nave" render "$store" -c "$config" -o "$work/reference.exr" -q
size=$(stat -c %s "$store")
errors=0 same=0 failures=0
for ((offset = 0; offset < size; offset += stride)); do
  bad=$work/bad.nave
  cp "$store" "$bad"
  byte=$(od -An -tu1 -j "$offset" -N1 "$bad" | tr -d ' ')
  flipped=$((byte ^ (1 << (offset % 8))))
  printf "\\$(printf '%03o' "$flipped")" | dd of="$bad" bs=1 seek="$offset" conv=notrunc status=none
  rm -f "$work/out.exr"
  status=0
  output=$(timeout 60 "$nave" render "$bad" -c "$config" -o "$work/out.exr" -q 2>&1) || status=$?
  if ((status == 1)) && [[ $output == *"nave: error: "*"$bad"* ]]; then
    errors=$((errors + 1))
  elif ((status == 0)) && "$nave" compare "$work/out.exr" "$work/reference.exr" --reference --json |
      grep -qE '"relmse[a-z_]*": 0[,}]'; then
    same=$((same + 1))
  else
    failures=$((failures + 1))
    echo "byte $offset: exit $status: ${output:-(no output)}" >&2
  fi
done
echo "corrupt_store_trials.sh: $store, $size bytes, stride $stride: $errors errors naming the store," \
     "$same identical images, $failures failures"
((failures == 0))
