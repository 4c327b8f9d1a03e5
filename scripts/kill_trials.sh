#!/usr/bin/env bash
# kill -9 at random moments of `nave preprocess` and of `nave render --checkpoint`, TRIALS times
# each (docs/kill_trials.md). After every kill it checks that:
#   - the output is absent, the one from before the run, or complete and valid (a store passes
#     `nave verify`; an image is bit for bit the uninterrupted render's, `nave compare --identical`);
#   - the run's leftover temporaries are named as nave's own, and the next run into the same place
#     removes them and says so in its log;
#   - render: `--resume` from the checkpoint left (or a fresh start when the kill came before the
#     first one) gives the uninterrupted render's image bit for bit.
# Prints one line per trial and a summary; exits 1 if any check failed.
#
#   bash scripts/kill_trials.sh            # 20 trials each, in /tmp/nave-kill-trials
#   TRIALS=5 SEED=7 WORK=/tmp/k bash scripts/kill_trials.sh
set -uo pipefail
cd "$(dirname "$0")/.."
nave=${NAVE:-$PWD/build/release/src/cli/nave}
trials=${TRIALS:-20}
work=${WORK:-/tmp/nave-kill-trials}
RANDOM=${SEED:-1}
failures=0

rm -rf "$work"
mkdir -p "$work/pre" "$work/render"

fail() {
    echo "  FAIL: $*"
    failures=$((failures + 1))
}

# A random delay in [0, max_s) seconds, printed with millisecond precision.
random_delay() {
    awk -v max="$1" -v r="$RANDOM" 'BEGIN { printf "%.3f", max * r / 32768 }'
}

seconds_since() {
    awk -v t0="$1" -v t1="$(date +%s.%N)" 'BEGIN { printf "%.2f", t1 - t0 }'
}

# Temporaries of nave runs in directory $1 and its texture folder, relative to $1 (names carry the
# pid: "*.tmp-<pid>-<n>*", ".tmp-<pid>-<n>.exr", ".nave-tmp-<pid>-<n>").
temporaries() {
    find "$1" -mindepth 1 -maxdepth 2 \( -name '*.tmp-*' -o -name '.tmp-*' -o -name '.nave-tmp-*' \) -prune \
        -printf '%P\n' | sort
}

# ---------------------------------------------------------------------------------------------
# Preprocess: the 1.4 M-triangle abbey into pre/abbey.nave.
store=$work/pre/abbey.nave
preprocess=("$nave" preprocess --generate abbey:detail=1 --memory 2G --brick-triangles 100000)
t0=$(date +%s.%N)
"${preprocess[@]}" -q -o "$work/ref.nave" || { echo "reference preprocess failed"; exit 1; }
pre_s=$(seconds_since "$t0")
echo "preprocess: uninterrupted run $pre_s s; $trials kills at random moments in [0, 1.2 x that)"
declare -A pre_outcomes=()
pre_left=0
pre_named=0
pending=()  # temporaries left by kills and not yet removed
# Each leftover in `pending` must, after the run whose log is $1, either be gone and named in that log,
# or still be there (that run was killed before it looked).
check_pending() {
    local still=()
    for name in "${pending[@]}"; do
        if [[ -e $work/pre/$name ]]; then
            still+=("$name")
        elif grep -q "removed $work/pre/$name, left by an earlier nave run that was killed" "$1"; then
            pre_named=$((pre_named + 1))
        else
            fail "$name was removed without the run saying so"
        fi
    done
    pending=("${still[@]}")
}
for ((i = 1; i <= trials; i++)); do
    # Odd trials start with a complete store in place (it must survive or be replaced whole),
    # even ones with none.
    if ((i % 2 == 1)); then cp "$work/ref.nave" "$store"; else rm -f "$store"; fi
    before=$(sha256sum "$store" 2>/dev/null | cut -c1-64)
    delay=$(random_delay "$(awk -v t="$pre_s" 'BEGIN { print 1.2 * t }')")
    "${preprocess[@]}" -o "$store" >"$work/pre/run.log" 2>&1 &
    pid=$!
    sleep "$delay"
    kill -9 "$pid" 2>/dev/null && killed=yes || killed=no
    wait "$pid" 2>/dev/null
    after=$(sha256sum "$store" 2>/dev/null | cut -c1-64)
    if [[ -z $after ]]; then
        outcome=absent
        [[ -n $before ]] && fail "trial $i: the store that was there is gone"
    elif [[ $after == "$before" ]]; then
        outcome=old
    elif "$nave" -q verify "$store" >/dev/null 2>&1; then
        outcome=complete
    else
        outcome=INVALID
        fail "trial $i: $store is neither the old store nor a valid one"
    fi
    check_pending "$work/pre/run.log"
    mine=$(temporaries "$work/pre" | grep -e "-$pid-" || true)
    left=$(echo "$mine" | grep -c .)
    pre_left=$((pre_left + left))
    for name in $mine; do pending+=("$name"); done
    pre_outcomes[$outcome]=$((${pre_outcomes[$outcome]:-0} + 1))
    printf '  trial %2d: kill -9 at %6.3f s (%s): store %s, %d temporaries left%s\n' "$i" "$delay" \
        "$([[ $killed == yes ]] && echo "while running" || echo "after it finished")" "$outcome" "$left" \
        "$( ((left > 0)) && echo ": $(echo $mine)")"
