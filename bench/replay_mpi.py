#!/usr/bin/env python3
"""A replay of one traced render over R ranks x T threads (docs/distributed.md, "Replay"): what the origin
paper's table would look like for the abbey, and how far the same model is from the runs this machine can make.

The trace (`nave render --trace`, one process, one thread) gives, brick by brick, the time its batches took, the
time its loads took and the rays each batch sent to every other brick, and the bricks' depth-first order. For R
ranks the bricks are cut into R runs of that order by measured work, as a distributed render re-balances them
(StreamScheduler::Rebalance). A rank's time is its work over its threads' speed-up, or the time its network
takes to send and receive the rays crossing to and from other ranks (the bytes per ray the --measured runs
sent, packed by LZ4; 128 unpacked; or --ray-bytes; messages of up to 1 MiB of unpacked rays, sent while it traces), whichever is longer, plus the rounds that find the end of each pass (a latency per
round, log2 R deep). The job takes its slowest rank's time.

Threads: the speed-up of T threads on one node follows the universal scalability law (Gunther 1993, "A simple
capacity model of massively parallel transaction systems"; Gunther 2007, "Guerrilla capacity planning", ch. 4):
S(T) = T / (1 + sigma (T - 1) + kappa T (T - 1)). sigma (contention) comes from this machine: the same render at
1 and 2 threads. Two cores cannot show kappa (coherency, which makes 128 threads slower than 64 in the paper's
one-domain row), so kappa and the paper's one-thread time are fitted to the paper's one-domain row (four
values); the rows of 2, 4 and 8 sub-domains (twelve values) are then predicted, not fitted. The paper's threads
are the job's (its 16 threads took the same 5.5 minutes for any number of sub-domains): each of R sub-domains
has T / R of them. Its network is Gigabit Ethernet (--bandwidth 117 MB/s, --latency 50 us); the rays scale with
the work, by the ratio of the paper's one-thread time to the trace's.

Check: with --measured (the CSV of bench/bench_mpi.py on the same model and settings) the same model, unscaled,
on this machine's shared memory (--local-bandwidth, --local-latency) and its cores (R x T beyond them share
them), predicts each real run; the table gives both and how far apart.

    bash bench/setup-bench.sh     # once
    /usr/bin/python3 bench/bench_mpi.py --detail 30 --resolution 320x213 --spp 4 --runs 1x2,2x1,4x1
    /usr/bin/python3 bench/replay_mpi.py --detail 30 --resolution 320x213 --spp 4 \\
        --measured /tmp/nave-bench-mpi/mpi.csv
"""

import argparse
import csv
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import nave_bench as nb  # noqa: E402

# The origin paper's table: minutes for sub-domains x threads (the job's threads).
PAPER_THREADS = [16, 32, 64, 128]
PAPER_TABLE = {
    1: [5.61, 3.57, 2.97, 3.88],
    2: [5.52, 2.93, 1.82, 1.59],
    4: [5.57, 3.06, 1.77, 1.66],
    8: [5.54, 3.08, 1.70, 1.07],
}
# "From a sequential processing that lasted about 1 hour and 30 minutes" (the paper, Results).
PAPER_SEQUENTIAL_S = 90 * 60
# "more than one billion light-rays are used for the simulation" (the paper, section 4).
PAPER_RAYS = 1e9
RAY_BYTES = 128  # a ray record unpacked (ray_message.h); packed, what --measured runs sent (--pack-rays)
MESSAGE_BYTES = 1 << 20  # a message goes out once it holds this much (mpi_ray_exchange.h)


def read_trace_triangles(path):
    """-> triangles per brick (from the trace's loads of full meshes, or of the finest level loaded where the
    full mesh never was): what a render's first ownership divides (BrickOwners cuts by the full meshes'
    estimated memory, which the triangles dominate)."""
    with open(path) as f:
        events = json.load(f)["traceEvents"]
    bricks = next(int(e["args"]["bricks"]) for e in events if e.get("name") == "bricks" and e.get("ph") == "i")
    full, finest = [0] * bricks, [0] * bricks
    for e in events:
        if e.get("ph") == "X" and e.get("name") == "load" and "triangles" in e.get("args", {}):
            slot, n = int(e["args"]["brick"]), int(e["args"]["triangles"])
            if slot < bricks:  # level 0: the full mesh
                full[slot] = n
            else:
                finest[slot % bricks] = max(finest[slot % bricks], n)
    return [f or c for f, c in zip(full, finest)]


