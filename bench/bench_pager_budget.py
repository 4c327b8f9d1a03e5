#!/usr/bin/python3
"""Paging-tuning harness for `nave render --memory` (docs/pager.md).

Builds a procedural abbey store, renders it in-core and under brick budgets that are fractions of the
in-core brick bytes (50 %, 25 %, 10 %, 5 % by default), with the pager's tunables varied at one budget,
and writes a CSV plus two plots (time ratio to in-core vs budget, bytes read vs budget).

    /usr/bin/python3 bench/bench_pager_budget.py             # from the source root, after a release build
    /usr/bin/python3 bench/bench_pager_budget.py --detail 2 --spp 4 --out /tmp/pager-bench

Every render uses the same settings but --memory and --pager; the camera paths go in waves of two passes of the
image (--wave-paths). Numbers come from the EXR's "nave:statistics" metadata and /usr/bin/time; each
setting runs --repeat times and the fastest run is kept (the machine may be shared: CPU seconds are reported too).
"""

import argparse
import csv
import os
import re
import struct
import subprocess
import sys
import time


def exr_string_attributes(path):
    """The string attributes of an OpenEXR file's header (scanline, single part)."""
    with open(path, "rb") as f:
        data = f.read(1 << 20)
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(f"{path}: not an OpenEXR file")
    pos, out = 8, {}
    while pos < len(data) and data[pos] != 0:
        name_end = data.index(b"\0", pos)
        name = data[pos:name_end].decode()
        type_end = data.index(b"\0", name_end + 1)
        kind = data[name_end + 1:type_end].decode()
        (size,) = struct.unpack_from("<i", data, type_end + 1)
        value = data[type_end + 5:type_end + 5 + size]
        if kind == "string":
            out[name] = value.decode(errors="replace")
        pos = type_end + 5 + size
    return out


def parse_statistics(text):
    """'wall=1.234s rays=5 ...' -> {'wall': 1.234, 'rays': 5.0, ...} (non-numbers kept as text)."""
    out = {}
    for item in text.split():
        key, _, value = item.partition("=")
        try:
            out[key] = float(value.rstrip("s"))
        except ValueError:
            out[key] = value
    return out


