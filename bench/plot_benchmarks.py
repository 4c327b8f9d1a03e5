#!/usr/bin/python3
"""Plots Google Benchmark results for nave.

Usage:
  BENCH --benchmark_format=json --benchmark_out=results.json
  /usr/bin/python3 bench/plot_benchmarks.py results.json [more.json ...] -o plots/ [--counter items_per_second]

One bar chart per benchmark family (the name before the first '/'), one bar per argument set, showing the
chosen counter (default: items_per_second, i.e. triangles/s or rays/s as the benchmark reports it) or, when a
benchmark lacks it, real time. Needs python3-matplotlib (bash bench/setup-bench.sh installs it).
"""
import argparse
import collections
import json
import os
import sys


def load(paths):
    runs = []
    for path in paths:
        try:
            with open(path) as f:
                data = json.load(f)
        except (OSError, json.JSONDecodeError) as e:
            sys.exit(f"plot_benchmarks: cannot read {path}: {e}")
        if "benchmarks" not in data:
            sys.exit(f"plot_benchmarks: {path} has no 'benchmarks' list (not Google Benchmark JSON output)")
        for b in data["benchmarks"]:
            if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "mean":
                continue
            runs.append(b)
    return runs


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("inputs", nargs="+", help="Google Benchmark JSON files")
    parser.add_argument("-o", "--out", default="bench-plots", help="output directory for PNG files")
    parser.add_argument("--counter", default="items_per_second", help="counter to plot")
    args = parser.parse_args()

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    families = collections.OrderedDict()
    for run in load(args.inputs):
        name = run.get("run_name", run["name"])
        families.setdefault(name.split("/")[0], []).append(run)

    os.makedirs(args.out, exist_ok=True)
    for family, runs in families.items():
        labels, values = [], []
        for r in runs:
            name = r.get("run_name", r["name"])
            labels.append(name[len(family) + 1:] or family)
            values.append(r.get(args.counter, r.get("real_time")))
        unit = args.counter if args.counter in runs[0] else f"real time ({runs[0].get('time_unit', 'ns')})"
        fig, ax = plt.subplots(figsize=(max(4, 0.8 * len(labels) + 2), 3.5))
        ax.bar(range(len(values)), values, color="#4c72b0")
        ax.set_xticks(range(len(values)))
        ax.set_xticklabels(labels, rotation=30, ha="right", fontsize=8)
        ax.set_ylabel(unit)
        ax.set_title(family)
        fig.tight_layout()
        out = os.path.join(args.out, f"{family}.png")
        fig.savefig(out, dpi=110)
        plt.close(fig)
        print(out)


if __name__ == "__main__":
    main()