done
# One more run killed half way, so that the last run below surely has leftovers to remove.
"${preprocess[@]}" -o "$store" >"$work/pre/run.log" 2>&1 &
pid=$!
sleep "$(awk -v t="$pre_s" 'BEGIN { print 0.5 * t }')"
kill -9 "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
check_pending "$work/pre/run.log"
half_left=0
for name in $(temporaries "$work/pre" | grep -e "-$pid-"); do
    pending+=("$name")
    half_left=$((half_left + 1))
done
"${preprocess[@]}" -o "$store" >"$work/pre/clean.log" 2>&1 || fail "the run after the trials failed"
check_pending "$work/pre/clean.log"
((${#pending[@]} == 0)) || fail "temporaries remain after the last run: ${pending[*]}"
[[ -z $(temporaries "$work/pre") ]] || fail "temporaries remain after the last run: $(temporaries "$work/pre")"
"$nave" -q verify "$store" >/dev/null 2>&1 || fail "the store of the last run does not verify"
pre_summary=""
for k in "${!pre_outcomes[@]}"; do pre_summary+="$k ${pre_outcomes[$k]}, "; done
echo "preprocess: ${pre_summary%, }; temporaries left by the kills: $pre_left, plus $half_left by a run" \
    "killed half way; $pre_named removed by a later run that named each in its log, none left"

# ---------------------------------------------------------------------------------------------
# Render with checkpoints after every pass, on one thread and the fullest brick always first
# (prefer_resident above 1, whatever is resident) so that the film adds its samples in one order
# and images can be compared bit for bit; trials alternate path mode (the path guide
# learning) and photon mode in pairs.
out=$work/render/out.exr
ckpt=$work/render/out.ckpt
render_path=("$nave" render "$store" --config configs/abbey.toml --resolution 96x64 --threads 1
             --pager prefer_resident=2 --checkpoint-every 0 --mode path --spp 40)
render_photon=("$nave" render "$store" --config configs/abbey.toml --resolution 96x64 --threads 1
               --pager prefer_resident=2 --checkpoint-every 0 --mode photon --iterations 20 --photons 40000)
declare -A render_s=()
for mode in path photon; do
    declare -n cmd=render_$mode
    # An earlier image under the output's name: a run killed before it finishes must leave it.
    "${cmd[@]}" -q --stop-after 1 --checkpoint "$work/old_$mode.ckpt" -o "$work/old_$mode.exr" ||
        { echo "old $mode render failed"; exit 1; }
    t0=$(date +%s.%N)
    "${cmd[@]}" -q --checkpoint "$work/ref_$mode.ckpt" -o "$work/ref_$mode.exr" ||
        { echo "reference $mode render failed"; exit 1; }
    render_s[$mode]=$(seconds_since "$t0")
    unset -n cmd
done
echo "render: uninterrupted runs ${render_s[path]} s (path, 40 passes), ${render_s[photon]} s (photon, 20 iterations);" \
    "$trials kills at random moments in [0, that)"
declare -A render_outcomes=()
resumed_same=0
render_left=0
for ((i = 1; i <= trials; i++)); do
    mode=$( (((i - 1) / 2 % 2 == 0)) && echo path || echo photon)
    declare -n cmd=render_$mode
    ref=$work/ref_$mode.exr
    old=$work/old_$mode.exr
    rm -f "$ckpt" "$work/render/out.png"
    if ((i % 2 == 1)); then cp "$old" "$out"; else rm -f "$out"; fi
    delay=$(random_delay "${render_s[$mode]}")
    "${cmd[@]}" -q --checkpoint "$ckpt" -o "$out" >"$work/render/run.log" 2>&1 &
    pid=$!
    sleep "$delay"
    kill -9 "$pid" 2>/dev/null && killed=yes || killed=no
    wait "$pid" 2>/dev/null
    if [[ ! -e $out ]]; then
        outcome=absent
        ((i % 2 == 1)) && fail "trial $i: the image that was there is gone"
    elif cmp -s "$out" "$old"; then
        outcome=old
    elif "$nave" compare --identical "$ref" "$out" >/dev/null 2>&1; then
        outcome=complete
    else
        outcome=INVALID
        fail "trial $i: $out is neither the old image nor the complete render"
    fi
    leftovers=$(temporaries "$work/render")
    left=$(echo "$leftovers" | grep -c .)
    render_left=$((render_left + left))
    # Continue: from the checkpoint if the kill left one, else from the start.
    if [[ -e $ckpt ]]; then
        "${cmd[@]}" --resume "$ckpt" -o "$out" >"$work/render/resume.log" 2>&1
        rc=$?
        how=$(grep -o 'resuming from .* after [0-9]* [a-z]*' "$work/render/resume.log" | sed 's/.* after /after /')
    else
        "${cmd[@]}" --checkpoint "$ckpt" -o "$out" >"$work/render/resume.log" 2>&1
        rc=$?
        how="from the start (no checkpoint yet)"
    fi
    ((rc == 0)) || fail "trial $i: the run after the kill failed: $(tail -1 "$work/render/resume.log")"
    for name in $leftovers; do
        grep -q "removed $work/render/$name, left by an earlier nave run that was killed" "$work/render/resume.log" ||
            fail "trial $i: the next run did not say it removed $name"
    done
    [[ -z $(temporaries "$work/render") ]] || fail "trial $i: temporaries remain: $(temporaries "$work/render")"
    if "$nave" compare --identical "$ref" "$out" >/dev/null 2>&1; then
        same=identical
        resumed_same=$((resumed_same + 1))
    else
        same=DIFFERENT
        fail "trial $i: the continued render differs from the uninterrupted one"
    fi
    render_outcomes[$outcome]=$((${render_outcomes[$outcome]:-0} + 1))
    printf '  trial %2d (%s): kill -9 at %6.3f s (%s): image %s, %d temporaries left%s; continued %s: %s\n' \
        "$i" "$mode" "$delay" "$([[ $killed == yes ]] && echo "while running" || echo "after it finished")" \
        "$outcome" "$left" "$( ((left > 0)) && echo " ($(echo $leftovers))")" "$how" "$same"
    unset -n cmd
done
render_summary=""
for k in "${!render_outcomes[@]}"; do render_summary+="$k ${render_outcomes[$k]}, "; done
echo "render: ${render_summary%, }; temporaries left by the kills: $render_left, all removed by the next run;" \
    "continued image identical to the uninterrupted one in $resumed_same of $trials"

if ((failures > 0)); then
    echo "kill trials: $failures checks FAILED"
    exit 1
fi
echo "kill trials: all checks passed"
