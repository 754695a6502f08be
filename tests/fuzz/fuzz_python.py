#!/usr/bin/python3
"""Bounded fuzz run of the Python module frepfarm (python/frepfarm_module.cpp), for run_fuzz.sh.

Case i of a run is a pure function of (--seed, i): a HyperFun text mutated from the seed corpus
(tests/fuzz/corpus/python/*.hf and the small models of examples/) and argument values chosen
among NaN, infinities, 1e308, negative and huge sizes, resolutions out of range, wrong types and
wrong shapes. Each case goes through the module's public calls: compile (or load of the text
written to a file), Model.eval, Model.mesh and Model.sample at tiny grids, Volume.inside_volume.

Every call must return a result or raise a Python exception. Findings:
  - the child process dies of a signal (a crash, an abort) or exits unexpectedly;
  - a case makes no progress for --timeout seconds (a hang);
  - MemoryError (the child runs under RLIMIT_DATA, --memory-mb: an allocation beyond it) or
    SystemError (a broken C-API contract);
  - RuntimeError("internal error: ...") (the module's own "this is a bug");
  - a result that breaks its shape: eval's length, triangle indices beyond the vertices.
The cases run in a child process; after a crash the parent records the case and starts a new child
at the next one. Exit 0: no findings; exit 1: findings, each kept as FINDINGS/python-<i>.txt (its
text and arguments) and replayed in one process by `fuzz_python.py --seed S --replay I`.

The run stops after --cases cases or --budget seconds of wall time, whichever comes first (the
summary says how many ran).
"""
import argparse
import glob
import json
import math
import os
import random
import resource
import select
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))

NUMBERS = [0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 1e-300, 5e-324, 1e300, 1e308, -1e308, 1.7976931348623157e308,
           math.inf, -math.inf, math.nan, 3.0, 1e-9, 4096.0, 2.0 ** 31, -(2.0 ** 63)]
INTS = [-(2 ** 63), -(2 ** 31), -1, 0, 1, 2, 3, 4, 5, 8, 4097, 65536, 2 ** 31, 2 ** 63, 10 ** 30]
TOKENS = ["x[1]", "x[2]", "x[3]", "x[4]", "x[0]", "x[99999]", "a[1]", "a[0]", "a[2147483647]", "1e308",
          "-1e308", "1e-320", "0/0", "1/0", "sqrt(-1)", "log(0)", "^", "^999", "&", "|", "\\", "~", "@",
          "(", ")", "[", "]", ";", ",", "=", "if", "then", "else", "endif", "while", "loop", "endloop",
          "array", "hfSphere(x, c, 1)", "hfBlock(x, c, 1, 1, 1)", "hfTorusZ(x, c, 0.5, 0.1)",
          "frVolumeSplineFile(x, \"/dev/zero\", 0.1)", "frMesh(x, \"/dev/zero\")", "min(", "max(", "abs(",
          "\"", "\n", "/*", "*/", "--", "99999999999999999999", "0x1p3", "nan", "inf", "\x00", "\xff", "é"]


def seeds():
    texts = []
    for path in sorted(glob.glob(os.path.join(HERE, "corpus", "python", "*.hf"))) + \
            sorted(glob.glob(os.path.join(REPO, "examples", "*.hf"))):
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
        if len(text) <= 4096:
            texts.append(text)
    return texts


def mutate(rng, text, others):
    for _ in range(rng.choice([1, 1, 1, 2, 3, 5, 8])):
        n = len(text)
        op = rng.randrange(7)
        at = rng.randrange(n + 1)
        if op == 0 and n:  # flip one bit of one character
            i = rng.randrange(n)
            text = text[:i] + chr((ord(text[i]) ^ (1 << rng.randrange(7))) or 32) + text[i + 1:]
        elif op == 1:  # insert a token
            text = text[:at] + rng.choice(TOKENS) + text[at:]
        elif op == 2 and n:  # delete a range
            text = text[:at] + text[at + rng.randrange(1, 16):]
        elif op == 3 and n:  # duplicate a range
            j = rng.randrange(n)
            text = text[:at] + text[j:j + rng.randrange(1, 40)] + text[at:]
        elif op == 4:  # splice with another seed
            other = rng.choice(others)
            text = text[:at] + other[rng.randrange(len(other) + 1):]
        elif op == 5:  # a number replaced by an extreme one
            digits = [i for i, c in enumerate(text) if c.isdigit()]
            if digits:
                i = rng.choice(digits)
                text = text[:i] + repr(rng.choice(NUMBERS)).replace("inf", "1e999").replace("nan", "0/0") + text[i + 1:]
        else:  # truncate
            text = text[:at]
    return text


