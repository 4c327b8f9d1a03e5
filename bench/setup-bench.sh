#!/usr/bin/env bash
# Installs the Debian 12 packages the benchmark scripts in bench/ need on top of scripts/setup-debian.sh, only
# those missing: `apt-get update` runs once and only when something must be installed, so a machine that has
# everything is left untouched.
set -euo pipefail

packages=(
  python3                  # bench/*.py
  python3-openimageio      # reads the "nave:statistics" metadata of the rendered EXR files
  python3-matplotlib       # the PNG plots of bench_pager_budget.py, bench_pager_scale.py, plot_benchmarks.py
  time                     # /usr/bin/time -v: the peak resident set size of a whole nave process
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  exit 0
fi
echo "nave bench setup: installing ${#missing[@]} missing Debian packages: ${missing[*]}" >&2
as_root=()
if [[ $(id -u) -ne 0 ]]; then as_root=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
# Waits for another install on the same machine rather than failing on its dpkg lock.
lock_wait=(-o DPkg::Lock::Timeout=600)
"${as_root[@]}" apt-get "${lock_wait[@]}" update -qq
"${as_root[@]}" apt-get "${lock_wait[@]}" install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "nave bench setup: done" >&2