class Trace:
    """A traced render, slot by slot (a slot is a brick at a level of detail: slot = level x bricks + brick):
    batch_us and load_us per slot, sent[(from slot, to slot)] rays, the bricks' depth-first order and the
    slots the pager kept resident (which every rank holds with --coarse-levels-everywhere)."""

    def __init__(self, path):
        with open(path) as f:
            events = json.load(f)["traceEvents"]
        self.bricks, self.order, self.kept = None, None, set()
        for e in events:
            if e.get("name") == "bricks" and e.get("ph") == "i":
                self.bricks = int(e["args"]["bricks"])
                self.order = [int(b) for b in e["args"]["depth_first"].split()]
                self.kept = {int(s) for s in e["args"].get("kept", "").split()}
        if self.bricks is None:
            raise SystemExit(f"{path}: no 'bricks' event: trace a render of this version of nave (--trace)")
        self.batch_us, self.load_us, self.sent = {}, {}, {}
        for e in events:
            if e.get("ph") != "X":
                continue
            if e.get("name") == "batch":
                s = int(e["args"]["brick"])
                self.batch_us[s] = self.batch_us.get(s, 0.0) + float(e["dur"])
                for pair in e["args"].get("sent", "").split():
                    to, n = pair.split(":")
                    key = (s, int(to))
                    self.sent[key] = self.sent.get(key, 0) + int(n)
            elif e.get("name") == "load" and "brick" in e.get("args", {}):
                s = int(e["args"]["brick"])
                self.load_us[s] = self.load_us.get(s, 0.0) + float(e["dur"])

    def per_brick(self, per_slot):
        """A per-slot dict summed brick by brick (the levels of a brick count as the brick)."""
        out = [0.0] * self.bricks
        for s, v in per_slot.items():
            out[s % self.bricks] += v
        return out


def owners_by_work(order, work, ranks):
    """The rank of each brick: runs of the depth-first order of about equal work (BrickOwnersByWork, where a
    brick without work weighs a microsecond). `work` in seconds."""
    weight = [w + 1e-6 for w in work]
    total = sum(weight[b] for b in order)
    owner, before = [0] * len(work), 0.0
    for b in order:
        middle = (before + 0.5 * weight[b]) / total
        owner[b] = min(max(int(middle * ranks), 0), ranks - 1)
        before += weight[b]
    return owner


def spread_of_shared_work(made, shared):
    """Row r: the fraction of the rays rank r's bricks send into the kept slots that each rank traces
    (SpreadOfSharedWork, brick_owners.h): ranks above the mean hand their excess, at most their shared work, to
    the ranks below it in proportion to what each lacks."""
    n = len(made)
    mean = sum(made) / n
    lacking = sum(max(0.0, mean - m) for m in made)
    spread = [[1.0 if d == r else 0.0 for d in range(n)] for r in range(n)]
    for r in range(n):
        excess = min(max(0.0, made[r] - mean), shared[r])
        if excess <= 0 or lacking <= 0 or shared[r] <= 0:
            continue
        handed = excess / shared[r]
        spread[r][r] = 1.0 - handed
        for d in range(n):
            if d != r:
                spread[r][d] = handed * max(0.0, mean - made[d]) / lacking
    return spread


def usl(threads, sigma, kappa):
    """Universal scalability law: the speed-up of `threads` threads."""
    return threads / (1 + sigma * (threads - 1) + kappa * threads * (threads - 1))


