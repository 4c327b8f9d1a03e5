#!/usr/bin/python3
"""Scale benchmark of `nave render --memory` (docs/pager.md): the 88 M-triangle abbey, in-core and paged, from
several views, at full detail or with levels of detail.

Generates the abbey store at --detail (110: 88 M triangles; with --lod, with `--levels`) unless it exists. For
each of --views (the abbey's camera spots, configs/abbey.toml with the camera replaced) it renders the store
in-core at full detail (the reference for time and for the image), then under each of --budgets; with --lod it
renders full detail under the budgets too (unless --no-full-paged) and then levels of detail (`--lod auto`)
in-core and under each budget, and compares each levels image with the full-detail one of the same seed (mean
luminance, and the worst region of a 3 x 3 grid: the bias of coarse geometry). Every render is wrapped in
/usr/bin/time -v for the whole process's peak resident set size. Writes DIR/pager_scale.csv, a plot
DIR/pager_scale.png (render time against full-detail in-core, and peak RSS, against the budget, per view) and,
on stdout, a Markdown table for the docs. Render numbers (wall, brick loads, bytes read, stall) come from the
"nave:statistics" metadata of each EXR.

    bash bench/setup-bench.sh                              # once: python3-openimageio, matplotlib, time
    /usr/bin/python3 bench/bench_pager_scale.py            # from the source root, after a release build
    /usr/bin/python3 bench/bench_pager_scale.py --lod --resolution 480x320 --budgets 2G,1G
    /usr/bin/python3 bench/bench_pager_scale.py --detail 1 --resolution 160x107 --spp 1 --budgets 600M,500M \
        --views nave
    # the dust cut into the bricks, rendered from them:
    /usr/bin/python3 bench/bench_pager_scale.py --medium configs/dust.vdb --config configs/abbey_dust.toml \
        --store /tmp/nave-scale/abbey110-dust.nave --resolution 480x320 --budgets 2G

The default case needs about 3 minutes of both cores for the store (docs/preprocess.md) and a few minutes per
view and budget for the renders; the small one above checks the script in a minute. A budget nave refuses (too
small for the model) is a row with status "refused", a render that fails one with status "failed", both with the
first line of nave's error as the reason; the other budgets still run. With --repeat N every setting runs N times
and the fastest is kept.
"""

import argparse
import os
import re
import shlex
import sys

import nave_bench

CSV_FIELDS = ["view", "lod", "run", "budget", "budget_bytes", "status", "reason", "wall_s", "ratio_to_incore", "loads",
              "bytes_read", "stall_s", "stall_fraction", "peak_rss_bytes", "peak_rss_over_budget_bytes",
              "nave_peak_rss_bytes", "process_wall_s", "runs_s", "mean_ratio_to_full",
              "worst_region_ratio_to_full", "exr"]


