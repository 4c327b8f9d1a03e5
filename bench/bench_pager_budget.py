#!/usr/bin/python3
"""Paging-tuning harness for `nave render --memory` (docs/pager.md).

Builds a procedural abbey store, renders it in-core and under brick budgets that are fractions of the
in-core brick bytes (50 %, 25 %, 10 %, 5 % by default), with the pager's tunables varied at one budget,
and writes a CSV plus two plots (time ratio to in-core vs budget, bytes read vs budget).

    bash bench/setup-bench.sh                                 # once: python3-openimageio, matplotlib, time
    /usr/bin/python3 bench/bench_pager_budget.py             # from the source root, after a release build
    /usr/bin/python3 bench/bench_pager_budget.py --detail 2 --spp 4 --out /tmp/pager-bench

Every render uses the same settings but --memory and --pager; the camera paths go in waves of two passes of the
image (--wave-paths). Numbers come from the EXR's "nave:statistics" metadata and /usr/bin/time; each
setting runs --repeat times and the fastest run is kept (the machine may be shared: CPU seconds are reported too).
A budget nave refuses (below the reserve plus the largest brick) or a run that fails is a row with status
"refused" or "failed" and the first line of nave's error as its reason; the other budgets still run, and the
plots leave such rows out.
"""

import argparse
import os
import re
import sys
import time