class Model:
    """Seconds a job of R ranks takes: on its slowest rank, the longest of its batches over its threads'
    speed-up, its loads over its loaders (which load ahead while the workers trace) and its network, plus the
    rounds that find the ends of the passes. It has no term for a rank idling while the rays it waits for are
    traced on another: a lower bound where ranks hand few rays back and forth many times.

    With `everywhere` (--coarse-levels-everywhere), the slots the pager kept are held by every rank: a ray bound
    for one is traced on the rank it is on, so its batches' time goes to the ranks in the shares of the rays
    they send it (the rays of a kept slot are where the rays sending them were: found by iterating those
    shares), and every rank loads every kept slot once."""

    LOADERS = 2  # the pager's loader threads (pager.h)

    def __init__(self, trace, sigma, kappa, scale, ray_scale, bandwidth, latency, passes, ray_bytes=RAY_BYTES,
                 everywhere=True):
        """`scale`: what the batches' time is multiplied by; `ray_scale`: the rays sent; `ray_bytes`: a ray's
        bytes on the wire."""
        self.trace = trace
        self.everywhere = trace.kept if everywhere else set()
        self.load_s = [w * 1e-6 for w in trace.per_brick(trace.load_us)]
        self.order = trace.order
        self.sigma, self.kappa, self.scale, self.ray_scale = sigma, kappa, scale, ray_scale
        self.bandwidth, self.latency, self.passes = bandwidth, latency, passes
        self.ray_bytes = ray_bytes

    def shares(self, owner, spread, ranks):
        """-> {slot: [share of each rank]}: where each slot's rays are traced. A brick's own slots on its owner;
        a kept slot (with `everywhere`) where the rays sending to it are: a brick's own slot hands its rays to
        the ranks of its owner's row of `spread`, a kept slot keeps them (iterated until chains of kept slots
        settle)."""
        bricks = self.trace.bricks
        slots = set(self.trace.batch_us) | {s for pair in self.trace.sent for s in pair}
        share = {}
        for s in slots:
            if s in self.everywhere:
                share[s] = [1.0 / ranks] * ranks
            else:
                share[s] = [0.0] * ranks
                share[s][owner[s % bricks]] = 1.0
        into = {}
        for (a, b), n in self.trace.sent.items():
            if b in self.everywhere and a != b:
                into.setdefault(b, []).append((a, n))

        def sender(a):
            return share[a] if a in self.everywhere else spread[owner[a % bricks]]

        for _ in range(30):
            for b, senders in into.items():
                total = sum(n for _, n in senders)
                share[b] = [sum(n * sender(a)[r] for a, n in senders) / total for r in range(ranks)]
        return share

    def rank_work(self, owner, spread, ranks):
        """-> (batch microseconds per rank, shares) for `owner` and `spread`."""
        share = self.shares(owner, spread, ranks)
        work = [0.0] * ranks
        for s, us in self.trace.batch_us.items():
            for r in range(ranks):
                work[r] += share[s][r] * us
        return work, share

    def owners_rebalanced(self, ranks):
        """-> (owner per brick, spread) as re-balancing leaves them (StreamScheduler::Rebalance, which looks at
        passes 4, 8, 16...): while the busiest rank does more than 1.2x the mean, runs are cut by each brick's
        work, its own slots' and, with `everywhere`, that of the rays it sends into the kept slots (the mean
        work per ray entering them); then the ranks above the mean hand a share of the rays entering the kept
        slots to those below it (spread_of_shared_work); kept if that makes the busiest lighter."""
        t = self.trace
        identity = [[1.0 if d == r else 0.0 for d in range(ranks)] for r in range(ranks)]
        moving = t.per_brick({s: w for s, w in t.batch_us.items() if s not in self.everywhere})
        into = [0.0] * t.bricks
        for (a, b), n in t.sent.items():
            if b in self.everywhere and a not in self.everywhere:
                into[a % t.bricks] += n
        shared_total = sum(w for s, w in t.batch_us.items() if s in self.everywhere)
        per_entry = shared_total / sum(into) if sum(into) else 0.0
        weight = [m + per_entry * i for m, i in zip(moving, into)]
        owner = owners_by_work(self.order, [w * 1e-6 * self.scale + l for w, l in zip(moving, self.load_s)],
                               ranks)
        spread = identity
        for _ in range(8):
            did, _ = self.rank_work(owner, spread, ranks)
            if max(did) <= 1.2 * sum(did) / ranks:
                break
            next_owner = owners_by_work(self.order, [w * 1e-6 * self.scale + l
                                                     for w, l in zip(weight, self.load_s)], ranks)
            made, shared = [0.0] * ranks, [0.0] * ranks
            for b in range(t.bricks):
                made[next_owner[b]] += weight[b]
                shared[next_owner[b]] += per_entry * into[b]
            next_spread = spread_of_shared_work(made, shared) if self.everywhere else identity
            after = [made[r] - shared[r] for r in range(ranks)]
            for r in range(ranks):
                for d in range(ranks):
                    after[d] += shared[r] * next_spread[r][d]
            if max(after) >= max(did):
                break
            owner, spread = next_owner, next_spread
        return owner, spread

    def predict(self, ranks, threads_per_rank, cpu_share=1.0, triangles=None):
        """-> (seconds, rays between ranks) for `ranks` ranks of `threads_per_rank` threads; `cpu_share`: the
        share of a core each thread gets (below 1 where the ranks' threads exceed the cores). `triangles` per
        brick: the bricks keep the first ownership, cut by memory, as a render too short to re-balance does
        (re-balancing starts at pass 4: StreamScheduler::Rebalance); else they are as re-balancing leaves
        them."""
        t = self.trace
        if triangles is not None:
            owner = owners_by_work(self.order, [float(x) for x in triangles], ranks)
            spread = [[1.0 if d == r else 0.0 for d in range(ranks)] for r in range(ranks)]
        else:
            owner, spread = self.owners_rebalanced(ranks)
        work, share = self.rank_work(owner, spread, ranks)
        batch = [w * 1e-6 * self.scale for w in work]
        load = [0.0] * ranks
        for s, us in t.load_us.items():
            if s in self.everywhere:
                for r in range(ranks):
                    load[r] += us * 1e-6  # every rank loads every kept level once
            else:
                load[owner[s % t.bricks]] += us * 1e-6
        out, into = [0.0] * ranks, [0.0] * ranks
        crossing = 0.0

        def move(n, src, dst):
            nonlocal crossing
            crossing += n
            out[src] += n * self.ray_bytes * self.ray_scale
            into[dst] += n * self.ray_bytes * self.ray_scale

        for (a, b), n in t.sent.items():
            if b in self.everywhere:
                if a in self.everywhere:
                    continue  # from one kept slot to another: stays where it is
                r = owner[a % t.bricks]  # entering the kept slots: handed on by the owner's spread
                for d in range(ranks):
                    if d != r and spread[r][d] > 0:
                        move(n * spread[r][d], r, d)
                continue
            dest = owner[b % t.bricks]
            for r in range(ranks):
                if r != dest and share[a][r] > 0:
                    move(n * share[a][r], r, dest)
        speed = usl(threads_per_rank, self.sigma, self.kappa) * cpu_share
        worst = 0.0
        for r in range(ranks):
            # The loaders load ahead while the workers trace (pager.h): the longer of the two.
            compute = max(batch[r] / speed, load[r] / (self.LOADERS * cpu_share))
            moved = max(out[r], into[r])
            messages = math.ceil(moved * RAY_BYTES / self.ray_bytes / MESSAGE_BYTES)
            network = moved / self.bandwidth + messages * self.latency
            worst = max(worst, compute, network)
        rounds = self.passes * 2 * max(1, math.ceil(math.log2(ranks))) if ranks > 1 else 0
        return worst + rounds * self.latency, crossing * self.ray_scale

    def bound(self, ranks, threads_per_rank):
        """'network' where moving rays takes longer than computing on the slowest rank, else 'compute'."""
        saved = self.bandwidth
        self.bandwidth = float("inf")
        compute, _ = self.predict(ranks, threads_per_rank)
        self.bandwidth = saved
        total, _ = self.predict(ranks, threads_per_rank)
        return "network" if total > compute * 1.001 else "compute"


