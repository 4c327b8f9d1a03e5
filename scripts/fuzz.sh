#!/usr/bin/env bash
# Builds nave's libFuzzer targets (build preset `fuzz` of the `asan` configuration: clang, ASan +
# UBSan, the same build as `scripts/test.sh asan`'s) and runs each for SECONDS on a seed corpus made from the test fixtures, in a scratch copy (the repository is never modified).
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]     default: 10 seconds, every target but fuzz_assimp_in_process
#
# NAVE_FUZZ_RUNS=N stops each target after N executions instead (SECONDS 0: no time limit);
# NAVE_FUZZ_WORK=DIR keeps the corpora and crash files there (default: a temporary directory,
# removed at the end unless something crashed). Prints one line per target: executions, exec/s,
# crashes. Exits 1 if any target crashed, leaving the crashing inputs in the work directory.
# docs/fuzzing.md explains the targets and the long runs.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-10}
shift || true
targets=("$@")
if ((${#targets[@]} == 0)); then
  # fuzz_assimp_in_process is left out: Assimp 5.2 crashes (segmentation faults, bus errors) on some
  # inputs within seconds; nave isolates that (fuzz_assimp_isolated). docs/fuzzing.md runs it
  # separately, past those crashes. fuzz_vdb too: OpenVDB 10 allocates whatever size a damaged
  # block's header says, which ASan ends as fatal within seconds (a release build throws bad_alloc,
  # which nave reports); docs/fuzzing.md runs it separately. fuzz_cad too: Open CASCADE 7.6
  # dereferences null on some damaged STEP entities within a minute (nave runs it in a child
  # process: fuzz_cad_isolated, in the list when the build has Open CASCADE or IFC++).
  targets=(fuzz_obj fuzz_ply fuzz_stl fuzz_gltf fuzz_assimp_isolated fuzz_model_wire fuzz_store
           fuzz_scene_config)
  if dpkg-query -W -f='${Status}' libocct-data-exchange-dev libifcplusplus-dev 2>/dev/null | grep -q "install ok installed"; then
    targets+=(fuzz_cad_isolated)
  fi
fi

bash scripts/setup-debian.sh clang libclang-rt-14-dev  # clang 14, its sanitizer and libFuzzer runtimes (Debian 12)
cmake --preset asan >/dev/null
cmake --build --preset fuzz -j "$(nproc)"
bin=build/asan/tests/fuzz

work=${NAVE_FUZZ_WORK:-}
keep_work=1
if [[ -z $work ]]; then
  work=$(mktemp -d "${TMPDIR:-/tmp}/nave_fuzz.XXXXXX")
  keep_work=0
fi
mkdir -p "$work"
# The targets write every input to a file: on tmpfs when there is one, in a directory of this run's
# own, removed at the end (a target that crashed leaves its scratch files behind).
scratch_parent=${TMPDIR:-/tmp}
if [[ -d /dev/shm && -w /dev/shm ]]; then scratch_parent=/dev/shm; fi
scratch=$(mktemp -d "$scratch_parent/nave_fuzz_inputs.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
export TMPDIR=$scratch

models=tests/fixtures/models
# The Assimp targets' inputs start with a byte that picks the file's extension from kAssimpFormats
# (tests/fuzz/assimp_formats.h, read here so that the list has one home). Writes each model file
# given after directory $1 into it, that byte prefixed.
assimp_formats=()
mapfile -t assimp_formats < <(sed -n '/kAssimpFormats = {/,/};/p' tests/fuzz/assimp_formats.h |
                               grep -o '"[^"]*"' | tr -d '"')
seed_assimp() {
  local dir=$1 f ext i
  shift
  for f in "$@"; do
    ext=${f##*.}
    for i in "${!assimp_formats[@]}"; do
      if [[ ${assimp_formats[i]} == "$ext" ]]; then
        { printf "\\$(printf %03o "$i")"; cat "$f"; } >"$dir/$(basename "$f")"
        continue 2
      fi
    done
    echo "fuzz.sh: $f: .$ext is not in tests/fuzz/assimp_formats.h" >&2
    exit 2
  done
}
# Seeds for one target, written into directory $2.
seed() {
  local target=$1 dir=$2 f
  mkdir -p "$dir"
  case $target in
    fuzz_obj)
      # OBJ, a NUL, then the MTL the target writes as fuzz.mtl (fuzz_obj.cpp).
      for f in "$models"/*.obj; do
        if grep -q '^mtllib' "$f"; then
          { sed 's/^mtllib .*/mtllib fuzz.mtl/' "$f"; printf '\0'; cat "$models/shapes.mtl"; } \
            >"$dir/$(basename "$f")"
        else
          cp "$f" "$dir/"
        fi
      done ;;
    fuzz_ply) cp "$models"/*.ply "$dir/" ;;
    fuzz_stl) cp "$models"/*.stl "$dir/" ;;
    fuzz_gltf) cp "$models"/*.gltf "$models"/*.glb "$dir/" ;;
    fuzz_assimp_in_process) seed_assimp "$dir" "$models/square.off" "$models"/assimp/* ;;
    # The same, and the OFF files Assimp aborts on.
    fuzz_assimp_isolated) seed_assimp "$dir" "$models"/*.off "$models"/assimp/* ;;
    fuzz_model_wire)
      # The stream needs a model: fuzz_assimp_in_process's round trip is its test; here start from an
      # empty stream and the magic alone.
      printf 'NAVEMDL1' >"$dir/magic"
      printf 'NAVEMDL1\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0' >"$dir/empty_model" ;;
    fuzz_store)
      # First byte: 0 as is, 1 resealed (fuzz_store.cpp).
      for f in tests/fixtures/stores/*.nave; do
        { printf '\0'; cat "$f"; } >"$dir/raw_$(basename "$f")"
        { printf '\1'; cat "$f"; } >"$dir/resealed_$(basename "$f")"
      done ;;
    fuzz_vdb)
      # Coarse dust (a few KiB each): two voxel sizes, two layouts of leaves.
      build/asan/src/cli/nave generate dust --voxel 8 -o "$dir/dust8.vdb" >/dev/null 2>&1
      build/asan/src/cli/nave generate dust --voxel 4 --seed 3 -o "$dir/dust4.vdb" >/dev/null 2>&1 ;;
    fuzz_cad | fuzz_cad_isolated)
      # First byte modulo 3: STEP, IGES, IFC (fuzz_cad.cpp); the files the CAD and IFC tests read.
      for f in tests/fixtures/models/cad/*.step; do { printf '\0'; cat "$f"; } >"$dir/$(basename "$f")"; done
      for f in tests/fixtures/models/cad/*.igs; do { printf '\1'; cat "$f"; } >"$dir/$(basename "$f")"; done
      for f in tests/fixtures/models/ifc/*.ifc; do { printf '\2'; cat "$f"; } >"$dir/$(basename "$f")"; done ;;
    fuzz_scene_config) cp configs/*.toml tests/fixtures/scenes/*.toml "$dir/" ;;
    *) echo "fuzz.sh: unknown target $target" >&2; exit 2 ;;
  esac
}

# Leaks inside third-party libraries that nave cannot free (OpenVDB's reader, on bytes it gives up on) are
# the asan preset's suppressions too.
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/lsan.supp}
limits=(-max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1)
if [[ -n ${NAVE_FUZZ_RUNS:-} ]]; then limits+=(-runs="$NAVE_FUZZ_RUNS"); fi

failed=0
printf '%-24s %12s %10s %8s\n' target executions exec/s crashes
for t in "${targets[@]}"; do
  corpus=$work/$t/corpus
  artifacts=$work/$t/artifacts
  mkdir -p "$artifacts"
  [[ -d $corpus ]] || seed "$t" "$corpus"
  log=$work/$t/log.txt
  status=0
  asan=
  # The isolated Assimp target's children crash by design: SIGSEGV and SIGBUS must reach their default
  # handler (the child resets it) rather than ASan's, as in the `nave` executable.
  if [[ $t == fuzz_assimp_isolated || $t == fuzz_cad_isolated ]]; then asan=allow_user_segv_handler=1; fi
  ASAN_OPTIONS=${ASAN_OPTIONS:-$asan} "$bin/$t" "${limits[@]}" -artifact_prefix="$artifacts/" "$corpus" \
    >"$log" 2>&1 || status=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  crashes=$(find "$artifacts" -type f | wc -l)
  printf '%-24s %12s %10s %8s\n' "$t" "${runs:-?}" "${rate:-?}" "$crashes"
  if ((status != 0 || crashes > 0)); then
    failed=1
    echo "fuzz.sh: $t failed (exit $status): see $log and $artifacts" >&2
    grep -m3 -E 'ERROR: |SUMMARY: |runtime error' "$log" >&2 || true
  fi
done
if ((failed)); then
  echo "fuzz.sh: crashing inputs kept in $work" >&2
  exit 1
fi
if ((!keep_work)); then rm -rf "$work"; fi