def gib(n):
    return f"{n / 2**30:.2f} GiB"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nave", default=nave_bench.default_nave())
    ap.add_argument("--dir", default="/tmp/nave-scale", help="where the store, images, CSV and plot go")
    ap.add_argument("--detail", type=int, default=110, help="abbey detail (110: 88 M triangles)")
    ap.add_argument("--store", help="the store to reuse or generate (default: DIR/abbey<detail>.nave)")
    ap.add_argument("--preprocess-memory", default="4G", help="--memory of nave preprocess")
    ap.add_argument("--medium", default="",
                    help="a .vdb given to nave preprocess beside the abbey (cut into the bricks); the --config's "
                         "[medium] grid then becomes \"store\" (configs/abbey_dust.toml)")
    ap.add_argument("--config", default="configs/abbey.toml")
    ap.add_argument("--resolution", default="640x427")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--budgets", default="2G,1G", help="comma-separated --memory values, after the in-core run")
    ap.add_argument("--render-args", default="",
                    help="more nave render arguments, given with '=' since they start with '-': "
                         "--render-args='--threads 2'")
    ap.add_argument("--repeat", type=int, default=1, help="runs per setting; the fastest is kept")
    ap.add_argument("--views", default="nave,crossing_vault,north_aisle",
                    help=f"comma-separated camera spots: {', '.join(nave_bench.VIEWS)}")
    ap.add_argument("--lod", action="store_true",
                    help="a store with levels of detail: full detail, then --lod auto, in-core and paged")
    ap.add_argument("--level-errors", default="", help="with --lod: nave preprocess --level-errors (default nave's)")
    ap.add_argument("--no-full-paged", action="store_true",
                    help="with --lod: skip the full-detail renders under the budgets (only full in-core)")
    args = ap.parse_args()
    views = nave_bench.parse_views(args.views)

    budgets = [b.strip() for b in args.budgets.split(",") if b.strip()]
    try:
        budget_bytes = {b: nave_bench.parse_byte_size(b) for b in budgets}
    except ValueError as e:
        sys.exit(f"--budgets: {e}")
    os.makedirs(args.dir, exist_ok=True)
    log = open(os.path.join(args.dir, "runs.log"), "w")
    store = args.store or os.path.join(args.dir, f"abbey{args.detail}{'-levels' if args.lod else ''}.nave")

    if os.path.exists(store):
        print(f"reusing {store}", file=sys.stderr)
    else:
        print(f"preprocess: abbey detail {args.detail} -> {store} (--memory {args.preprocess_memory})",
              file=sys.stderr)
        # nave writes the store under a temporary name and renames it when complete, so an interrupted run
        # leaves nothing here to be mistaken for a store next time.
        cmd = [args.nave, "preprocess", "--generate", f"abbey:detail={args.detail}", "--memory",
               args.preprocess_memory, "-o", store] + ([args.medium] if args.medium else [])
        if args.lod:
            cmd += ["--levels"] + (["--level-errors", args.level_errors] if args.level_errors else [])
        p = nave_bench.run_timed(cmd, log)
        if not p.ok:
            sys.exit(f"preprocess failed: {nave_bench.error_reason(p.output, p.returncode)} (see {log.name})")
        print(f"preprocess: {p.elapsed_s:.1f} s, peak RSS {gib(p.peak_rss_bytes)}", file=sys.stderr)

    base_text = open(args.config).read()
    if args.medium:
        base_text, n = re.subn(r'(?m)^grid = ".*"$', 'grid = "store"', base_text)
        if n != 1:
            sys.exit(f"--medium: {args.config} has no [medium] grid = \"...\" line to point at the store")

    def render_once(view, lod, budget):
        label = f"{view}-{lod}-{budget or 'in-core'}"
        exr = os.path.join(args.dir, f"run-{label}.exr")
        config = os.path.join(args.dir, f"abbey_{view}.toml")
        cmd = [args.nave, "render", store, "--config", config, "--mode", "path", "--resolution", args.resolution,
               "--spp", str(args.spp), "--lod", lod, "-o", exr] + (["--memory", budget] if budget else [])
        r = nave_bench.run_timed(cmd + shlex.split(args.render_args), log)
        row = {"view": view, "lod": lod, "run": label, "exr": exr, "budget": budget or "in-core",
               "budget_bytes": budget_bytes[budget] if budget else ""}
        if not r.ok:
            row["reason"] = nave_bench.error_reason(r.output, r.returncode)
            row["status"] = nave_bench.run_status(r.returncode, row["reason"])
        if row.get("status") == "refused":
            return row  # a process that only checked the sizes: its time and memory say nothing
        # A failed render keeps what time measured: a run killed for memory shows how far it got.
        row["peak_rss_bytes"] = r.peak_rss_bytes if r.peak_rss_bytes is not None else ""
        row["process_wall_s"] = r.elapsed_s if r.elapsed_s is not None else ""
        if not r.ok:
            return row
        stats = nave_bench.read_statistics(exr)
        row.update(status="ok", reason="", wall_s=stats["wall"], loads=stats.get("brick_loads", ""),
                   bytes_read=stats.get("bytes_read", ""), stall_s=stats.get("stall", ""),
                   nave_peak_rss_bytes=stats.get("peak_rss", ""))
        if isinstance(row["stall_s"], float) and row["wall_s"] > 0:
            # The stall is time the scheduler waited for a load with the workers idle: a share of the wall.
            row["stall_fraction"] = round(row["stall_s"] / row["wall_s"], 4)
        if budget and r.peak_rss_bytes is not None:
            row["peak_rss_over_budget_bytes"] = r.peak_rss_bytes - budget_bytes[budget]
        return row

    def render(view, lod, budget):
        runs = []
        for _ in range(max(1, args.repeat)):
            runs.append(render_once(view, lod, budget))
            if runs[-1]["status"] == "refused":
                break  # the refusal depends on the sizes only: running it again says the same
        ok = [r for r in runs if r["status"] == "ok"]
        row = min(ok, key=lambda r: r["wall_s"]) if ok else runs[0]
        row["runs_s"] = " ".join(f"{r['wall_s']:.2f}" if r["status"] == "ok" else r["status"] for r in runs)
        label = row["run"]
        if row["status"] == "ok":
            print(f"{label:>32}: {row['wall_s']:8.2f} s (runs {row['runs_s']}), loads {row['loads']}, stall "
                  f"{row['stall_s']:.2f} s, peak RSS {gib(row['peak_rss_bytes'])}", file=sys.stderr)
        else:
            print(f"{label:>32}: {row['status']}: {row['reason']}", file=sys.stderr)
        return row

    rows = []
    for view in views:
        with open(os.path.join(args.dir, f"abbey_{view}.toml"), "w") as f:
            f.write(nave_bench.config_for_view(base_text, view))
        full = render(view, "full", None)
        view_rows = [full]
        if not (args.lod and args.no_full_paged):
            view_rows += [render(view, "full", b) for b in budgets]
        if args.lod:
            view_rows += [render(view, "auto", None)] + [render(view, "auto", b) for b in budgets]
        for r in view_rows:
            if r["status"] == "ok" and full["status"] == "ok" and full["wall_s"] > 0:
                r["ratio_to_incore"] = round(r["wall_s"] / full["wall_s"], 3)
            if r["lod"] == "auto" and r["status"] == "ok" and full["status"] == "ok":
                # Same seed: the difference is the levels' bias plus the noise of two paths through them.
                against = nave_bench.compare(args.nave, r["exr"], full["exr"], True, log)
                r["mean_ratio_to_full"] = round(1 / against["ratio_b_to_a"], 4) if against["ratio_b_to_a"] else ""
                r["worst_region_ratio_to_full"] = round(nave_bench.worst_region_ratio(against), 4)
        rows += view_rows

    csv_path = os.path.join(args.dir, "pager_scale.csv")
    nave_bench.write_csv(csv_path, CSV_FIELDS, rows)
    print(f"wrote {csv_path}", file=sys.stderr)
    plot(args, rows)

    table = []
    for r in rows:
        head = [r["view"], r["lod"], r["budget"]]
        if r["status"] != "ok":
            table.append(head + [r["status"], "", "", "", "", "", "", "", "", short_reason(r["reason"])])
            continue
        over = r.get("peak_rss_over_budget_bytes")
        table.append(head + [
            "ok", f"{r['wall_s']:.1f} s",
            f"{r['ratio_to_incore']:.2f}x" if "ratio_to_incore" in r else "",
            r["loads"], gib(r["bytes_read"]) if r["bytes_read"] != "" else "",
            f"{r['stall_s']:.1f} s ({100 * r['stall_fraction']:.0f} %)" if "stall_fraction" in r else "",
            gib(r["peak_rss_bytes"]) if r["peak_rss_bytes"] != "" else "",
            (f"{'+' if over >= 0 else '-'}{abs(over) / 2**20:.0f} MiB" if over is not None else ""),
            (f"{r['mean_ratio_to_full']:.4f} / {r['worst_region_ratio_to_full']:.4f}"
             if r.get("mean_ratio_to_full", "") != "" else ""),
            ""])
    print(f"abbey detail {args.detail}, {args.resolution}, {args.spp} spp, path mode"
          f"{', ' + args.render_args if args.render_args else ''}; peak RSS of the whole process (time -v); "
          "times against full detail in-core; levels' mean (worst region) luminance against full detail's\n")
    print(nave_bench.markdown_table(["view", "lod", "--memory", "status", "render time", "vs full in-core",
                                     "brick loads", "read", "stall", "peak RSS", "peak RSS - budget",
                                     "mean / worst region vs full", "note"], table))