import nave_bench


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nave", default=nave_bench.default_nave())
    ap.add_argument("--out", default="bench-pager")
    ap.add_argument("--detail", type=int, default=1)
    ap.add_argument("--brick-triangles", type=int, default=16000)
    ap.add_argument("--config", default="configs/abbey.toml")
    ap.add_argument("--resolution", default="480x320")
    ap.add_argument("--spp", type=int, default=8)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--wave-paths", type=int, default=0, help="default: two passes of the image")
    ap.add_argument("--repeat", type=int, default=2, help="runs per setting; the fastest is kept")
    ap.add_argument("--budgets", default="0.5,0.25,0.1,0.05", help="fractions of the in-core brick bytes")
    ap.add_argument("--tune-at", type=float, default=0.1, help="budget fraction where tunables are varied")
    ap.add_argument("--variants", default="prefetch=off;wave_overlap=0;wave_overlap=0.25;nearly_empty_rays=1;nearly_empty_rays=65536;"
                    "prefer_resident=0.25;evict=traffic", help="';'-separated --pager settings tried at --tune-at")
    args = ap.parse_args()

    os.makedirs(args.out, exist_ok=True)
    log = open(os.path.join(args.out, "runs.log"), "w")
    store = os.path.join(args.out, f"abbey-{args.detail}-{args.brick_triangles}.nave")
    if not os.path.exists(store):
        print(f"preprocess: abbey detail {args.detail}, {args.brick_triangles} triangles per brick", file=sys.stderr)
        p = nave_bench.run_logged([args.nave, "preprocess", "--generate", f"abbey:detail={args.detail}",
                                   "--brick-triangles", str(args.brick_triangles), "-o", store], log)
        if p.returncode != 0:
            sys.exit(f"preprocess failed, see {log.name}")

    w, h = (int(v) for v in args.resolution.lower().split("x"))
    wave = args.wave_paths or 2 * w * h
    common = [args.nave, "render", store, "--config", args.config, "--mode", "path", "--resolution",
              args.resolution, "--spp", str(args.spp), "--threads", str(args.threads), "--wave-paths", str(wave)]

    # The reserve and the in-core brick bytes, from the refusal of a 1-byte budget (per tunables: the wave
    # overlap changes the reserve, and the brick budget must stay the same fraction). A variant whose probe
    # fails (a --pager setting nave rejects) raises ProbeFailed with nave's reason and becomes a failed row.
    reserves = {}

    class ProbeFailed(Exception):
        pass

    def reserve_and_total(tunables):
        if tunables not in reserves:
            cmd = common + ["--memory", "1", "-o", os.path.join(args.out, "never.exr")]
            if tunables:
                cmd += ["--pager", tunables]
            p = nave_bench.run_logged(cmd, log)
            m_reserve = re.search(r"ray queues and process is [^(]*\((\d+) bytes\)", p.stdout)
            m_total = re.search(r"resident at once take [^,]*, (\d+) bytes", p.stdout)
            if p.returncode == 0 or not m_reserve or not m_total:
                reason = nave_bench.error_reason(p.stdout, p.returncode) if p.returncode else "a 1-byte budget ran"
                reserves[tunables] = ProbeFailed(f"no reserve from a 1-byte budget: {reason}")
            else:
                reserves[tunables] = (int(m_reserve.group(1)), int(m_total.group(1)))
        if isinstance(reserves[tunables], ProbeFailed):
            raise reserves[tunables]
        return reserves[tunables]

    try:
        reserve, total = reserve_and_total("")
    except ProbeFailed as e:
        sys.exit(f"{e} (see {log.name})")
    print(f"in-core bricks {total / 2**20:.1f} MiB, reserve {reserve / 2**20:.1f} MiB, wave {wave} paths",
          file=sys.stderr)

    def render_once(label, fraction, tunables):
        exr = os.path.join(args.out, f"{label}.exr")
        cmd = common + ["-o", exr]
        row = {
            "label": label,
            "budget_fraction": fraction if fraction is not None else 1.0,
            "tunables": tunables or ("in-core" if fraction is None else "default"),
        }
        if fraction is not None:
            try:
                variant_reserve, _ = reserve_and_total(tunables)
            except ProbeFailed as e:
                return dict(row, status="failed", reason=str(e))
            row["memory_bytes"] = variant_reserve + int(fraction * total)
            cmd += ["--memory", str(row["memory_bytes"])]
        if tunables:
            cmd += ["--pager", tunables]
        start = time.time()
        r = nave_bench.run_timed(cmd, log)
        row["process_s"] = round(time.time() - start, 3)
        row["cpu_s"] = r.cpu_s if r.cpu_s is not None else ""
        row["process_peak_rss_bytes"] = r.peak_rss_bytes if r.peak_rss_bytes is not None else ""
        if not r.ok:
            row["reason"] = nave_bench.error_reason(r.output, r.returncode)
            row["status"] = nave_bench.run_status(r.returncode, row["reason"])
            return row
        stats = nave_bench.read_statistics(exr)
        row.update({
            "status": "ok",
            "reason": "",
            "brick_budget_bytes": stats["brick_budget"] if fraction is not None else total,
            "time_s": stats["wall"],
            "loads": stats["brick_loads"],
            "reloads": stats["brick_reloads"],
            "evictions": stats["brick_evictions"],
            "bytes_read": stats["bytes_read"],
            "peak_brick_bytes": stats["peak_brick_bytes"],
            # The render's peak (nave measures it when tracing ends) and the whole process's, which includes
            # writing the images through the OpenImageIO plugin afterwards.
            "peak_rss_bytes": stats["peak_rss"],
            "stall_s": stats["stall"],
            "prefetch_loads": stats["prefetch_loads"],
            "resident_hits": stats["resident_hits"],
            "batches": stats["batches"],
        })
        return row

    def render(label, fraction, tunables):
        runs = []
        for _ in range(max(1, args.repeat)):
            runs.append(render_once(label, fraction, tunables))
            if runs[-1]["status"] != "ok" and "process_s" not in runs[-1]:
                break  # failed before nave rendered: running it again says the same
            if runs[-1]["status"] == "refused":
                break  # nave's refusal depends on the sizes only: running it again says the same
        ok = [r for r in runs if r["status"] == "ok"]
        if not ok:
            row = runs[0]
            print(f"{label:>32}: {row['status']}: {row['reason']}", file=sys.stderr)
            return row
        row = min(ok, key=lambda r: r["time_s"])
        row["runs_s"] = " ".join(f"{r['time_s']:.2f}" if r["status"] == "ok" else r["status"] for r in runs)
        print(f"{label:>32}: {row['time_s']:7.2f} s (runs {row['runs_s']}), cpu {row['cpu_s']} s, loads "
              f"{row['loads']:5d}, stall {row['stall_s']:6.2f} s, peak bricks {row['peak_brick_bytes'] / 2**20:6.1f} "
              f"MiB, peak RSS {row['peak_rss_bytes'] / 2**20:6.1f} MiB", file=sys.stderr)
        return row

    rows = [render("in-core", None, "")]
    budgets = [float(b) for b in args.budgets.split(",") if b]
    for f in budgets:
        rows.append(render(f"budget-{f:g}", f, ""))
    for v in [v for v in args.variants.split(";") if v]:
        rows.append(render(f"budget-{args.tune_at:g}-{v.replace('=', '-').replace(',', '_')}", args.tune_at, v))
    base = rows[0]["time_s"] if rows[0]["status"] == "ok" else None
    for r in rows:
        if base and r["status"] == "ok":
            r["time_ratio"] = round(r["time_s"] / base, 3)

    csv_path = os.path.join(args.out, "pager_budget.csv")
    fields = ["label", "budget_fraction", "memory_bytes", "brick_budget_bytes", "tunables", "status", "reason",
              "time_s", "time_ratio", "runs_s", "cpu_s",
              "loads", "reloads", "evictions", "bytes_read", "peak_brick_bytes", "peak_rss_bytes",
              "process_peak_rss_bytes", "stall_s",
              "prefetch_loads", "resident_hits", "batches", "process_s"]
    nave_bench.write_csv(csv_path, fields, rows)
    print(f"wrote {csv_path}", file=sys.stderr)

    plt = nave_bench.pyplot()
    if plt is None:
        print(f"matplotlib missing: no plots ({nave_bench.SETUP_HINT})", file=sys.stderr)
        return
    for key, ylabel, name in (("time_ratio", "render time / in-core time", "pager_time_ratio.png"),
                              ("bytes_read", "bytes read (MiB)", "pager_bytes_read.png")):
        # Refused and failed rows have no numbers to plot, and without an in-core time there is no ratio.
        plotted = [r for r in rows if r["status"] == "ok" and key in r]
        default = sorted((r for r in plotted if r["tunables"] in ("default", "in-core")),
                         key=lambda r: r["budget_fraction"])
        variants = [r for r in plotted if r["tunables"] not in ("default", "in-core")]
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        scale = 1.0 if key == "time_ratio" else 1.0 / 2**20
        ax.plot([100 * r["budget_fraction"] for r in default], [r[key] * scale for r in default], "o-",
                label="default tunables")
        for r in variants:
            ax.plot([100 * r["budget_fraction"]], [r[key] * scale], "x", label=r["tunables"])
        if key == "time_ratio":
            ax.axhspan(1.1, 1.25, color="green", alpha=0.12, label="target 1.1-1.25x")
        ax.set_xscale("log")
        ax.set_xlabel("brick budget (% of in-core brick bytes)")
        ax.set_ylabel(ylabel)
        ax.set_title(f"abbey detail {args.detail}, {args.resolution}, {args.spp} spp, wave {wave} paths")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, name), dpi=120)
        print(f"wrote {os.path.join(args.out, name)}", file=sys.stderr)


if __name__ == "__main__":
    main()
