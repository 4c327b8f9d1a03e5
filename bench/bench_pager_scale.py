#!/usr/bin/python3
"""Scale benchmark of `nave render --memory` (docs/pager.md): the 96 M-triangle abbey, in-core and paged.

Generates the abbey store at --detail (110: 96 M triangles) unless it exists, renders it in-core (no --memory)
and under each of --budgets, every render wrapped in /usr/bin/time -v for the whole process's peak resident set
size, and writes DIR/pager_scale.csv, a plot DIR/pager_scale.png (render time ratio to in-core and peak RSS vs
budget) and, on stdout, a Markdown table for the docs. Render numbers (wall, brick loads, bytes read, stall)
come from the "nave:statistics" metadata of each EXR.

    bash bench/setup-bench.sh                              # once: python3-openimageio, matplotlib, time
    /usr/bin/python3 bench/bench_pager_scale.py            # from the source root, after a release build
    /usr/bin/python3 bench/bench_pager_scale.py --detail 1 --resolution 160x107 --spp 1 --budgets 300M,200M

The default case needs about 7 minutes of both cores for the store (docs/preprocess.md) and more for the
renders; the small one above checks the script in seconds. A budget nave refuses (too small for the model) is a row with
status "refused", a render that fails one with status "failed", both with the first line of nave's error as
the reason; the other budgets still run. With --repeat N every setting runs N times and the fastest is kept.
"""

import argparse
import os
import re
import shlex
import sys

import nave_bench

CSV_FIELDS = ["run", "budget", "budget_bytes", "status", "reason", "wall_s", "ratio_to_incore", "loads",
              "bytes_read", "stall_s", "stall_fraction", "peak_rss_bytes", "peak_rss_over_budget_bytes",
              "nave_peak_rss_bytes", "process_wall_s", "runs_s"]


