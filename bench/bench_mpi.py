#!/usr/bin/env python3
"""Real runs of the distributed render (docs/distributed.md): `mpirun -np R nave render` of the procedural
abbey with R ranks of T threads each, for each (R, T) of --runs, against the single process.

For each run: wall time (the job's, by /usr/bin/time -v around mpirun), the rays sent between ranks, messages
and bytes, the ranks' idle time waiting for rays (from the image's "nave:statistics"), the peak resident set
size (the largest of mpirun's children: time -v reports the largest process it waited on, mpirun's children
included), and whether the image equals the single process's in RGB (`nave compare --identical` checks every
channel; here the AOVs, float sums, may differ in their last bit, so RGB is compared with OpenImageIO).
Writes DIR/mpi.csv and, on stdout, a Markdown table for docs/distributed.md.

    bash bench/setup-bench.sh     # once
    /usr/bin/python3 bench/bench_mpi.py --detail 30 --resolution 320x213 --spp 4 --runs 1x2,2x1,4x1

On this 2-core machine, ranks x threads beyond 2 oversubscribe the cores: the runs measure the exchange's
overhead and check the image, not scaling.
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import nave_bench as nb  # noqa: E402

MPI_ENV = {
    "OMPI_ALLOW_RUN_AS_ROOT": "1",
    "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
    "OMPI_MCA_btl_vader_single_copy_mechanism": "none",
}


def rgb(path):
    import OpenImageIO as oiio
    buf = oiio.ImageBuf(path)
    return buf.get_pixels(oiio.FLOAT)[..., :3]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    nb.add_abbey_run_arguments(ap, "/tmp/nave-bench-mpi")
    ap.add_argument("--memory", default="", help="each rank's --memory (default: in-core)")
    ap.add_argument("--runs", default="1x2,2x1,4x1", help="RANKSxTHREADS, comma separated; 1x... is one process")
    ap.add_argument("--pack-rays", default="on", choices=["on", "off"],
                    help="nave render --pack-rays: LZ4 on the rays sent between ranks (default on)")
    ap.add_argument("--coarse-levels-everywhere", default="on", choices=["on", "off"],
                    help="nave render --coarse-levels-everywhere, with --levels: every rank traces the rays "
                         "that meet the coarse levels it keeps (default on)")
    args = ap.parse_args()
    os.makedirs(args.dir, exist_ok=True)
    os.environ.update(MPI_ENV)
    log = open(os.path.join(args.dir, "mpi.log"), "a")
    store, config = nb.abbey_store_and_view(args.nave, args.dir, args.detail, args.store, args.config, args.view,
                                            log, args.levels)
    rows, reference = [], None
    for run in args.runs.split(","):
        ranks, threads = (int(x) for x in run.split("x"))
        out = os.path.join(args.dir, f"r{ranks}t{threads}.exr")
        cmd = [args.nave, "render", store, "-c", config, "--mode", "path", "--resolution", args.resolution,
               "--spp", str(args.spp), "--threads", str(threads), "-q", "-o", out]
        if args.memory:
            cmd += ["--memory", args.memory]
        if ranks > 1:
            cmd = ["mpirun", "-np", str(ranks), "--oversubscribe"] + cmd + [
                "--pack-rays", args.pack_rays, "--coarse-levels-everywhere", args.coarse_levels_everywhere]
        t = nb.run_timed(cmd, log)
        stats = nb.read_statistics(out) if t.ok else {}
        same = ""
        if t.ok:
            image = rgb(out)
            if reference is None and ranks == 1:
                reference = image
            elif reference is not None:
                same = "yes" if (image == reference).all() else "no"
        row = {
            "ranks": ranks, "threads": threads, "status": "ok" if t.ok else nb.error_reason(t.output, t.returncode),
            "wall_s": t.elapsed_s, "peak_rss_gib": round(t.peak_rss_bytes / 2**30, 2) if t.peak_rss_bytes else "",
            "rays": stats.get("rays", ""), "rays_between_ranks": stats.get("rays_between_ranks", 0),
            "messages": stats.get("messages_between_ranks", 0), "bytes": stats.get("bytes_between_ranks", 0),
            "bytes_per_ray": round(stats.get("bytes_between_ranks", 0) / stats["rays_between_ranks"], 1)
            if stats.get("rays_between_ranks") else "",
            "idle_s": stats.get("ranks_idle", ""), "loads_rank0": stats.get("brick_loads", ""),
            "same_rgb": same,
        }
        print(f"{ranks} x {threads}: {row['wall_s']} s, {row['rays_between_ranks']} rays between ranks, "
              f"idle {row['idle_s']}, same image: {same or '-'}", file=sys.stderr)
        rows.append(row)
    fields = list(rows[0].keys())
    nb.write_csv(os.path.join(args.dir, "mpi.csv"), fields, rows)
    print(nb.markdown_table(fields, [[r[k] for k in fields] for r in rows]))


if __name__ == "__main__":
    main()