def short_reason(reason):
    """A note for the Markdown table: nave's minimum for a refused budget, else the reason's first words."""
    m = re.search(r"at least ([^(]+?) \(\d+ bytes\) is needed", reason)
    if m:
        return f"needs at least {m.group(1)}"
    return reason if len(reason) <= 100 else reason[:97] + "..."


def plot(args, rows):
    plt = nave_bench.pyplot()
    if plt is None:
        print(f"matplotlib missing: no plot ({nave_bench.SETUP_HINT})", file=sys.stderr)
        return
    fig, (ax_time, ax_rss) = plt.subplots(1, 2, figsize=(11, 4.5))
    largest = 0.0
    # One line per view and level setting; refused and failed rows have nothing to plot, in-core has no budget.
    for view in dict.fromkeys(r["view"] for r in rows):
        for lod in ("full", "auto"):
            paged = sorted((r for r in rows if r["view"] == view and r["lod"] == lod and r["status"] == "ok"
                            and r["budget_bytes"] != ""), key=lambda r: r["budget_bytes"])
            if not paged:
                continue
            x = [r["budget_bytes"] / 2**30 for r in paged]
            largest = max(largest, max(x))
            style = "o-" if lod == "auto" else "s--"
            label = f"{view}, {'levels' if lod == 'auto' else 'full detail'}"
            ax_time.plot(x, [r.get("ratio_to_incore", float("nan")) for r in paged], style, label=label)
            ax_rss.plot(x, [r["peak_rss_bytes"] / 2**30 if r["peak_rss_bytes"] != "" else float("nan")
                            for r in paged], style, label=label)
    ax_time.axhline(1.0, color="gray", linestyle=":", label="full detail in-core")
    ax_time.axhline(1.3, color="red", linestyle=":", label="1.3x")
    if largest:
        ax_rss.plot([0, 1.1 * largest], [0, 1.1 * largest], ":", color="red", label="peak RSS = --memory")
    ax_time.set_xlabel("--memory (GiB)")
    ax_time.set_ylabel("render time / full-detail in-core time")
    ax_rss.set_xlabel("--memory (GiB)")
    ax_rss.set_ylabel("peak resident set size (GiB)")
    ax_time.set_ylim(bottom=0)
    ax_rss.set_ylim(bottom=0)
    for ax in (ax_time, ax_rss):
        ax.set_xlim(left=0)
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    fig.suptitle(f"abbey detail {args.detail}, {args.resolution}, {args.spp} spp")
    fig.tight_layout()
    path = os.path.join(args.dir, "pager_scale.png")
    fig.savefig(path, dpi=120)
    print(f"wrote {path}", file=sys.stderr)


if __name__ == "__main__":
    main()
