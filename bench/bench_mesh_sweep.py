#!/usr/bin/python3
"""Sweeps of mesh parts by translation along keyframes: the exact sum with the path vs the search.

frSweepKeys(x, part, ts, ps) of an frMesh part takes the exact construction (path_sweep.h,
mesh_convex_sum.h with the path's segments); the same call with zero angles sweeps the same set
through the certified extremum search (the path before issue 30's mesh sweeps). Both run in the
same process of this script with `frep mesh` (its default workers), at each resolution; printed:
wall time, the search / exact ratio, volume (against the closed form where there is one),
unpaired edges (0: watertight) and the report's search count. Never fails on time.

Cases: cube   the unit cube OBJ (12 triangles) along (0.05, 0.05, 0.05) -> (2.05, ..) -> (2.05,
              1.55, 0.05): the union of two boxes, volume 4.5
       ltool  an L prism STL (20 triangles, non-convex) along two segments, one oblique
       bunny  --bunny FILE (a closed STL, e.g. the one bench_minkowski_general.py writes) along
              three segments; its search is slow, see --timeout

Usage: bench/bench_mesh_sweep.py [--res 48,64] [--timeout 300] [--bunny FILE] [--frep build/bin/frep]
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from bench_minkowski_general import l_tool, unpaired_edges, write_stl  # noqa: E402
from bench_minkowski_peers import read_stl, volume  # noqa: E402


def model(part, path, search):
    k = len(path)
    ps = ", ".join("%g" % c for p in path for c in p)
    ts = ", ".join(str(i) for i in range(k))
    arrays = "ts[%d], ps[%d]" % (k, 3 * k) + (", an[%d]" % (3 * k) if search else "")
    body = "  ts = [%s];\n  ps = [%s];\n" % (ts, ps)
    if search:
        body += "  an = [%s];\n  my_model = frSweepKeys(x, part, ts, ps, an);\n" % ", ".join(["0"] * (3 * k))
    else:
        body += "  my_model = frSweepKeys(x, part, ts, ps);\n"
    return 'part(x[3], a[1]) { part = frMesh(x, "%s"); }\nmy_model(x[3], a[1]) {\n  array %s;\n%s}\n' % (
        part, arrays, body)


def run(frep, hf, box, res, out, timeout):
    cmd = [frep, "mesh", hf, "-b", ",".join("%g" % b for b in box), "--res", str(res), "-O", out, "--no-progress"]
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, "timeout after %g s" % timeout
    dt = time.monotonic() - t0
    if p.returncode != 0:
        return None, p.stderr.decode(errors="replace")[-300:]
    tris = read_stl(out)
    report = open(out + ".report.json").read()
    at = report.find('"searches": ')
    searches = report[at + 12:].split(",")[0].split("\n")[0].strip() if at >= 0 else "?"
    return dict(wall=dt, tris=len(tris), vol=volume(tris), open=unpaired_edges(tris), searches=searches), ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frep", default=os.path.join(ROOT, "build", "bin", "frep"))
    ap.add_argument("--res", default="48,64")
    ap.add_argument("--timeout", type=float, default=300)
    ap.add_argument("--bunny", default=None)
    ap.add_argument("--only", default="")
    ap.add_argument("--keep", default=None)
    args = ap.parse_args()
    if not os.path.exists(args.frep):
        print("frep not found (build it, or pass --frep)")
        return 0
    sys.stdout.reconfigure(line_buffering=True)
    work = args.keep or tempfile.mkdtemp(prefix="bench_mesh_sweep_")
    os.makedirs(work, exist_ok=True)
    cube_v = [[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    cube_t = [(0, 2, 3), (0, 3, 1), (4, 5, 7), (4, 7, 6), (0, 1, 5), (0, 5, 4), (2, 6, 7), (2, 7, 3), (0, 4, 6),
              (0, 6, 2), (1, 3, 7), (1, 7, 5)]
    with open(os.path.join(work, "cube.obj"), "w") as f:
        f.writelines("v %g %g %g\n" % tuple(v) for v in cube_v)
        f.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in cube_t)
    lv, lt = l_tool(0.5)
    write_stl(os.path.join(work, "ltool.stl"), lv, lt)
    cases = [
        ("cube", "cube.obj", [(0.05, 0.05, 0.05), (2.05, 0.05, 0.05), (2.05, 1.55, 0.05)], (-0.3, -0.3, -0.3, 3.4, 2.9, 1.4),
         4.5),
        ("ltool", "ltool.stl", [(0, 0, 0), (1.2, 0, 0), (1.6, 0.9, 0.5)], (-0.8, -0.8, -0.6, 2.4, 1.8, 1.2), None),
    ]
    if args.bunny:
        shutil.copy(args.bunny, os.path.join(work, "bunny.stl"))
        cases.append(("bunny", "bunny.stl", [(0, 0, 0), (0.6, 0, 0), (0.6, 0.5, 0), (0.9, 0.5, 0.4)],
                      (-1.2, -1.2, -1, 2.1, 1.7, 1.4), None))
    if args.only:
        cases = [c for c in cases if c[0] in args.only.split(",")]
    print("Mesh sweeps by translation: exact sum with the path vs the search (zero angles), frep mesh")
    print("%d cores, load average %.2f; work in %s" % (os.cpu_count(), os.getloadavg()[0], work))
    for name, part, path, box, exact in cases:
        print("\n== %s along %d segments%s" % (name, len(path) - 1, ", exact volume %g" % exact if exact else ""))
        print("  %-7s %5s %9s %10s %12s %9s %6s %9s" % ("path", "res", "wall s", "triangles", "volume", "vol err", "open",
                                                       "searches"))
        for res in [int(r) for r in args.res.split(",")]:
            walls = {}
            for search in (False, True):
                kind = "search" if search else "exact"
                hf = os.path.join(work, "%s_%s.hf" % (name, kind))
                with open(hf, "w") as f:
                    f.write(model(part, path, search))
                r, err = run(args.frep, hf, box, res, os.path.join(work, "%s_%s_%d.stl" % (name, kind, res)),
                             args.timeout)
                if r is None:
                    print("  %-7s %5d failed: %s" % (kind, res, err.strip()))
                    continue
                walls[kind] = r["wall"]
                e = "%+8.3f%%" % (100 * (r["vol"] - exact) / exact) if exact else "%9s" % "-"
                print("  %-7s %5d %9.2f %10d %12.6f %s %6d %9s" % (kind, res, r["wall"], r["tris"], r["vol"], e, r["open"],
                                                                 r["searches"]))
            if len(walls) == 2:
                print("  search / exact at %d: %.1fx" % (res, walls["search"] / walls["exact"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