def number(rng):
    return rng.choice(NUMBERS) if rng.random() < 0.5 else rng.uniform(-3, 3)


def anything(rng):
    """A value of the wrong type, most of the time."""
    return rng.choice([None, "1", b"\x00", [], [1.0], {"a": 1}, object, 1j, True, math.nan, 2 ** 70, -1])


def box(rng):
    if rng.random() < 0.8:
        r = rng.choice([1.0, 1.5, 2.0, 0.3])
        lo, hi = [-r] * 3, [r] * 3
    else:
        lo, hi = [number(rng) for _ in range(3)], [number(rng) for _ in range(3)]
    roll = rng.random()
    if roll < 0.05:
        return anything(rng), hi
    if roll < 0.1:
        return lo[:rng.randrange(5)], hi
    return lo, hi


def make_case(seed, i, corpus):
    rng = random.Random(seed * 1000003 + i)
    case = {"index": i, "seed": seed}
    text = rng.choice(corpus)
    case["text"] = mutate(rng, text, corpus) if rng.random() < 0.6 else text
    case["via"] = "load" if rng.random() < 0.1 else "compile"
    odd = rng.random() < 0.15  # one compile argument of an odd value or a wrong type
    case["file"] = rng.choice(["a\x00b.hf", "x" * 5000, "", "é.hf"]) if odd and rng.random() < 0.2 else "m.hf"
    case["object"] = rng.choice(["my_model", "ball", "ring", "nosuch", "\x00", "é" * 3]) \
        if odd and rng.random() < 0.3 else ""
    case["params"] = rng.choice([[number(rng)], [number(rng) for _ in range(rng.randrange(6))],
                                 [rng.choice(NUMBERS)] * 3, [math.nan] * 2, "wrong", [None]]) \
        if odd and rng.random() < 0.5 else [rng.uniform(0.3, 1.5) for _ in range(rng.randrange(2))]
    case["iso"] = rng.choice([number(rng), "0", None]) if odd and rng.random() < 0.3 else 0.0
    calls = []
    for _ in range(rng.randrange(1, 4)):
        kind = rng.choice(["eval", "eval", "mesh", "mesh", "sample"])
        if kind == "eval":
            rows = rng.choice([0, 1, 3, 257, 600])
            cols = rng.choice([3, 3, 3, 4, 1, 2, 0])
            calls.append({"call": "eval", "rows": rows, "cols": cols, "flat": rng.random() < 0.1,
                          "values": [number(rng) for _ in range(4)], "use_wrong": rng.random() < 0.05,
                          "wrong": anything(rng)})
        else:
            lo, hi = box(rng)
            res = rng.choice([2, 3, 4, 6, 8, 12]) if rng.random() < 0.85 else rng.choice(INTS + [anything(rng), 1.5])
            fixed = rng.choice([[], [], [], [0.2], [number(rng)], [0.0, 0.0], "x"])
            call = {"call": kind, "lo": lo, "hi": hi, "res": res, "fixed": fixed}
            if kind == "mesh":
                call["simplify"] = rng.choice([0.0, 0.0, 0.1, 0.5, number(rng)])
            else:
                call["band"] = rng.choice([1, 2, 3, 3, 64, 65, 0, -1, 2 ** 31, 1.5])
            calls.append(call)
    case["calls"] = calls
    return case


def check(ok, what):
    if not ok:
        raise AssertionError("oracle: " + what)


