#!/usr/bin/env bash
# A real full disk under `nave preprocess` and `nave render` (docs/full_disk.md): a small tmpfs is
# mounted for each trial, of a size that runs out at some point of the run, and the run writes into it
# (the store and its work directory, preprocess's bins alone, the store and its textures alone, the
# image, the ray-queue spill and brick cache, a checkpoint). After every trial it checks that:
#   - the run either succeeded with a complete output (the store passes `nave verify`, the image is
#     bit for bit the one rendered on a large disk) or exited 1 with a message naming the full
#     file system's path (never another exit code, never a crash);
#   - what was on the disk before the run (an older store, an older image) is still there, byte for
#     byte, when the run failed;
#   - no temporary file or directory of the run is left on the disk.
# A last pass fills the disk's inodes rather than its bytes (tmpfs nr_inodes).
# Needs root (it mounts tmpfs); prints one line per trial and a summary; exits 1 if any check failed,
# 3 if tmpfs cannot be mounted here.
#
#   bash scripts/full_disk_trials.sh              # in /tmp/nave-full-disk
#   WORK=/tmp/d NAVE=build/ci/src/cli/nave bash scripts/full_disk_trials.sh
set -uo pipefail
cd "$(dirname "$0")/.."
nave=${NAVE:-$PWD/build/release/src/cli/nave}
work=${WORK:-/tmp/nave-full-disk}
disk=$work/disk
failures=0
trials=0

fail() {
    echo "  FAIL: $*"
    failures=$((failures + 1))
}

# Runs one trial's command, killed after 10 minutes: a run that never ends (a library waiting
# forever after a failed write) is a failed check with exit code 137, not a CI that never ends.
trial() { timeout -s KILL 600 "$@"; }

unmount() { if mountpoint -q "$disk"; then umount "$disk"; fi; }
trap unmount EXIT

# Mounts an empty tmpfs of $1 bytes (rounded up to pages by the kernel) and optionally $2 inodes.
mount_disk() {
    unmount
    mkdir -p "$disk"
    local opts="size=$1"
    [[ -n ${2:-} ]] && opts+=",nr_inodes=$2"
    mount -t tmpfs -o "$opts" nave-full-disk "$disk"
}

# Temporaries of nave runs below directory $1 (names carry the pid: "*.tmp-<pid>-<n>*",
# ".tmp-<pid>-<n>.exr", ".nave-tmp-<pid>-<n>").
temporaries() {
    find "$1" -mindepth 1 -maxdepth 3 \( -name '*.tmp-*' -o -name '.tmp-*' -o -name '.nave-tmp-*' \) -prune \
        -printf '%P\n' 2>/dev/null | sort
}

bytes_of() { du -sb "$@" 2>/dev/null | awk '{ s += $1 } END { print s + 0 }'; }

if ! [[ -x $nave ]]; then
    echo "nave full-disk trials: no nave executable at $nave (build first, or set NAVE)" >&2
    exit 2
fi
rm -rf "$work"
mkdir -p "$work"
if ! mount_disk 1M 2>"$work/mount.log"; then
    echo "nave full-disk trials: cannot mount a tmpfs here ($(cat "$work/mount.log")); they need root" \
        "and a system that allows mounts: not run" >&2
    exit 3
fi
unmount

# One trial's verdict. $1 label, $2 exit code, $3 log, $4 "ok" check command (string, run with eval
# when the run succeeded), $5.. files that were on the disk before and must be unchanged on failure,
# given as PATH=SHA256.
judge() {
    local label=$1 rc=$2 log=$3 ok_check=$4
    shift 4
    trials=$((trials + 1))
    local outcome
    if ((rc == 0)); then
        if eval "$ok_check"; then
            outcome="complete"
        else
            outcome="INVALID"
            fail "$label: exit 0 but the output does not check: $ok_check"
        fi
    elif ((rc == 1)); then
        outcome="error"
        if ! grep -q "$disk" "$log"; then
            fail "$label: the error does not name the disk ($disk): $(grep 'error' "$log" | tail -1)"
        fi
        local kept
        for kept in "$@"; do
            if [[ $(sha256sum "${kept%%=*}" 2>/dev/null | cut -c1-64) != "${kept#*=}" ]]; then
                fail "$label: ${kept%%=*}, there before the run, changed or is gone"
            fi
        done
    elif ((rc == 137)); then
        outcome="KILLED"
        fail "$label: still running after 10 minutes, killed: $(tail -2 "$log")"
    else
        outcome="EXIT $rc"
        fail "$label: exit code $rc (expected 0, or 1 with a message): $(tail -2 "$log")"
    fi
    local left
    left=$(temporaries "$disk")
    [[ -z $left ]] || fail "$label: temporaries left on the disk: $(echo $left)"
    if [[ $outcome == error ]]; then
        printf '  %-44s error: %s\n' "$label" "$(grep -m1 'error' "$log" | sed "s|$work|WORK|g" | cut -c1-150)"
    else
        printf '  %-44s %s\n' "$label" "$outcome"
    fi
}

