#!/usr/bin/python3
"""The farm's 1 -> 2 worker scaling, in counters that do not depend on the machine's load
(issue 35: two local workers at least 1.9x one). Runs `frep sample` and `frep mesh` of the chair
with --workers 1 and 2 (alternated, ROUNDS times each; medians) and prints, per run, from the
report's per-worker counters (docs/farm.md, "Scaling") and the CPU the run took (wait4):

  work      the workers' CPU in computeBrick (the brick compute itself)
  task+     their compute thread's CPU on a task outside computeBrick (model look-up, encoding, CRC)
  other     the rest of their processes' CPU (start-up, compiling the job, the I/O thread)
  idle      the time their compute threads waited with no task queued (after their first task;
            `start` is the wait for the first one: start-up and the master's plan; `tail` the time
            from a worker's last result to the job's last, done while another still computed)
  dups      results computed beyond one per brick (straggler copies), and straggler re-issues
  master    the frep process's CPU: during the bricks (concurrent with the workers) and the rest
            (before and after them: compile, merge, simplification, writing; serial)

and from them the speed-up two workers would give on two idle cores (a CPU model: a worker's
chain of tasks is its own CPU; both cores also run the master's concurrent part; the master's
serial part adds), next to the wall-clock ratio, which only a quiet machine measures:

  T(n) = serial + max(max_i worker_i, (sum_i worker_i + master_concurrent) / cores)

usage: bench/bench_farm_scaling.py build/bin/frep [RES_SAMPLE] [RES_MESH] [ROUNDS]
       (default 512 256 3; the same output bytes for 1 and 2 workers are checked)"""
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

FREP = os.path.abspath(sys.argv[1])
RES = {"sample": int(sys.argv[2]) if len(sys.argv) > 2 else 512, "mesh": int(sys.argv[3]) if len(sys.argv) > 3 else 256}
ROUNDS = int(sys.argv[4]) if len(sys.argv) > 4 else 3
CHAIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "chair.hf")
BOUNDS = "-1.5,-1.5,-0.5,1.5,1.5,2.5"
CORES = 2


def run(op, workers, tmp):
    out = os.path.join(tmp, f"{op}-{workers}." + ("vdb" if op == "sample" else "ply"))
    cmd = [FREP, op, CHAIR, "-b", BOUNDS, "--res", str(RES[op]), "--workers", str(workers), "--no-progress", "-O", out]
    t0 = time.monotonic()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.monotonic() - t0
    err = p.stderr.read().decode(errors="replace")
    p.stderr.close()
    if status != 0:
        sys.exit(f"{' '.join(cmd)}: exit status {status}\n{err}")
    with open(out + ".report.json") as f:
        r = json.load(f)
    with open(out, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    ws = list(r["per_worker"].values())
    # wait4 counts frep and the workers it reaped; the workers' own CPU (by their last result)
    # is taken out to leave the master's. Their CPU after it (bye, exit) is a few ms.
    total_cpu = usage.ru_utime + usage.ru_stime
    worker_cpu = [w["process_cpu_seconds"] for w in ws]
    master = max(0.0, total_cpu - sum(worker_cpu))
    concurrent = max(0.0, r["master_cpu_seconds"] - r["master_cpu_after_last_brick"])
    results = sum(w["results"] for w in ws)
    return {
        "wall": wall,
        "digest": digest,
        "bricks": r["bricks"]["computed"],
        "work": sum(w["compute_cpu_seconds"] for w in ws),
        "task+": sum(w["task_cpu_seconds"] - w["compute_cpu_seconds"] for w in ws),
        "other": sum(w["process_cpu_seconds"] - w["task_cpu_seconds"] for w in ws),
        "idle": sum(w["idle_seconds"] - w["first_idle_seconds"] for w in ws),
        "start": max(w["first_idle_seconds"] for w in ws),
        "tail": sum(w["tail_idle_seconds"] for w in ws),
        "dups": results - sum(w["bricks"] for w in ws),
        "reissues": r["faults"]["straggler_reissues"] + r["faults"]["queued_reissues"] + r["faults"]["lease_reissues"],
        "workers_cpu": worker_cpu,
        "master": master,
        "master_concurrent": min(concurrent, master),
        "master_serial": master - min(concurrent, master),
    }


def model_wall(m, workers):
    cores = min(CORES, workers + 1)
    return m["master_serial"] + max(max(m["workers_cpu"]), (sum(m["workers_cpu"]) + m["master_concurrent"]) / cores)


def med(runs, key):
    return statistics.median(r[key] for r in runs)


def main():
    print(f"frep {{sample {RES['sample']}^3, mesh {RES['mesh']}^3}} of examples/chair.hf, 1 and 2 local workers, "
          f"{ROUNDS} alternated rounds, medians; load {os.getloadavg()[0]:.1f}")
    print("CPU seconds (whole run): work = the workers' computeBrick; task+ = their tasks outside it; other = the rest\n"
          "of their processes; idle = their compute threads waiting for a task after the first (start: the wait for\n"
          "the first); dups = results beyond one a brick; master = frep's own CPU, concurrent with the bricks / serial")
    with tempfile.TemporaryDirectory() as tmp:
        for op in ("sample", "mesh"):
            runs = {1: [], 2: []}
            for _ in range(ROUNDS):
                for w in (1, 2):
                    runs[w].append(run(op, w, tmp))
            digests = {r["digest"] for w in (1, 2) for r in runs[w]}
            model = {}
            for w in (1, 2):
                rs = runs[w]
                model[w] = statistics.median(model_wall(r, w) for r in rs)
                print(f"  {op} {w} worker(s): wall {med(rs, 'wall'):.2f} s; bricks {med(rs, 'bricks'):.0f}; "
                      f"work {med(rs, 'work'):.3f}, task+ {med(rs, 'task+'):.3f}, other {med(rs, 'other'):.3f}; "
                      f"idle {med(rs, 'idle'):.3f} (start {med(rs, 'start'):.3f}, tail {med(rs, 'tail'):.3f}); dups {med(rs, 'dups'):.0f} "
                      f"(re-issues {med(rs, 'reissues'):.0f}); master {med(rs, 'master_concurrent'):.3f} / "
                      f"{med(rs, 'master_serial'):.3f}; modelled wall {model[w]:.3f} s")
            w1, w2 = runs[1], runs[2]
            extra = (med(w2, "work") + med(w2, "task+") + med(w2, "other")) / (
                med(w1, "work") + med(w1, "task+") + med(w1, "other"))
            print(f"  {op}: 2 workers' CPU / 1 worker's {extra:.3f}x (1.00: no extra work); modelled speed-up on "
                  f"{CORES} idle cores {model[1] / model[2]:.2f}x; wall-clock {med(w1, 'wall') / med(w2, 'wall'):.2f}x "
                  f"(trust it on a quiet machine only); same bytes for 1 and 2 workers: "
                  f"{'yes' if len(digests) == 1 else 'NO'}")
            if len(digests) != 1:
                sys.exit(f"{op}: the outputs differ between runs")


if __name__ == "__main__":
    main()
