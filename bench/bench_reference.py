#!/usr/bin/python3
"""Error against a converged reference (docs/render.md, "The abbey's noise"): how far a render of the main
job's length is from the image it converges to, in every mode, from several views.

For each view it renders a reference (path tracing, unbiased, --ref-time seconds per seed, two seeds: the
first is the reference, the pair gives the reference's own relMSE), then renders every --modes at --time
seconds with two seeds and compares each against the reference and with its twin:

  - relMSE against the reference on RGB, and after a box blur of 4 pixels (pixel noise falls some 80-fold
    under it; photon discs and blotches survive it), with the reference's own error beside them;
  - the two-seed relMSE (RGB), variance only;
  - the mean luminance against the reference's, of the whole image and its worst region of a 3 x 3 grid:
    a bias shows there.

The views are the abbey's camera spots (docs/abbey.md): the main job's ("nave", looking east), the crossing
vault and the north aisle; the configs are configs/abbey.toml with the camera replaced, written to DIR.
Everything else comes from configs/abbey.toml and --render-args. Writes DIR/reference.csv and, on stdout, a
Markdown table for docs/render.md.

    /usr/bin/python3 bench/bench_reference.py                       # hours: 2 h references, 2 min renders
    /usr/bin/python3 bench/bench_reference.py --ref-time 30 --time 10 --resolution 240x160 --views nave
                                                                    # checks the recipe in about 2 minutes
    /usr/bin/python3 bench/bench_reference.py --lod --detail 30 --modes path --memory "" ...
                                                                    # levels of detail against full detail
    /usr/bin/python3 bench/bench_reference.py --lod --store dragon.nave --config configs/dragon.toml \
        --config-camera --modes path --memory ""                    # the same on another model, its own camera

The reference's error must be well below the errors it measures (the table says both); a reference of two
hours of path tracing on two cores reaches about 0.005 on RGB at 960x640 on the nave view.
"""

import argparse
import os
import sys

import nave_bench