def fit_one_domain(work_total_s):
    """sigma and kappa of the paper's nodes, fitted to its one-domain row (least squares on log time), the
    work scaled to its sequential time."""
    scale = PAPER_SEQUENTIAL_S / work_total_s
    best = None
    for i in range(0, 301):
        sigma = 1e-4 * (1.03 ** i) if i else 0.0
        for j in range(0, 501):
            kappa = 1e-7 * (1.03 ** j) if j else 0.0
            err = sum(math.log(PAPER_TABLE[1][k] * 60 / (PAPER_SEQUENTIAL_S / usl(t, sigma, kappa))) ** 2
                      for k, t in enumerate(PAPER_THREADS))
            if best is None or err < best[0]:
                best = (err, sigma, kappa)
    return best[1], best[2], scale


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    nb.add_abbey_run_arguments(ap, "/tmp/nave-bench-mpi")
    ap.add_argument("--bandwidth", type=float, default=117e6, help="the paper's network, bytes/s (Gigabit)")
    ap.add_argument("--latency", type=float, default=50e-6, help="the paper's network, seconds a message")
    ap.add_argument("--local-bandwidth", type=float, default=2e9, help="this machine's shared memory, bytes/s")
    ap.add_argument("--local-latency", type=float, default=5e-6)
    ap.add_argument("--measured", default="", help="bench_mpi.py's CSV of real runs to check against")
    ap.add_argument("--ray-bytes", type=float, default=0,
                    help="a ray's bytes on the wire (default: what the --measured runs sent per ray, else 128)")
    ap.add_argument("--reuse", action="store_true", help="the trace and times of the last run in --dir")
    ap.add_argument("--coarse-levels-everywhere", default="on", choices=["on", "off"],
                    help="with --levels: every rank traces the rays that meet the coarse levels it keeps, as "
                         "nave render does by default (on), or sends them to the brick's owner (off)")
    args = ap.parse_args()
    os.makedirs(args.dir, exist_ok=True)
    log = open(os.path.join(args.dir, "replay.log"), "a")
    store, config = nb.abbey_store_and_view(args.nave, args.dir, args.detail, args.store, args.config, args.view,
                                            log, args.levels)

    # One process at 1 and 2 threads, each traced: the batches' speed-up gives sigma.
    runs = {}
    runs_file = os.path.join(args.dir, "replay_runs.json")
    if args.reuse and os.path.exists(runs_file):
        with open(runs_file) as f:
            runs = {int(k): v for k, v in json.load(f).items()}
    for threads in (1, 2):
        trace = os.path.join(args.dir, f"replay_t{threads}.json")
        if threads in runs and os.path.exists(trace):
            continue
        cmd = [args.nave, "render", store, "-c", config, "--mode", "path", "--resolution", args.resolution,
               "--spp", str(args.spp), "--threads", str(threads), "-q", "--trace", trace, "-o",
               os.path.join(args.dir, f"replay_t{threads}.exr")]
        t = nb.run_timed(cmd, log)
        if not t.ok:
            raise SystemExit(f"render failed: {nb.error_reason(t.output, t.returncode)}")
        runs[threads] = {"wall_s": t.elapsed_s, "trace": trace}
    with open(runs_file, "w") as f:
        json.dump(runs, f)
    trace = Trace(runs[1]["trace"])
    trace2 = Trace(runs[2]["trace"])
    batch_s, load_s = sum(trace.batch_us.values()) * 1e-6, sum(trace.load_us.values()) * 1e-6
    speedup = sum(trace.batch_us.values()) / sum(trace2.batch_us.values())
    # S(2) = 2 / (1 + sigma): kappa's share is negligible at 2 threads.
    sigma = min(max(2 / speedup - 1, 0.0), 1.0)
    everywhere = args.coarse_levels_everywhere == "on"
    kept_rays = sum(n for (a, b), n in trace.sent.items() if b in trace.kept)
    where = "traced where they are" if everywhere else "sent to the brick's owner"
    print(f"trace: {len(trace.order)} bricks, one thread: batches {batch_s:.1f} s, loads {load_s:.1f} s, wall "
          f"{runs[1]['wall_s']:.1f} s; {sum(trace.sent.values())} rays sent between slots, {kept_rays} of them "
          f"to the {len(trace.kept)} kept coarse levels ({where}); batches at 2 threads {speedup:.2f}x faster: "
          f"sigma {sigma:.3f}", file=sys.stderr)

    measured = []
    if args.measured:
        with open(args.measured) as f:
            measured = [r for r in csv.DictReader(f) if r.get("status") == "ok"]
    ray_bytes = args.ray_bytes
    if not ray_bytes:
        moved = [(float(r["bytes"]), float(r["rays_between_ranks"])) for r in measured
                 if int(r["ranks"]) > 1 and float(r.get("rays_between_ranks") or 0) > 0]
        ray_bytes = sum(b for b, _ in moved) / sum(n for _, n in moved) if moved else RAY_BYTES
    print(f"{ray_bytes:.1f} bytes a ray on the wire", file=sys.stderr)

    paper_sigma, kappa, scale = fit_one_domain(batch_s)
    rays = float(nb.read_statistics(os.path.join(args.dir, "replay_t1.exr")).get("rays", 0)) or 1.0
    ray_scale = PAPER_RAYS / rays
    print(f"the paper's nodes, from its one-domain row and its 90 min sequential time: sigma {paper_sigma:.2e}, "
          f"kappa {kappa:.2e}; the batches scaled by {scale:.0f}, the rays by {ray_scale:.0f} (to the paper's "
          f"billion)", file=sys.stderr)
    for name, bandwidth, latency in (("Gigabit Ethernet, the paper's network", args.bandwidth, args.latency),
                                     ("10 Gigabit Ethernet", 10 * args.bandwidth, args.latency / 2)):
        paper = Model(trace, paper_sigma, kappa, scale, ray_scale, bandwidth, latency, args.spp, ray_bytes,
                      everywhere)
        rows, errors = [], []
        for domains, times in PAPER_TABLE.items():
            row = [f"{domains} {'domain' if domains == 1 else 'sub-domains'}"]
            for k, threads in enumerate(PAPER_THREADS):
                seconds, _ = paper.predict(domains, threads / domains)
                mark = " (n)" if paper.bound(domains, threads / domains) == "network" else ""
                row.append(f"{times[k]:.2f} / {seconds / 60:.2f}{mark}")
                if domains > 1:
                    errors.append(abs(seconds / 60 - times[k]) / times[k])
            rows.append(row)
        print(f"\nThe paper's table (minutes) / the replay's prediction for the abbey on {name} "
              "((n): the network bounds it):\n")
        print(nb.markdown_table(["", *[f"{t} threads" for t in PAPER_THREADS]], rows))
        print(f"\nPredicted cells (2, 4, 8 sub-domains): mean error {100 * sum(errors) / len(errors):.0f} %, "
              f"largest {100 * max(errors):.0f} %")

    if args.measured:
        local = Model(trace, sigma, 0.0, 1.0, 1.0, args.local_bandwidth, args.local_latency, args.spp,
                      ray_bytes, everywhere)
        cores = os.cpu_count() or 1
        # Start, bookkeeping, the image: what one process of one thread takes beyond the model, from the
        # measured run of 1 x 1 where there is one (a traced run is slower), else the traced run.
        one = [float(r["wall_s"]) for r in measured if r["ranks"] == "1" and r["threads"] == "1"]
        fixed = max(0.0, (one[0] if one else runs[1]["wall_s"]) - local.predict(1, 1)[0])
        # Renders of fewer than 5 passes never re-balance: they keep the ownership by memory.
        triangles = read_trace_triangles(runs[1]["trace"]) if args.spp <= 4 else None
        check = []
        for r in measured:
            ranks, threads = int(r["ranks"]), int(r["threads"])
            share = min(1.0, cores / (ranks * threads))
            seconds, crossing = local.predict(ranks, threads, share, triangles)
            seconds += fixed
            wall = float(r["wall_s"])
            check.append([f"{ranks} x {threads}", f"{wall:.1f}", f"{seconds:.1f}",
                          f"{100 * (seconds - wall) / wall:+.0f} %", r.get("rays_between_ranks", ""),
                          f"{crossing:.0f}"])
        print("\nThe same model on this machine against real runs (bench_mpi.py):\n")
        print(nb.markdown_table(["ranks x threads", "measured s", "predicted s", "off by", "rays between ranks",
                                 "predicted rays between ranks"], check))


if __name__ == "__main__":
    main()