def run_case(frepfarm, np, case, tmpdir):
    """Raises AssertionError for a finding; every other exception is an accepted refusal."""
    def guarded(fn):
        try:
            return fn()
        except (MemoryError, SystemError) as e:
            raise AssertionError(type(e).__name__ + ": " + str(e)[:300])
        except RuntimeError as e:
            if str(e).startswith("internal error"):
                raise AssertionError("RuntimeError: " + str(e)[:300])
            return None
        except AssertionError:
            raise
        except Exception:
            return None

    def compile_model():
        if case["via"] == "load":
            path = os.path.join(tmpdir, "case.hf")
            with open(path, "w", encoding="utf-8", errors="surrogatepass") as f:
                f.write(case["text"])
            return frepfarm.load(path, object=case["object"], params=case["params"], iso=case["iso"])
        return frepfarm.compile(case["text"], file=case["file"], object=case["object"], params=case["params"],
                                iso=case["iso"])

    model = guarded(compile_model)
    if model is None:
        return
    for c in case["calls"]:
        if c["call"] == "eval":
            if c["use_wrong"]:
                guarded(lambda: model.eval(c["wrong"]))
                continue
            vals = c["values"]
            pts = np.array([[vals[(r + k) % 4] for k in range(c["cols"])] for r in range(c["rows"])],
                           dtype=np.float64).reshape(c["rows"], c["cols"])
            arg = pts.reshape(-1) if c["flat"] else pts
            out = guarded(lambda: model.eval(arg))
            if out is not None:
                n = c["rows"] if arg.ndim == 2 else 1
                check(out.shape == (n,), "eval of %s points gave shape %s" % (arg.shape, out.shape))
        elif c["call"] == "mesh":
            mesh = guarded(lambda: model.mesh(c["lo"], c["hi"], c["res"], c["simplify"], c["fixed"]))
            if mesh is not None:
                v, t = mesh.vertices, mesh.triangles
                check(v.ndim == 2 and v.shape[1] == 3 and t.ndim == 2 and t.shape[1] == 3, "mesh array shapes")
                check(t.size == 0 or int(t.max()) < len(v), "a triangle names a vertex beyond the vertices")
                check(bool(np.isfinite(v).all()), "a non-finite vertex")
        else:
            vol = guarded(lambda: model.sample(c["lo"], c["hi"], c["res"], c["band"], c["fixed"]))
            if vol is not None:
                guarded(lambda: vol.inside_volume())
                check(vol.leaf_count >= 0, "leaf count")


def child(args):
    """Runs cases [start, end), writing "<i>\\n" before each and "ok\\n" at the end to --report-fd."""
    resource.setrlimit(resource.RLIMIT_DATA, (args.memory_mb << 20, args.memory_mb << 20))
    import numpy as np
    import frepfarm
    report = os.fdopen(args.report_fd, "w", buffering=1)
    corpus = seeds()
    with tempfile.TemporaryDirectory(prefix="fuzz_python-") as tmpdir:
        for i in range(args.start, args.end):
            report.write("%d\n" % i)
            case = make_case(args.seed, i, corpus)
            if os.environ.get("FUZZ_PYTHON_SELFTEST_CRASH") == str(i):  # checks the harness sees a signal
                os.kill(os.getpid(), signal.SIGSEGV)
            try:
                run_case(frepfarm, np, case, tmpdir)
            except AssertionError as e:
                report.write("finding %d %s\n" % (i, json.dumps(str(e))))
    report.write("ok\n")
    return 0


def keep(findings_dir, case, why):
    os.makedirs(findings_dir, exist_ok=True)
    path = os.path.join(findings_dir, "python-%d.txt" % case["index"])
    with open(path, "w", encoding="utf-8", errors="surrogatepass") as f:
        f.write("# fuzz_python finding: %s\n" % why)
        f.write("# replay: tests/fuzz/fuzz_python.py --seed %d --replay %d\n" % (case["seed"], case["index"]))
        f.write(json.dumps(case, indent=1, default=repr) + "\n")
    return path


