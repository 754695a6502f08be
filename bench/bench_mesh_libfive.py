#!/usr/bin/python3
"""libfive's mesher against `frep mesh` on bench_mesh.cpp's model, measured on this machine.

Replaces libfive's published figure (~21 M voxel-eq/s, multi-core) by runs of both tools on the
same model, box and grid. Optional, not part of CI: libfive is built outside this repository, e.g.
  fetch https://github.com/libfive/libfive into /work/peers/libfive-src, then
  cmake -S /work/peers/libfive-src -B /work/peers/libfive-build -DCMAKE_BUILD_TYPE=Release \
    -DBUILD_STUDIO_APP=OFF -DBUILD_GUILE_BINDINGS=OFF -DBUILD_PYTHON_BINDINGS=OFF -DBUILD_TESTS=OFF \
    -DENABLE_DEBUG=OFF && cmake --build /work/peers/libfive-build --target libfive -j2
Accuracy: every referenced vertex, each triangle's centroid and 3 interior barycentric points are
projected on {f = 0} (Newton along grad f, else bracketing along the gradient, as bench_mesh.cpp
does, or Gauss-Newton onto the rim where the sphere meets the sheet); the distance moved, in each
tool's own cell size, bounds the mesh -> surface distance.
"""
import argparse
import filecmp
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
LO, HI = -1.1, 1.1
# Same text as kGyroidHf in bench_mesh.cpp.
GYROID_HF = """-- bench_mesh: the unit ball intersected with a gyroid sheet (period 2 pi / 8)
my_model(x[3], a[1])
{
  g = sin(8*x[1])*cos(8*x[2]) + sin(8*x[2])*cos(8*x[3]) + sin(8*x[3])*cos(8*x[1]);
  my_model = min(1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3], 0.3 - abs(g));
}
"""


def terms(p):
    """The two terms of f = min(ball, sheet) and their gradients (frepfarm sign: solid f >= 0)."""
    X, Y, Z = 8 * p[:, 0], 8 * p[:, 1], 8 * p[:, 2]
    sx, cx, sy, cy, sz, cz = np.sin(X), np.cos(X), np.sin(Y), np.cos(Y), np.sin(Z), np.cos(Z)
    g = sx * cy + sy * cz + sz * cx
    dg = 8 * np.stack([cx * cy - sz * sx, cy * cz - sx * sy, cz * cx - sy * sz], 1)
    return 1 - (p * p).sum(1), -2 * p, 0.3 - np.abs(g), -np.sign(g)[:, None] * dg


def f_grad(p):
    ball, gball, sheet, gsheet = terms(p)
    use_ball = ball < sheet
    return np.where(use_ball, ball, sheet), np.where(use_ball[:, None], gball, gsheet)


def f_only(p):
    return f_grad(p)[0]


def project(p0, voxel):
    """Distance each point moves to reach {f = 0} (world units; -1 if not found within 3 voxels)."""
    x = p0.copy()
    dist = np.full(len(p0), -1.0)
    todo = np.arange(len(p0))
    for _ in range(40):
        if not len(todo):
            break
        f, g = f_grad(x[todo])
        gg = (g * g).sum(1)
        ok = (gg > 0) & np.isfinite(f)
        s = np.where(ok, f / np.where(ok, gg, 1), 0)
        x[todo] -= s[:, None] * g
        moved = np.linalg.norm(x[todo] - p0[todo], axis=1)
        done = ok & (np.abs(s) * np.sqrt(gg) < 1e-9 * voxel) & (moved <= 3 * voxel)
        dist[todo[done]] = moved[done]
        todo = todo[ok & ~done & (moved <= 3 * voxel)]
    # Bracketing along the initial gradient (0.05 voxel steps, 3 voxels each way), then bisection.
    rest = np.flatnonzero(dist < 0)
    rim = project_rim(p0[rest], voxel)
    if len(rest):
        f0, g0 = f_grad(p0[rest])
        d = g0 / np.maximum(np.linalg.norm(g0, axis=1), 1e-300)[:, None]
        at = lambda idx, t: f_only(p0[rest[idx]] + t[:, None] * d[idx])
        found = np.zeros(len(rest), bool)
        for k in range(1, 61):
            for sgn in (-1, 1):
                idx = np.flatnonzero(~found)
                if not len(idx):
                    break
                t0 = np.full(len(idx), sgn * (k - 1) * 0.05 * voxel)
                t1 = np.full(len(idx), sgn * k * 0.05 * voxel)
                fa = f0[idx] if k == 1 else at(idx, t0)
                hit = (fa >= 0) != (at(idx, t1) >= 0)
                idx, t0, t1, fa = idx[hit], t0[hit], t1[hit], fa[hit]
                for _ in range(60):
                    tm = 0.5 * (t0 + t1)
                    same = (at(idx, tm) >= 0) == (fa >= 0)
                    t0, t1 = np.where(same, tm, t0), np.where(same, t1, tm)
                dist[rest[idx]] = np.abs(0.5 * (t0 + t1))
                found[idx] = True
        # Both give points of {f = 0}: keep the nearer.
        d = dist[rest]
        dist[rest] = np.where((rim >= 0) & ((d < 0) | (rim < d)), rim, d)
    return dist


