#!/usr/bin/env bash
# The billion-triangle abbey end to end under one memory budget: generate and preprocess it, then
# render it, each under --memory, and print each phase's time, the store's size, the temporary disk
# and the whole process's peak RSS (/usr/bin/time -v) as a Markdown table.
#
#     bash bench/bench_billion.sh                      # detail 1250 (1.02 G triangles), 4G, 1920x1080
#     bash bench/bench_billion.sh --detail 1 --resolution 160x107 --spp 1 --memory 1G   # the script in a minute
#     bash bench/bench_billion.sh --levels --noise 0.05 --time-limit 3600  # levels, until relMSE 0.05 or an hour
#
# Defaults: detail 1250, --memory 4G for both phases, configs/abbey.toml, path mode, 1920x1080, 4 spp.
# --levels preprocesses with levels of detail (a store of its own, abbey<detail>-levels.nave) and renders
# with --lod auto; --noise T renders until the estimated relMSE is at most T (--spp is then the most);
# --time-limit S stops the render after S seconds (nave render --time-limit).
# Everything goes under --dir (default /tmp/nave-billion): the store of detail 1250 takes 988 MiB
# (1.01 bytes per triangle), the preprocess's temporary files 17.8 GiB at their peak (1.45 GiB at
# detail 110), the render's brick cache 17.4 GiB and its spill files a few hundred MiB. On a RAM file
# system they would count against memory.
# An existing store of the same detail is reused (--fresh: generate it again).
set -euo pipefail

detail=1250
memory=4G
resolution=1920x1080
spp=4
mode=path
config=configs/abbey.toml
dir=/tmp/nave-billion
fresh=0
levels=0
noise=""
time_limit=""
while [ $# -gt 0 ]; do
  case "$1" in
    --detail) detail=$2; shift 2 ;;
    --memory) memory=$2; shift 2 ;;
    --resolution) resolution=$2; shift 2 ;;
    --spp) spp=$2; shift 2 ;;
    --mode) mode=$2; shift 2 ;;
    --config) config=$2; shift 2 ;;
    --dir) dir=$2; shift 2 ;;
    --fresh) fresh=1; shift ;;
    --levels) levels=1; shift ;;
    --noise) noise=$2; shift 2 ;;
    --time-limit) time_limit=$2; shift 2 ;;
    -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench_billion.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

cd "$(dirname "$0")/.."
nave=${NAVE:-build/release/src/cli/nave}  # NAVE=path: a copy, so that rebuilding does not touch the run
if [ ! -x "$nave" ] && [ -z "${NAVE:-}" ]; then
  cmake --preset release >/dev/null && cmake --build --preset release -j"$(nproc)" --target nave
fi
if [ ! -x /usr/bin/time ]; then
  echo "bench_billion.sh: needs GNU time (/usr/bin/time): run bash bench/setup-bench.sh" >&2
  exit 1
fi
mkdir -p "$dir"
store="$dir/abbey$detail.nave"
preprocess_args=()
render_args=()
if [ "$levels" = 1 ]; then
  store="$dir/abbey$detail-levels.nave"
  preprocess_args+=(--levels)
  render_args+=(--lod auto)
fi
if [ -n "$noise" ]; then render_args+=(--noise "$noise"); fi
if [ -n "$time_limit" ]; then render_args+=(--time-limit "$time_limit"); fi

# field LOG LABEL: the value after "LABEL:" in /usr/bin/time -v's report.
field() { grep -F "$2:" "$1" | tail -1 | sed 's/.*: //'; }
kib_to_gib() { awk -v k="$1" 'BEGIN { printf "%.2f GiB", k / 1048576 }'; }

rows=()
if [ "$fresh" = 1 ] || [ ! -f "$store" ]; then
  echo "== preprocess: abbey detail $detail -> $store (--memory $memory)" >&2
  log="$dir/preprocess.log"
  /usr/bin/time -v "$nave" preprocess --generate "abbey:detail=$detail" --memory "$memory" "${preprocess_args[@]}" -o "$store" 2>"$log"
  disk=$(grep -F "on disk:" "$log" | tail -1 | sed 's/^ *on disk: *//')
  rate=$(grep -F "time:" "$log" | tail -1 | sed 's/^ *time: *//')
  rows+=("| preprocess | $(field "$log" "Elapsed (wall clock) time (h:mm:ss or m:ss)") | $(kib_to_gib "$(field "$log" "Maximum resident set size (kbytes)")") | $rate; $disk |")
else
  echo "== reusing $store (--fresh to generate it again)" >&2
fi

echo "== render: $mode, $spp spp, $resolution, --memory $memory ${render_args[*]}" >&2
log="$dir/render.log"
/usr/bin/time -v "$nave" render "$store" --config "$config" --mode "$mode" --spp "$spp" \
  --resolution "$resolution" --memory "$memory" --temp-dir "$dir" "${render_args[@]}" \
  -o "$dir/abbey$detail.exr" 2>"$log"
summary=$(grep -E "^  (time|rays moved|noise:|bricks:|ray queues:|brick cache:)" "$log" | sed 's/^ *//' | paste -sd ';' - | sed 's/;/; /g')
rows+=("| render | $(field "$log" "Elapsed (wall clock) time (h:mm:ss or m:ss)") | $(kib_to_gib "$(field "$log" "Maximum resident set size (kbytes)")") | $summary |")

echo
echo "abbey detail $detail ($(du -h "$store" | cut -f1) store), --memory $memory; render $mode, $spp spp, $resolution, $config ${render_args[*]}"
echo
echo "| phase | wall time | peak RSS | details |"
echo "|---|---|---|---|"
printf '%s\n' "${rows[@]}"
echo
echo "logs: $dir/preprocess.log, $dir/render.log; image: $dir/abbey$detail.png"
