#!/usr/bin/env bash
# Installs the Debian 12 packages the benchmark scripts in bench/ need on top of scripts/setup-debian.sh, only
# those missing (the same installer, given this list).
set -euo pipefail
cd "$(dirname "$0")/.."
packages=(
  python3                  # bench/*.py
  python3-openimageio      # reads the "nave:statistics" metadata of the rendered EXR files
  python3-matplotlib       # the PNG plots of bench_pager_budget.py, bench_pager_scale.py, plot_benchmarks.py
  time                     # /usr/bin/time -v: the peak resident set size of a whole nave process
)
bash scripts/setup-debian.sh "${packages[@]}"