def project_rim(p0, voxel):
    """Distance moved to the rim {ball = 0, sheet = 0} (least-norm Gauss-Newton on both terms), -1
    if not within 3 voxels. Points just outside the rim (a convex crease) have no sign change along
    the gradient, so the one-term Newton and the bracketing above both miss them."""
    x = p0.copy()
    dist = np.full(len(p0), -1.0)
    todo = np.arange(len(p0))
    for _ in range(40):
        if not len(todo):
            break
        f1, g1, f2, g2 = terms(x[todo])
        a, b, c = (g1 * g1).sum(1), (g1 * g2).sum(1), (g2 * g2).sum(1)
        det = a * c - b * b
        ok = det > 1e-12 * a * c
        det = np.where(ok, det, 1)
        l1, l2 = (c * f1 - b * f2) / det, (a * f2 - b * f1) / det
        step = np.where(ok[:, None], l1[:, None] * g1 + l2[:, None] * g2, 0)
        x[todo] -= step
        moved = np.linalg.norm(x[todo] - p0[todo], axis=1)
        done = ok & (np.linalg.norm(step, axis=1) < 1e-9 * voxel) & (moved <= 3 * voxel)
        dist[todo[done]] = moved[done]
        todo = todo[ok & ~done & (moved <= 3 * voxel)]
    return dist


def read_ply(path):
    """Binary little-endian PLY: vertex xyz (+ other scalar properties), faces as a list of 3."""
    types = {"float": "f4", "double": "f8", "uchar": "u1", "char": "i1", "int": "i4", "uint": "u4",
             "short": "i2", "ushort": "u2", "float32": "f4", "float64": "f8", "int32": "i4", "uint32": "u4"}
    with open(path, "rb") as fh:
        elems = []
        while True:
            line = fh.readline().decode().split()
            if line[:1] == ["element"]:
                elems.append((line[1], int(line[2]), []))
            elif line[:1] == ["property"]:
                elems[-1][2].append(line[1:])
            elif line[:1] == ["end_header"]:
                break
        data = {}
        for name, count, props in elems:
            if props[0][0] == "list":
                _, ct, it, _ = props[0]
                dt = np.dtype([("n", types[ct]), ("i", types[it], 3)])
            else:
                dt = np.dtype([(p[1], types[p[0]]) for p in props])
            data[name] = np.frombuffer(fh.read(count * dt.itemsize), dt, count)
    v = data["vertex"]
    assert (data["face"]["n"] == 3).all()
    return np.stack([v["x"], v["y"], v["z"]], 1).astype(np.float64), data["face"]["i"].astype(np.int64)


def edge_check(tris, nv):
    """(open or non-manifold edges, edges used twice in the same direction, degenerate triangles)."""
    a, b = tris, np.roll(tris, -1, axis=1)
    a, b = a.ravel(), b.ravel()
    _, uc = np.unique(np.minimum(a, b) * nv + np.maximum(a, b), return_counts=True)
    _, dc = np.unique(a * nv + b, return_counts=True)
    degenerate = int(((tris[:, 0] == tris[:, 1]) | (tris[:, 1] == tris[:, 2]) | (tris[:, 0] == tris[:, 2])).sum())
    return int((uc != 2).sum()), int((dc > 1).sum()), degenerate