# Sizes of a tmpfs for a run that needs about $1 bytes at its peak beside $2 bytes already there: from
# far too small to comfortably enough.
sizes_for() {
    awk -v need="$1" -v base="${2:-0}" 'BEGIN {
        n = split("0.01 0.15 0.5 0.85 0.95 1.05 2.0", f, " ")
        for (i = 1; i <= n; i++) { s = base + int(need * f[i]); if (s < 16384) s = 16384; print s }
    }'
}

# The most the command "$@" ever holds on the disk (bytes used, sampled every 20 ms), run on a large
# tmpfs; its output is removed afterwards.
peak_use() {
    mount_disk 4G
    "$@" >"$work/peak.log" 2>&1 &
    local pid=$! peak=0 used
    while kill -0 "$pid" 2>/dev/null; do
        used=$(df -B1 --output=used "$disk" | tail -1)
        ((used > peak)) && peak=$used
        sleep 0.02
    done
    wait "$pid" || { echo "measuring the disk use of '$*' failed: $(tail -1 "$work/peak.log")" >&2; exit 1; }
    unmount
    echo "$peak"
}

# ---------------------------------------------------------------------------------------------
# Preprocess: the 1.4 M-triangle abbey (16 bricks and its glass textures), and a smaller one as the
# "older store" already on the disk.
model_args=(--generate abbey:detail=1 --memory 2G --brick-triangles 100000)
"$nave" preprocess -q "${model_args[@]}" -o "$work/ref.nave" || { echo "reference preprocess failed"; exit 1; }
"$nave" preprocess -q --generate abbey:detail=0.3 --brick-triangles 100000 -o "$work/old.nave" ||
    { echo "older store's preprocess failed"; exit 1; }
old_bytes=$(bytes_of "$work/old.nave" "$work/old.nave.textures")
store_peak=$(peak_use "$nave" preprocess -q "${model_args[@]}" -o "$disk/abbey.nave")
bins_peak=$(peak_use "$nave" preprocess -q "${model_args[@]}" --temp-dir "$disk" -o "$work/peak.nave")
rm -rf "$work/peak.nave" "$work/peak.nave.textures"
echo "preprocess: at most $store_peak bytes on the disk (store, textures, bins), $bins_peak of them bins;" \
    "the older store takes $old_bytes"

for size in $(sizes_for "$store_peak" "$old_bytes"); do
    mount_disk "$size"
    cp -r "$work/old.nave" "$disk/abbey.nave"
    cp -r "$work/old.nave.textures" "$disk/abbey.nave.textures"
    old_sum=$(sha256sum "$disk/abbey.nave" | cut -c1-64)
    trial "$nave" preprocess -q "${model_args[@]}" -o "$disk/abbey.nave" >"$work/run.log" 2>&1
    judge "store on a ${size}-byte disk (older store there)" $? "$work/run.log" \
        '"$nave" -q verify "$disk/abbey.nave" >/dev/null 2>&1' "$disk/abbey.nave=$old_sum"
done
# The bins alone on the small disk (--temp-dir), the store elsewhere.
for size in $(sizes_for "$bins_peak"); do
    mount_disk "$size"
    rm -rf "$work/out.nave" "$work/out.nave.textures"
    trial "$nave" preprocess -q "${model_args[@]}" --temp-dir "$disk" -o "$work/out.nave" >"$work/run.log" 2>&1
    judge "bins on a ${size}-byte disk (--temp-dir)" $? "$work/run.log" \
        '"$nave" -q verify "$work/out.nave" >/dev/null 2>&1'
    [[ $(temporaries "$work") == "" ]] || fail "bins trial: temporaries beside the store: $(temporaries "$work")"
done

# The store and its converted textures on the small disk, the bins and the generator's texture
# sources elsewhere: the texture conversion meets the full disk (OpenEXR's tiled writer does not
# come back from a failed write, so preprocess must refuse before it starts one).
textures_peak=$(peak_use "$nave" preprocess -q "${model_args[@]}" --temp-dir "$work" -o "$disk/abbey.nave")
echo "preprocess with --temp-dir elsewhere: at most $textures_peak bytes on the disk (store, textures)"
for size in $(sizes_for "$textures_peak"); do
    mount_disk "$size"
    trial "$nave" preprocess -q "${model_args[@]}" --temp-dir "$work" -o "$disk/abbey.nave" >"$work/run.log" 2>&1
    judge "store and textures on a ${size}-byte disk" $? "$work/run.log" \
        '"$nave" -q verify "$disk/abbey.nave" >/dev/null 2>&1'
    [[ $(temporaries "$work") == "" ]] || fail "textures trial: temporaries beside the bins: $(temporaries "$work")"
done

