#!/usr/bin/env bash
# The long run of fuzz_assimp_in_process (docs/fuzzing.md): Assimp 5.2 crashes on about one input in
# a few hundred, and every crash or timeout ends the fuzzing process, so this restarts it from its
# growing corpus until RUNS executions in all, keeping every crashing input.
#
#   NAVE_FUZZ_WORK=/tmp/nave_assimp NAVE_FUZZ_RUNS=0 scripts/fuzz.sh 0 fuzz_assimp_in_process  # build, seeds
#   scripts/fuzz_assimp_long.sh /tmp/nave_assimp/fuzz_assimp_in_process [RUNS]   # default 1000000
#
# DIR/corpus is the corpus; crashes and timeouts go to DIR/crashes, each run's log to DIR/logs and one
# line per run to DIR/progress ("run total-executions unix-time executions-of-this-run how-counted"),
# from which a stopped run resumes. Leak detection is off (docs/fuzzing.md says why). libFuzzer's
# timeout handler can hang once it has printed "ALARM:" (it needs a lock the Assimp thread holds):
# a run whose log shows ALARM for 10 s is killed and counted by the last "#N" its log printed.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=$1
runs=${2:-1000000}
bin=$PWD/build/asan/tests/fuzz/fuzz_assimp_in_process
[[ -x $bin ]] || { echo "fuzz_assimp_long.sh: $bin missing: run scripts/fuzz.sh first (above)" >&2; exit 2; }
[[ -d $dir/corpus ]] || { echo "fuzz_assimp_long.sh: $dir/corpus missing: seed it with scripts/fuzz.sh (above)" >&2; exit 2; }
cd "$dir"
mkdir -p crashes logs
scratch=$(mktemp -d "${TMPDIR:-/tmp}/nave_assimp_inputs.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
total=0 i=0
if [[ -s progress ]]; then read -r i total _ < <(tail -1 progress); fi
while ((total < runs)); do
  i=$((i + 1))
  log=logs/$i.txt
  TMPDIR=$scratch "$bin" -detect_leaks=0 -timeout=1 -rss_limit_mb=2048 -runs=$((runs - total)) \
    -print_final_stats=1 -artifact_prefix=crashes/ corpus >"$log" 2>&1 &
  pid=$!
  alarmed=0
  while kill -0 "$pid" 2>/dev/null; do
    sleep 1
    if grep -q '^ALARM:' "$log"; then
      alarmed=$((alarmed + 1))
      if ((alarmed >= 10)); then kill -9 "$pid" 2>/dev/null || true; fi
    fi
  done
  wait "$pid" || true
  n=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  how=stats
  if [[ -z $n ]]; then
    n=$(grep -oE '^#[0-9]+' "$log" | tail -1 | tr -d '#' || true)
    how=last
  fi
  total=$((total + ${n:-0}))
  echo "$i $total $(date +%s) ${n:-0} $how" >>progress
done
echo "fuzz_assimp_long.sh: $total executions in $i runs; $(find crashes -name 'crash-*' | wc -l) crashes, $(find crashes -name 'timeout-*' | wc -l) timeouts, in $dir/crashes" >&2