def accuracy(pts, tris, voxel, chunk=1 << 20):
    """mesh -> surface max and mean distance in voxels, and the number of unprojected points."""
    used = np.unique(tris)
    bary = np.array([[1 / 3, 1 / 3, 1 / 3], [2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])
    mx, total, n, failed = 0.0, 0.0, 0, 0
    sources = [pts[used[i:i + chunk]] for i in range(0, len(used), chunk)]
    for w in bary:
        sources += [(w[0] * pts[t[:, 0]] + w[1] * pts[t[:, 1]] + w[2] * pts[t[:, 2]])
                    for t in (tris[i:i + chunk] for i in range(0, len(tris), chunk))]
    for q in sources:
        d = project(q, voxel) / voxel
        good = d >= 0
        failed += int((~good).sum())
        if good.any():
            mx, total, n = max(mx, d[good].max()), total + d[good].sum(), n + int(good.sum())
    return mx, total / max(n, 1), failed


def ply_triangles(path):
    """The face count of a PLY header."""
    with open(path, "rb") as fh:
        for line in iter(fh.readline, b"end_header\n"):
            if line.startswith(b"element face"):
                return int(line.split()[2])
    return 0


def error_bound_voxels(ply, voxel):
    """The certified error bound of `frep mesh`'s report beside the mesh, in voxels."""
    with open(ply + ".report.json") as fh:
        s = json.load(fh)["output"].get("simplification")
    return s["error_bound"] / voxel if s else 0.0


def summarise(rows, n):
    """Ratios within this run at grid N: the adaptive mesh against the raw mesher and libfive."""
    at = {(r[0], r[2]): r for r in rows if r[1] == n}
    print(f"\nN={n}: triangles, error bound (voxels) and ratios of wall and CPU time, same run")
    for key in (("frep adaptive", 1), ("frep adaptive", 2), ("before adaptive", 2)):
        if key not in at:
            continue
        _, _, thr, wall, cpu, _, ply, voxel = at[key]
        line = f"  {key[0]:15s} {thr} thr: {ply_triangles(ply):9d} triangles, bound {error_bound_voxels(ply, voxel):.3f}"
        for ref in (("frep raw", thr), ("libfive DC", thr), ("frep adaptive", 2)):
            if ref in at and ref != key:
                r = at[ref]
                line += f"; /{ref[0]} {thr if ref[0] != 'frep adaptive' else 2} thr: wall {wall / r[3]:.2f}x CPU {cpu / r[4]:.2f}x"
        print(line, flush=True)
    print(flush=True)


def timed(cmd):
    """Run cmd; returns (stdout, wall seconds, CPU seconds of the child, user + system)."""
    r0, t0 = resource.getrusage(resource.RUSAGE_CHILDREN), time.monotonic()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    wall, r1 = time.monotonic() - t0, resource.getrusage(resource.RUSAGE_CHILDREN)
    return out.stdout + out.stderr, wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--libfive-src", default="/work/peers/libfive-src")
    ap.add_argument("--libfive-build", default="/work/peers/libfive-build")
    ap.add_argument("--frep", default=os.path.join(ROOT, "build", "bin", "frep"))
    ap.add_argument("--sizes", default="256,512")
    ap.add_argument("--no-adaptive-above", type=int, default=1 << 30,
                    help="skip frep's adaptive (default tolerance) run above this N")
    ap.add_argument("--repeat", type=int, default=1, help="best of R runs (CPU time; not the adaptive run)")
    ap.add_argument("--keep", help="directory to keep the meshes in (default: a temporary one)")
    ap.add_argument("--frep-before", help="another frep binary (e.g. an older build) whose default adaptive "
                    "`frep mesh` is measured in the same run, for a before/after ratio")
    ap.add_argument("--no-accuracy", action="store_true", help="skip the mesh -> surface distances (faster)")
    args = ap.parse_args()
    lib = os.path.join(args.libfive_build, "libfive", "src", "libfive.so")
    inc = os.path.join(args.libfive_src, "libfive", "include")
    if not (os.path.exists(lib) and os.path.isdir(inc)):
        print(__doc__.split("Accuracy:")[0].strip())
        print(f"\nlibfive not found ({lib}, {inc}): nothing measured.")
        return 0
    work = args.keep or tempfile.mkdtemp(prefix="bench_mesh_libfive_")
    os.makedirs(work, exist_ok=True)
    driver = os.path.join(work, "bench_mesh_libfive")
    # -march=native like libfive's own build: its Eigen members' alignment must match.
    subprocess.run(["g++", "-O2", "-march=native", "-std=c++17", "-I", inc, "-I", "/usr/include/eigen3",
                    os.path.join(HERE, "bench_mesh_libfive.cpp"), lib, "-Wl,-rpath," + os.path.dirname(lib),
                    "-o", driver], check=True)
    model = os.path.join(work, "gyroid.hf")
    with open(model, "w") as fh:
        fh.write(GYROID_HF)

    rows = []  # (tool, N, threads, wall, cpu, mesh seconds, ply, voxel)
    for n in [int(s) for s in args.sizes.split(",")]:
        if n & (n - 1):
            print(f"note: libfive's octree rounds N={n} up to {1 << (n - 1).bit_length()} cells per axis")
        for workers in (1, 2):
            ply = os.path.join(work, f"libfive_{n}_{workers}.ply")
            # Best of --repeat by render CPU: the machine is shared, other jobs only add time.
            out, wall, cpu = min((timed([driver, str(n), ply, str(workers)]) for _ in range(args.repeat)),
                                 key=lambda r: float(r[0].split()[3]))
            _, _, w_s, c_s = out.split()[:4]
            # Mesh::render's own wall and CPU (the driver's getrusage); the process adds the PLY.
            rows.append(("libfive DC", n, workers, float(w_s), float(c_s), cpu, ply, 2.2 / n))
            print(f"libfive N={n} workers={workers}: render {w_s} s wall, {c_s} s CPU; process {cpu:.2f} s CPU",
                  flush=True)
        # (label, binary, options, threads): the raw mesher in-process; the adaptive mesh in-process on
        # one thread and as plain `frep mesh` does it by default (embedded farm, 2 local workers).
        runs = [("frep raw", args.frep, ["--workers", "0", "--tolerance", "0"], 1),
                ("frep raw", args.frep, ["--workers", "0", "--tolerance", "0"], 2),
                ("frep adaptive", args.frep, ["--workers", "0"], 1),
                ("frep adaptive", args.frep, ["--workers", "2"], 2)]
        if args.frep_before:
            runs.append(("before adaptive", args.frep_before, ["--workers", "2"], 2))
        for label, binary, extra, threads in runs:
            adaptive = "--tolerance" not in extra
            if adaptive and n > args.no_adaptive_above:
                print(f"{label} N={n}: skipped (--no-adaptive-above)")
                continue
            ply = os.path.join(work, f"{label.replace(' ', '_')}_{n}_{threads}.ply")
            cmd = [binary, "mesh", model, "-b", f"{LO},{HI}", "--res", str(n), "-O", ply,
                   "--threads", str(threads), "--no-progress", *extra]
            _, wall, cpu = min((timed(cmd) for _ in range(1 if adaptive else args.repeat)), key=lambda r: r[2])
            rows.append((label, n, threads, wall, cpu, cpu, ply, 2.2 / (n - 1)))  # --res N: N points
            print(f"{label} N={n} threads={threads} ({' '.join(extra)}): {wall:.2f} s wall, {cpu:.2f} s CPU",
                  flush=True)
        summarise(rows, n)

    print("\ntool           N  thr   wall s    CPU s  proc CPU  triangles  M vox/CPU-s  Hausdorff max/mean (vox)"
          "  open/nm  misorient  degen  unprojected")
    prev = None
    for tool, n, thr, wall, cpu, pcpu, ply, voxel in rows:
        # The 2-thread meshes are usually byte-identical to the 1-thread ones: measure once.
        if not args.no_accuracy and not (prev and filecmp.cmp(prev[0], ply, shallow=False)):
            pts, tris = read_ply(ply)
            prev = (ply, len(tris), accuracy(pts, tris, voxel), edge_check(tris, len(pts)))
            del pts, tris
        _, ntris, (mx, mean, failed), (bad, mis, degen) = prev if not args.no_accuracy else (
            None, ply_triangles(ply), (float("nan"), float("nan"), 0), (0, 0, 0))
        print(f"{tool:13s} {n:4d} {thr:3d} {wall:8.2f} {cpu:8.2f} {pcpu:9.2f} {ntris:10d} {n ** 3 / cpu / 1e6:12.2f}"
              f"  {mx:11.4f} / {mean:.4f}  {bad:8d} {mis:10d} {degen:6d} {failed:12d}", flush=True)
    print("\nCPU s: libfive Mesh::render alone; frep: the whole process (parse, mesh, [simplify], write PLY)."
          "\nproc CPU: whole process for both.  M vox/CPU-s = N^3 / CPU s.  Hausdorff: mesh -> surface only,"
          "\nin each tool's cell (libfive 2.2/N: N cells; frep --res N: N points, 2.2/(N-1)).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