CSV_FIELDS = ["view", "mode", "seconds", "relmse_rgb", "relmse_rgb_blurred", "relmse_pair_rgb", "mean_ratio",
              "worst_region_ratio", "reference_relmse_rgb", "reference_relmse_rgb_blurred"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nave", default=nave_bench.default_nave())
    ap.add_argument("--dir", default="/tmp/nave-reference", help="store, configs, images, CSV")
    ap.add_argument("--store", help="the abbey store (default: DIR/abbey1.nave, generated at detail 1)")
    ap.add_argument("--config", default="configs/abbey.toml")
    ap.add_argument("--views", default="nave,crossing_vault,north_aisle",
                    help=f"comma-separated camera spots: {', '.join(nave_bench.VIEWS)}")
    ap.add_argument("--config-camera", action="store_true",
                    help="one view: the config's own camera, named after the config (for models other than "
                         "the abbey, with --store)")
    ap.add_argument("--modes", default="photon,path", help="render modes to measure")
    ap.add_argument("--resolution", default="960x640")
    ap.add_argument("--time", type=float, default=120, help="seconds of each measured render")
    ap.add_argument("--ref-time", type=float, default=7200, help="seconds of each reference seed")
    ap.add_argument("--memory", default="620M", help="--memory of every render (the main job's)")
    ap.add_argument("--render-args", default="",
                    help="more nave render arguments, given with '=': --render-args='--threads 2'")
    ap.add_argument("--detail", type=int, default=1, help="the generated abbey's detail (without --store)")
    ap.add_argument("--lod", action="store_true",
                    help="a store with levels of detail: every mode is measured at full detail and with "
                         "--lod auto, against a full-detail reference (the bias of coarse geometry)")
    args = ap.parse_args()

    config_view = os.path.splitext(os.path.basename(args.config))[0]
    views = [config_view] if args.config_camera else nave_bench.parse_views(args.views)
    modes = [m.strip() for m in args.modes.split(",") if m.strip()]
    os.makedirs(args.dir, exist_ok=True)
    log = open(os.path.join(args.dir, "runs.log"), "w")
    store = args.store or os.path.join(args.dir, f"abbey{args.detail}{'_levels' if args.lod else ''}.nave")
    if not os.path.exists(store):
        p = nave_bench.run_logged([args.nave, "preprocess", "--generate", f"abbey:detail={args.detail}",
                                   "--memory", "2G", "--brick-triangles", "100000", "-o", store, "-q"] +
                                  (["--levels"] if args.lod else []), log)
        if p.returncode != 0:
            sys.exit(f"preprocess failed: {p.stdout.strip()}")
    base_text = open(args.config).read()
    extra = args.render_args.split()

    def render(config, out, mode, seed, seconds, lod="full"):
        # A --spp / --iterations far beyond the time: the time limit ends every render.
        cmd = [args.nave, "render", store, "--config", config, "-o", out, "--mode", mode,
               "--seed", str(seed), "--time-limit", str(seconds), "--resolution", args.resolution,
               "--lod", lod, "-q"] + (["--memory", args.memory] if args.memory else []) + \
            (["--spp", "1000000"] if mode == "path" else ["--iterations", "1000000"]) + extra
        p = nave_bench.run_logged(cmd, log)
        if p.returncode != 0:
            sys.exit(f"render failed ({' '.join(cmd)}): {p.stdout.strip()}")

    rows = []
    for view in views:
        config = os.path.join(args.dir, f"abbey_{view}.toml")
        with open(config, "w") as f:
            f.write(base_text if args.config_camera else nave_bench.config_for_view(base_text, view))
        ref = [os.path.join(args.dir, f"{view}_reference_seed{s}.exr") for s in (1, 2)]
        for seed, out in zip((1, 2), ref):
            if not os.path.exists(out):
                print(f"{view}: reference seed {seed}, {args.ref_time:.0f} s of path tracing", file=sys.stderr)
                render(config, out, "path", 1000 + seed, args.ref_time)
        ref_pair = nave_bench.compare(args.nave, ref[0], ref[1], False, log)
        for mode, lod in [(m, lod) for m in modes for lod in (("full", "auto") if args.lod else ("full",))]:
            name = mode + ("_lod" if lod == "auto" else "")
            outs = [os.path.join(args.dir, f"{view}_{name}_{args.time:.0f}s_seed{s}.exr") for s in (1, 2)]
            for seed, out in zip((1, 2), outs):
                if os.path.exists(out):
                    continue  # a run before this one made it: delete DIR's images to measure again
                print(f"{view}: {mode}, lod {lod}, seed {seed}, {args.time:.0f} s", file=sys.stderr)
                render(config, out, mode, seed, args.time, lod)
            against = nave_bench.compare(args.nave, outs[0], ref[0], True, log)
            pair = nave_bench.compare(args.nave, outs[0], outs[1], False, log)
            rows.append({
                "view": view, "mode": mode + (" (levels)" if lod == "auto" else ""), "seconds": args.time,
                "relmse_rgb": against["relmse_against_reference_rgb"],
                "relmse_rgb_blurred": against["relmse_against_reference_rgb_blurred"],
                "relmse_pair_rgb": pair["relmse_of_one_rgb"],
                "mean_ratio": against["ratio_b_to_a"] and 1 / against["ratio_b_to_a"],
                "worst_region_ratio": nave_bench.worst_region_ratio(against),
                "reference_relmse_rgb": ref_pair["relmse_of_one_rgb"],
                "reference_relmse_rgb_blurred": ref_pair["relmse_of_one_rgb_blurred"],
            })
    nave_bench.write_csv(os.path.join(args.dir, "reference.csv"), CSV_FIELDS, rows)
    print(nave_bench.markdown_table(
        ["view", "mode", "time", "relMSE vs reference (RGB)", "blurred 4 px", "two-seed relMSE (RGB)",
         "mean / reference", "worst region / reference", "reference's own (RGB / blurred)"],
        [[r["view"], r["mode"], f"{r['seconds']:.0f} s", f"{r['relmse_rgb']:.3g}", f"{r['relmse_rgb_blurred']:.3g}",
          f"{r['relmse_pair_rgb']:.3g}", f"{r['mean_ratio']:.4f}", f"{r['worst_region_ratio']:.4f}",
          f"{r['reference_relmse_rgb']:.2g} / {r['reference_relmse_rgb_blurred']:.2g}"] for r in rows]))


if __name__ == "__main__":
    main()