def gib(n):
    return f"{n / 2**30:.2f} GiB"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nave", default=nave_bench.default_nave())
    ap.add_argument("--dir", default="/tmp/nave-scale", help="where the store, images, CSV and plot go")
    ap.add_argument("--detail", type=int, default=110, help="abbey detail (110: 96 M triangles)")
    ap.add_argument("--store", help="the store to reuse or generate (default: DIR/abbey<detail>.nave)")
    ap.add_argument("--preprocess-memory", default="4G", help="--memory of nave preprocess")
    ap.add_argument("--config", default="configs/abbey.toml")
    ap.add_argument("--resolution", default="640x427")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--budgets", default="2G,1G", help="comma-separated --memory values, after the in-core run")
    ap.add_argument("--render-args", default="",
                    help="more nave render arguments, given with '=' since they start with '-': "
                         "--render-args='--threads 2'")
    ap.add_argument("--repeat", type=int, default=1, help="runs per setting; the fastest is kept")
    args = ap.parse_args()

    budgets = [b.strip() for b in args.budgets.split(",") if b.strip()]
    try:
        budget_bytes = {b: nave_bench.parse_byte_size(b) for b in budgets}
    except ValueError as e:
        sys.exit(f"--budgets: {e}")
    os.makedirs(args.dir, exist_ok=True)
    log = open(os.path.join(args.dir, "runs.log"), "w")
    store = args.store or os.path.join(args.dir, f"abbey{args.detail}.nave")

    if os.path.exists(store):
        print(f"reusing {store}", file=sys.stderr)
    else:
        print(f"preprocess: abbey detail {args.detail} -> {store} (--memory {args.preprocess_memory})",
              file=sys.stderr)
        # nave writes the store under a temporary name and renames it when complete, so an interrupted run
        # leaves nothing here to be mistaken for a store next time.
        p = nave_bench.run_timed([args.nave, "preprocess", "--generate", f"abbey:detail={args.detail}",
                                  "--memory", args.preprocess_memory, "-o", store], log)
        if not p.ok:
            sys.exit(f"preprocess failed: {nave_bench.error_reason(p.output, p.returncode)} (see {log.name})")
        print(f"preprocess: {p.elapsed_s:.1f} s, peak RSS {gib(p.peak_rss_bytes)}", file=sys.stderr)

    common = [args.nave, "render", store, "--config", args.config, "--mode", "path", "--resolution",
              args.resolution, "--spp", str(args.spp)] + shlex.split(args.render_args)

    def render_once(label, budget):
        exr = os.path.join(args.dir, f"run-{label}.exr")
        cmd = common + ["-o", exr] + (["--memory", budget] if budget else [])
        r = nave_bench.run_timed(cmd, log)
        row = {"run": label, "budget": budget or "in-core", "budget_bytes": budget_bytes[budget] if budget else ""}
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

    def render(label, budget):
        runs = []
        for _ in range(max(1, args.repeat)):
            runs.append(render_once(label, budget))
            if runs[-1]["status"] == "refused":
                break  # the refusal depends on the sizes only: running it again says the same
        ok = [r for r in runs if r["status"] == "ok"]
        row = min(ok, key=lambda r: r["wall_s"]) if ok else runs[0]
        row["runs_s"] = " ".join(f"{r['wall_s']:.2f}" if r["status"] == "ok" else r["status"] for r in runs)
        if row["status"] == "ok":
            print(f"{label:>16}: {row['wall_s']:8.2f} s (runs {row['runs_s']}), loads {row['loads']}, stall "
                  f"{row['stall_s']:.2f} s, peak RSS {gib(row['peak_rss_bytes'])}", file=sys.stderr)
        else:
            print(f"{label:>16}: {row['status']}: {row['reason']}", file=sys.stderr)
        return row

    rows = [render("in-core", None)] + [render(f"memory-{b}", b) for b in budgets]
    incore = rows[0]
    for r in rows:
        if r["status"] == "ok" and incore["status"] == "ok" and incore["wall_s"] > 0:
            r["ratio_to_incore"] = round(r["wall_s"] / incore["wall_s"], 3)

    csv_path = os.path.join(args.dir, "pager_scale.csv")
    nave_bench.write_csv(csv_path, CSV_FIELDS, rows)
    print(f"wrote {csv_path}", file=sys.stderr)
    plot(args, rows)

    table = []
    for r in rows:
        if r["status"] != "ok":
            table.append([r["budget"], r["status"], "", "", "", "", "", "", "", short_reason(r["reason"])])
            continue
        over = r.get("peak_rss_over_budget_bytes")
        table.append([
            r["budget"], "ok", f"{r['wall_s']:.1f} s",
            f"{r['ratio_to_incore']:.2f}x" if "ratio_to_incore" in r else "",
            r["loads"], gib(r["bytes_read"]) if r["bytes_read"] != "" else "",
            f"{r['stall_s']:.1f} s ({100 * r['stall_fraction']:.0f} %)" if "stall_fraction" in r else "",
            gib(r["peak_rss_bytes"]) if r["peak_rss_bytes"] != "" else "",
            (f"{'+' if over >= 0 else '-'}{abs(over) / 2**20:.0f} MiB" if over is not None else ""),
            ""])
    print(f"abbey detail {args.detail}, {args.resolution}, {args.spp} spp, path mode"
          f"{', ' + args.render_args if args.render_args else ''}; peak RSS of the whole process (time -v)\n")
    print(nave_bench.markdown_table(["--memory", "status", "render time", "vs in-core", "brick loads", "read",
                                     "stall", "peak RSS", "peak RSS - budget", "note"], table))


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
    # Refused and failed rows have nothing to plot; in-core has no budget, so it is drawn as a line.
    paged = sorted((r for r in rows if r["status"] == "ok" and r["budget_bytes"] != ""),
                   key=lambda r: r["budget_bytes"])
    incore = rows[0] if rows[0]["status"] == "ok" else None
    x = [r["budget_bytes"] / 2**30 for r in paged]
    fig, (ax_time, ax_rss) = plt.subplots(1, 2, figsize=(10, 4))
    ratios = [r.get("ratio_to_incore", float("nan")) for r in paged]
    ax_time.plot(x, ratios, "o-", label="paged")
    if incore:
        ax_time.axhline(1.0, color="gray", linestyle="--", label="in-core")
    ax_time.set_xlabel("--memory (GiB)")
    ax_time.set_ylabel("render time / in-core render time")
    ax_rss.plot(x, [r["peak_rss_bytes"] / 2**30 if r["peak_rss_bytes"] != "" else float("nan") for r in paged],
                "o-", label="paged: peak RSS")
    if x:
        ax_rss.plot([0, 1.1 * max(x)], [0, 1.1 * max(x)], ":", color="red", label="peak RSS = --memory")
    if incore and incore["peak_rss_bytes"] != "":
        ax_rss.axhline(incore["peak_rss_bytes"] / 2**30, color="gray", linestyle="--", label="in-core: peak RSS")
    ax_rss.set_xlabel("--memory (GiB)")
    ax_rss.set_ylabel("peak resident set size (GiB)")
    ax_time.set_ylim(0, 1.15 * max([1.0] + [v for v in ratios if v == v]))  # v == v: not NaN
    ax_rss.set_ylim(bottom=0)
    for ax in (ax_time, ax_rss):
        ax.set_xlim(left=0)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"abbey detail {args.detail}, {args.resolution}, {args.spp} spp")
    fig.tight_layout()
    path = os.path.join(args.dir, "pager_scale.png")
    fig.savefig(path, dpi=120)
    print(f"wrote {path}", file=sys.stderr)


if __name__ == "__main__":
    main()