def parent(args):
    corpus = seeds()
    env = dict(os.environ, PYTHONPATH=args.module_dir + os.pathsep + os.environ.get("PYTHONPATH", ""))
    start, end = 0, args.cases
    began = time.monotonic()
    findings = []
    while start < end and time.monotonic() - began < args.budget:
        r, w = os.pipe()
        proc = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--child", "--start", str(start),
                                 "--end", str(end), "--seed", str(args.seed), "--memory-mb", str(args.memory_mb),
                                 "--report-fd", str(w)],
                                env=env, pass_fds=(w,), stdin=subprocess.DEVNULL)
        os.close(w)
        current, done, buf, last = start - 1, False, b"", time.monotonic()
        while True:
            ready, _, _ = select.select([r], [], [], 1.0)
            now = time.monotonic()
            if ready:
                chunk = os.read(r, 65536)
                if not chunk:
                    break
                buf += chunk
                *lines, buf = buf.split(b"\n")
                for line in lines:
                    text = line.decode()
                    if text == "ok":
                        done = True
                    elif text.startswith("finding "):
                        _, idx, why = text.split(" ", 2)
                        case = make_case(args.seed, int(idx), corpus)
                        findings.append((int(idx), json.loads(why), keep(args.findings, case, json.loads(why))))
                    else:
                        current, last = int(text), now
            if now - last > args.timeout:
                proc.kill()
                proc.wait()
                case = make_case(args.seed, current, corpus)
                why = "no progress for %d s (a hang)" % args.timeout
                findings.append((current, why, keep(args.findings, case, why)))
                break
            if now - began > args.budget:
                proc.kill()
                proc.wait()
                end = current  # the interrupted case is not counted
                break
        os.close(r)
        rc = proc.wait()
        if done and rc == 0:
            break
        if rc != 0 and rc != -signal.SIGKILL:
            why = ("killed by signal %d" % -rc) if rc < 0 else ("exit %d" % rc)
            case = make_case(args.seed, current, corpus)
            findings.append((current, why, keep(args.findings, case, why)))
        if current < start:  # died before its first case: the module itself is broken
            print("fuzz_python: the child died before running a case (%s); is %s built?" % (rc, args.module_dir))
            return 1
        start = current + 1
    elapsed = time.monotonic() - began
    for idx, why, path in findings:
        print("fuzz_python: case %d: %s (kept in %s)" % (idx, why, path))
    print("fuzz_python: %d cases (seed %d, %d seed models), %.0f s, %d findings" %
          (end, args.seed, len(corpus), elapsed, len(findings)))
    return 1 if findings else 0


def replay(args):
    import numpy as np
    import frepfarm
    case = make_case(args.seed, args.replay, seeds())
    with tempfile.TemporaryDirectory(prefix="fuzz_python-") as tmpdir:
        run_case(frepfarm, np, case, tmpdir)
    print("fuzz_python: case %d: no finding" % case["index"])
    return 0


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--module-dir", default=os.path.join(REPO, "build", "python"),
                   help="directory holding the built frepfarm module (default build/python)")
    p.add_argument("--cases", type=int, default=3000)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--budget", type=float, default=60.0, help="wall-time bound of the run, seconds")
    p.add_argument("--timeout", type=int, default=30, help="seconds without progress that make a hang")
    p.add_argument("--memory-mb", type=int, default=2048, help="RLIMIT_DATA of the child, MiB")
    p.add_argument("--findings", default=os.path.join(REPO, "build-fuzz", "findings"))
    p.add_argument("--replay", type=int, help="run case REPLAY of --seed in this process (a kept finding)")
    p.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--start", type=int, default=0, help=argparse.SUPPRESS)
    p.add_argument("--end", type=int, default=0, help=argparse.SUPPRESS)
    p.add_argument("--report-fd", type=int, default=3, help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.child:
        return child(args)
    if args.replay is not None:
        sys.path.insert(0, args.module_dir)
        return replay(args)
    return parent(args)


if __name__ == "__main__":
    sys.exit(main())