# ---------------------------------------------------------------------------------------------
# Render: one thread and the fullest brick first, so that a run's image is the same bit for bit
# whatever the disk (docs/kill_trials.md says why).
store=$work/ref.nave
base=("$nave" render "$store" --config configs/abbey.toml --resolution 96x64 --threads 1 --mode path --spp 8)
render=("${base[@]}" --pager prefer_resident=2)
"${render[@]}" -q -o "$work/ref.exr" || { echo "reference render failed"; exit 1; }
"${render[@]}" -q --seed 7 -o "$work/old.exr" || { echo "older render failed"; exit 1; }
image_bytes=$(bytes_of "$work/ref.exr" "$work/ref.png")
echo "render: the image (EXR and PNG) takes $image_bytes bytes"
# The older pair takes its bytes rounded up to tmpfs's pages: two more pages than its bytes.
for size in $(sizes_for "$image_bytes" "$((image_bytes + 8192))"); do
    mount_disk "$size"
    cp "$work/old.exr" "$disk/abbey.exr"
    cp "$work/old.png" "$disk/abbey.png"
    old_exr=$(sha256sum "$disk/abbey.exr" | cut -c1-64)
    old_png=$(sha256sum "$disk/abbey.png" | cut -c1-64)
    trial "${render[@]}" -q -o "$disk/abbey.exr" >"$work/run.log" 2>&1
    judge "image on a ${size}-byte disk (older image there)" $? "$work/run.log" \
        '"$nave" compare --identical "$work/ref.exr" "$disk/abbey.exr" >/dev/null 2>&1' \
        "$disk/abbey.exr=$old_exr" "$disk/abbey.png=$old_png"
done

# Paging under a small budget with the spill (ray queues beyond 64 KiB, the decoded-brick cache) on
# the small disk: a failed spill is an error; a failed brick-cache write only stops the caching.
# The budget leaves about five of the 16 bricks' worth of room beside the reserve (film, queues,
# path guide), so that bricks are evicted and reloaded through the cache.
budget=320M
paged=("${base[@]}" --memory "$budget" --pager prefer_resident=2,queue_memory=64K)
"${paged[@]}" --temp-dir "$work" -o "$work/ref_paged.exr" >"$work/run.log" 2>&1 ||
    { echo "reference paged render failed: $(tail -1 "$work/run.log")"; exit 1; }
# What the spill held at most: the ray queues' and the brick cache's figures of the summary, in MiB.
spill_need=$(awk '/ray queues:/ { match($0, /at most [0-9.]+ MiB/); q = substr($0, RSTART + 8, RLENGTH - 12) }
                  /brick cache:/ { match($0, /[0-9.]+ MiB on disk/); c = substr($0, RSTART, RLENGTH - 12) }
                  END { printf "%d", (q + c) * 1048576 }' "$work/run.log")
((spill_need > 0)) || { echo "no spill in the reference paged render: $(tail -4 "$work/run.log")"; exit 1; }
echo "render under --memory $budget: the spill holds at most $spill_need bytes"
for size in $(sizes_for "$spill_need"); do
    mount_disk "$size"
    trial "${paged[@]}" -q --temp-dir "$disk" -o "$work/out.exr" >"$work/run.log" 2>&1
    judge "spill on a ${size}-byte disk (--temp-dir)" $? "$work/run.log" \
        '"$nave" compare --identical "$work/ref_paged.exr" "$work/out.exr" >/dev/null 2>&1'
done

# A checkpoint after every pass on the small disk (the film's sums in double and the path guide: the
# old checkpoint and the new one's temporary side by side at most). Checkpointed passes end with all
# their rays traced, so the reference image is a checkpointed render too.
checkpointed=("${render[@]}" --checkpoint-every 0)
"${checkpointed[@]}" -q --checkpoint "$work/ref.ckpt" -o "$work/ref_ckpt.exr" ||
    { echo "reference checkpointed render failed"; exit 1; }
ckpt_bytes=$(bytes_of "$work/ref.ckpt")
for size in $(sizes_for "$((2 * ckpt_bytes))"); do
    mount_disk "$size"
    trial "${checkpointed[@]}" -q --checkpoint "$disk/abbey.ckpt" -o "$work/out.exr" >"$work/run.log" 2>&1
    judge "checkpoint on a ${size}-byte disk" $? "$work/run.log" \
        '"$nave" compare --identical "$work/ref_ckpt.exr" "$work/out.exr" >/dev/null 2>&1 &&
         "${checkpointed[@]}" -q --resume "$disk/abbey.ckpt" --checkpoint "$work/again.ckpt" \
             -o "$work/resumed.exr" >/dev/null 2>&1 &&
         "$nave" compare --identical "$work/ref_ckpt.exr" "$work/resumed.exr" >/dev/null 2>&1'
done

# Out of inodes rather than bytes: the store's work directory and bins, the image's temporaries.
for inodes in 2 3 4 6 10; do
    mount_disk 512M "$inodes"
    trial "$nave" preprocess -q "${model_args[@]}" -o "$disk/abbey.nave" >"$work/run.log" 2>&1
    judge "store on a disk of $inodes inodes" $? "$work/run.log" \
        '"$nave" -q verify "$disk/abbey.nave" >/dev/null 2>&1'
    mount_disk 512M "$inodes"
    trial "${render[@]}" -q -o "$disk/abbey.exr" >"$work/run.log" 2>&1
    judge "image on a disk of $inodes inodes" $? "$work/run.log" \
        '"$nave" compare --identical "$work/ref.exr" "$disk/abbey.exr" >/dev/null 2>&1'
done

unmount
echo "full-disk trials: $trials runs, $failures failed checks"
((failures == 0))
