#!/usr/bin/python3
"""frep sample on the chair, each row of issue 35's table against its baseline in one run:
the default store (the workers' band distance) and --store sdf-exact (the workers' exact distance to the
samples' piecewise-linear zero set) against --store raw, two local workers against
one, the master's peak RSS (the report's peak_rss_bytes) per size, and the sparse sampler's
evaluations against a dense grid. Every configuration runs ROUNDS times in turn (alternated,
so the machine's load falls on all of them alike) and the medians are compared; the machine is
shared, so the ratios are the figures to read, not the seconds, and the CPU time of the master
and its workers (RUSAGE_CHILDREN) is steadier than wall time under load. Also checks that 0, 1 and 2
workers write the same bytes.

At the end, the master's peak RSS per size and its ratio to the first size's (issue 35: memory
flat in the output size).

usage: bench/bench_sample_store.py build/bin/frep [RES,RES,...] [ROUNDS]   (default 256,512 3)"""
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

FREP = os.path.abspath(sys.argv[1])
RESES = [int(r) for r in (sys.argv[2] if len(sys.argv) > 2 else "256,512").split(",")]
ROUNDS = int(sys.argv[3]) if len(sys.argv) > 3 else 3
CHAIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "chair.hf")
BOUNDS = "-1.5,-1.5,-0.5,1.5,1.5,2.5"


def run(res, store, workers, out):
    args = [FREP, "sample", CHAIR, "-b", BOUNDS, "--res", str(res), "--store", store, "--workers", str(workers),
            "-O", out]
    t0, c0 = time.monotonic(), resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(args, capture_output=True, text=True)
    wall, c1 = time.monotonic() - t0, resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (c1.ru_utime + c1.ru_stime) - (c0.ru_utime + c0.ru_stime)  # master and its workers
    if r.returncode != 0:
        sys.exit("failed (%d): %s\n%s" % (r.returncode, " ".join(args), r.stderr))
    with open(out + ".report.json") as f:
        report = json.load(f)
    m = re.search(r"evaluations (\d+) \(([0-9.]+)% of dense (\d+)\)", r.stdout + r.stderr)
    return {"wall": wall, "cpu": cpu, "rss": report.get("peak_rss_bytes", 0) / 2 ** 20, "evals": int(m.group(1)) if m else 0,
            "dense": int(m.group(3)) if m else 0}


def median(runs, key):
    return statistics.median(r[key] for r in runs)


rss = {}  # (res, store) -> median master peak RSS (MiB), 2 workers
with tempfile.TemporaryDirectory() as tmp:
    for res in RESES:
        configs = [("raw", 1), ("raw", 2), ("sdf", 1), ("sdf", 2), ("sdf-exact", 2)]
        runs = {c: [] for c in configs}
        for _ in range(ROUNDS):
            for store, workers in configs:
                runs[(store, workers)].append(run(res, store, workers, os.path.join(tmp, "%s%d.vdb" % (store, workers))))
        print("chair %d^3 (load %s), medians of %d runs:" % (res, open("/proc/loadavg").read().split()[0], ROUNDS))
        for store, workers in configs:
            rs = runs[(store, workers)]
            print("  --store %s, %d worker%s: %.2f s wall, %.2f s CPU (master and workers), master peak RSS %.0f MiB" %
                  (store, workers, "s" if workers > 1 else "", median(rs, "wall"), median(rs, "cpu"), median(rs, "rss")))
        for store in ("raw", "sdf"):
            rss[(res, store)] = median(runs[(store, 2)], "rss")
        raw2, sdf2 = median(runs[("raw", 2)], "wall"), median(runs[("sdf", 2)], "wall")
        print("  default (sdf) / raw store, 2 workers: %.2fx wall (goal <= 1.3x), %.2fx CPU; RSS %.2fx" %
              (sdf2 / raw2, median(runs[("sdf", 2)], "cpu") / median(runs[("raw", 2)], "cpu"),
               median(runs[("sdf", 2)], "rss") / median(runs[("raw", 2)], "rss")))
        exact2 = median(runs[("sdf-exact", 2)], "wall")
        print("  sdf-exact / raw store, 2 workers: %.2fx wall (goal <= 1.5x), %.2fx CPU; RSS %.2fx" %
              (exact2 / raw2, median(runs[("sdf-exact", 2)], "cpu") / median(runs[("raw", 2)], "cpu"),
               median(runs[("sdf-exact", 2)], "rss") / median(runs[("raw", 2)], "rss")))
        for store in ("raw", "sdf"):
            print("  farm speed-up 1 -> 2 workers, --store %s: %.2fx (goal >= 1.9x)" %
                  (store, median(runs[(store, 1)], "wall") / median(runs[(store, 2)], "wall")))
        e = runs[("sdf", 2)][0]
        print("  evaluations (sdf, halo included): %d = %.2f%% of dense %d" %
              (e["evals"], 100.0 * e["evals"] / max(e["dense"], 1), e["dense"]))
        # Same bytes for any worker count (the last round's files), and in-process.
        run(res, "sdf", 0, os.path.join(tmp, "sdf0.vdb"))
        same = [open(os.path.join(tmp, "sdf%d.vdb" % w), "rb").read() for w in (0, 1, 2)]
        print("  same bytes for 0, 1 and 2 workers: %s" % ("yes" if same[0] == same[1] == same[2] else "NO"))
        run(res, "sdf-exact", 0, os.path.join(tmp, "sdf-exact0.vdb"))
        same = [open(os.path.join(tmp, "sdf-exact%d.vdb" % w), "rb").read() for w in (0, 2)]
        print("  sdf-exact: same bytes for 0 and 2 workers: %s" % ("yes" if same[0] == same[1] else "NO"))

# Memory flat in the output size (issue 35): the master's peak RSS per size against the first
# size's, in the same run. The output (leaves, file) grows about 4x a doubling of the resolution.
print("master peak RSS, 2 workers (MiB; x the %d^3 figure):" % RESES[0])
for res in RESES:
    print("  %5d^3: " % res + ", ".join("--store %s %.0f (%.2fx)" % (store, rss[(res, store)], rss[(res, store)] / rss[(RESES[0], store)])
                                       for store in ("raw", "sdf")))