def run(cmd, log):
    log.write("$ " + " ".join(cmd) + "\n")
    log.flush()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    log.write(p.stdout)
    log.flush()
    return p


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nave", default="build/release/src/cli/nave")
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
    ap.add_argument("--variants", default="prefetch=off;overlap=0;overlap=0.25;nearly_empty=1;nearly_empty=65536;"
                    "prefer_resident=0.25;evict=traffic", help="';'-separated --pager settings tried at --tune-at")
    args = ap.parse_args()

    os.makedirs(args.out, exist_ok=True)
    log = open(os.path.join(args.out, "runs.log"), "w")
    store = os.path.join(args.out, f"abbey-{args.detail}-{args.brick_triangles}.nave")
    if not os.path.exists(store):
        print(f"preprocess: abbey detail {args.detail}, {args.brick_triangles} triangles per brick", file=sys.stderr)
        p = run([args.nave, "preprocess", "--generate", f"abbey:detail={args.detail}", "--brick-triangles",
                 str(args.brick_triangles), "-o", store], log)
        if p.returncode != 0:
            sys.exit(f"preprocess failed, see {log.name}")

    w, h = (int(v) for v in args.resolution.lower().split("x"))
    wave = args.wave_paths or 2 * w * h
    common = [args.nave, "render", store, "--config", args.config, "--mode", "path", "--resolution",
              args.resolution, "--spp", str(args.spp), "--threads", str(args.threads), "--wave-paths", str(wave)]

    # The reserve and the in-core brick bytes, from the refusal of a 1-byte budget (per tunables: the wave
    # overlap changes the reserve, and the brick budget must stay the same fraction).
    reserves = {}

    def reserve_and_total(tunables):
        if tunables not in reserves:
            cmd = common + ["--memory", "1", "-o", os.path.join(args.out, "never.exr")]
            if tunables:
                cmd += ["--pager", tunables]
            p = run(cmd, log)
            m_reserve = re.search(r"ray queues and process is [^(]*\((\d+) bytes\)", p.stdout)
            m_total = re.search(r"resident at once take [^,]*, (\d+) bytes", p.stdout)
            if p.returncode == 0 or not m_reserve or not m_total:
                sys.exit(f"could not read the reserve and brick bytes from nave's refusal, see {log.name}")
            reserves[tunables] = (int(m_reserve.group(1)), int(m_total.group(1)))
        return reserves[tunables]

    reserve, total = reserve_and_total("")
    print(f"in-core bricks {total / 2**20:.1f} MiB, reserve {reserve / 2**20:.1f} MiB, wave {wave} paths",
          file=sys.stderr)

    def render_once(label, fraction, tunables):
        exr = os.path.join(args.out, f"{label}.exr")
        cmd = ["/usr/bin/time", "-f", "rss_kb=%M cpu_s=%U+%S"] + common + ["-o", exr]
        if fraction is not None:
            variant_reserve, _ = reserve_and_total(tunables)
            cmd += ["--memory", str(variant_reserve + int(fraction * total))]
        if tunables:
            cmd += ["--pager", tunables]
        start = time.time()
        p = run(cmd, log)
        if p.returncode != 0:
            sys.exit(f"{label}: nave render failed, see {log.name}")
        stats = parse_statistics(exr_string_attributes(exr)["nave:statistics"])
        rss = re.search(r"rss_kb=(\d+)", p.stdout)
        cpu = re.search(r"cpu_s=([\d.]+)\+([\d.]+)", p.stdout)
        return {
            "label": label,
            "budget_fraction": fraction if fraction is not None else 1.0,
            "brick_budget_bytes": int(stats["brick_budget"]) if fraction is not None else total,
            "tunables": tunables or ("in-core" if fraction is None else "default"),
            "time_s": stats["wall"],
            "cpu_s": round(float(cpu.group(1)) + float(cpu.group(2)), 2) if cpu else "",
            "process_s": round(time.time() - start, 3),
            "loads": int(stats["brick_loads"]),
            "reloads": int(stats["brick_reloads"]),
            "evictions": int(stats["brick_evictions"]),
            "bytes_read": int(stats["bytes_read"]),
            "peak_brick_bytes": int(stats["peak_brick_bytes"]),
            # The render's peak (nave measures it when tracing ends) and the whole process's, which includes
            # writing the images through the OpenImageIO plugin afterwards.
            "peak_rss_bytes": int(stats["peak_rss"]),
            "process_peak_rss_bytes": int(rss.group(1)) * 1024 if rss else "",
            "stall_s": stats["stall"],
            "prefetch_loads": int(stats["prefetch_loads"]),
            "prefetch_hits": int(stats["prefetch_hits"]),
            "brick_visits": int(stats["brick_visits"]),
        }

    def render(label, fraction, tunables):
        runs = [render_once(label, fraction, tunables) for _ in range(max(1, args.repeat))]
        row = min(runs, key=lambda r: r["time_s"])
        row["runs_s"] = " ".join(f"{r['time_s']:.2f}" for r in runs)
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
    base = rows[0]["time_s"]
    for r in rows:
        r["time_ratio"] = round(r["time_s"] / base, 3)

    csv_path = os.path.join(args.out, "pager_budget.csv")
    fields = ["label", "budget_fraction", "brick_budget_bytes", "tunables", "time_s", "time_ratio", "runs_s", "cpu_s",
              "loads", "reloads", "evictions", "bytes_read", "peak_brick_bytes", "peak_rss_bytes",
              "process_peak_rss_bytes", "stall_s",
              "prefetch_loads", "prefetch_hits", "brick_visits", "process_s"]
    with open(csv_path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields)
        writer.writeheader()
        writer.writerows(rows)
    print(f"wrote {csv_path}", file=sys.stderr)

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no plots", file=sys.stderr)
        return
    default = [r for r in rows if r["tunables"] in ("default", "in-core")]
    default.sort(key=lambda r: r["budget_fraction"])
    variants = [r for r in rows if r["tunables"] not in ("default", "in-core")]
    for key, ylabel, name in (("time_ratio", "render time / in-core time", "pager_time_ratio.png"),
                              ("bytes_read", "bytes read (MiB)", "pager_bytes_read.png")):
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
