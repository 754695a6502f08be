#!/usr/bin/python3
"""frepfarm vs OpenSCAD on Minkowski sums of non-convex solids, at equal volume accuracy.

Part 1 (issue 17; --only-slab runs it alone, --no-slab skips it): the non-convex slab (+) ball
of bench_minmax_form (an L-shaped plate, the block [-1, 1]^2 x [-0.25, 0.25] minus the block
[-0.2, 1.3]^2 x [-1, 1], written with min/max, plus the ball r = 0.3) by `frep mesh slab.hf`
(frMinkowski with its defaults: B&B gap 1e-3, the ball's box; the mesh straight from the model,
in-process on all cores by default, see --slab-workers) at several resolutions over
[-1.5, 1.5]^3, and by OpenSCAD's minkowski() with sphere(r = 0.3, $fn = 64 and 96). For each
OpenSCAD run, the coarsest frepfarm resolution whose volume error is at most OpenSCAD's (in
absolute value) is its equal-accuracy partner; the time ratio of the two is printed. Exact
volume: the plate is a prism P x [-h/2, h/2] (h = 0.5) over the L-shaped hexagon P (area
A = 4 - 1.2^2, perimeter L = 8, five convex corners and one reflex corner, all right angles).
Its cross-section at height z is P (+) disc(rho(z)), rho = r inside the slab's z range and
sqrt(r^2 - dz^2) beyond it, whose area is A + L rho + (5 pi / 4 - 1) rho^2 for rho <= 0.4
(five quarter discs at the convex corners; at the reflex corner the strips of its two edges
overlap in a rho x rho square counted twice); integrating over z:
    V = h (A + L r + c r^2) + 2 A r + pi L r^2 / 2 + (4/3) c r^3,   c = 5 pi / 4 - 1,
5.384059611 for r = 0.3.

Part 2: the Minkowski sum (cube 10 - sphere r 6) (+) sphere r 1.

The model is bench/bench_extremum.cpp's: A = cube of side 10 centred at the origin minus the
ball of radius 6 (min of the box's slabs and |X| - 6), B = the ball of radius 1 (1 - |X|),
A (+) B by frMinkowski (interval branch-and-bound, certified gap = half a voxel by default,
searched box [-1.5, 1.5]^3: see below),
sampled by `frep sample` on the farm with 1 and 2 local workers over [-6.5, 6.5]^3 (bricks of
32^3), then the .vdb meshed by `frep mesh out.vdb` (in-process, one thread; the farm's output is
the same bytes for any worker count, so it is meshed once); frepfarm's time is sample + mesh.
(`frep mesh model.hf` would place every vertex by root finding on the model, i.e. ~10 searches
per edge: much slower with extremum nodes; `--direct-mesh` times it.) OpenSCAD
computes `minkowski()` of the same solids with polygonal spheres whose deviation from the true
sphere is at most frepfarm's voxel size (both are printed; --scad-dev 1,0.5 adds a run at half
a voxel). For every run: wall time, triangles,
the mesh volume (signed tetrahedron sum) and its error against the exact volume, and the time
ratio frepfarm / OpenSCAD measured in the same run. Then the farm's 1 -> 2 worker speed-up on a
sweep model (examples/extremum/keyframe_sweep.hf). Never fails on time.

Exact volume. A (+) B1 = {X : dist(X, A) <= 1}, the parallel body of A at distance 1. A has
positive reach larger than 1 (the points with two nearest points of A are the centre, at
distance 6, and the axes through the six face centres, at distance >= sqrt(11) from A), so the
Steiner-Federer formula holds exactly for r = 1:
    V(A_r) = V + S r + M r^2 + (4 pi / 3) chi r^3,
with V the volume, S the area, M the integrated mean curvature (smooth parts: the integral of
(k1 + k2)/2, edges: length x exterior dihedral angle / 2) and chi the Euler characteristic.
With a = 5 (half side), R = 6, cap height h = R - a = 1, circle radius rho = sqrt(R^2 - a^2):
    V   = 1000 - (4/3 pi R^3 - 6 pi h^2 (3R - h) / 3)           = 1000 - 254 pi
    S   = 600 - 6 pi rho^2 + (4 pi R^2 - 6 * 2 pi R h)           = 600 + 6 pi
    M   = sphere part, concave: -(1/R) (4 pi R^2 - 12 pi R h)    = -12 pi
          + 12 cube edges of length 10, angle pi/2: 12*10*(pi/2)/2 = 30 pi
          + 6 circles of length 2 pi rho, exterior angle acos(-a/R): 6 pi rho acos(-5/6)
    chi = -4 (A retracts onto the cube's surface minus six discs: a sphere with six holes)
giving 1020.4659. Cross-checked by build/bin/bench_minkowski_peers_exact (midpoint rule on
{dist(X, A) <= 1} over [-6, 6]^3, dist exact: the nearest point of A is a critical point of one
stratum, face, edge, corner, sphere or face circle): 1020.5294 / 1020.4131 / 1020.4889 with
400 / 800 / 1600 cells per axis, i.e. +6.2e-5 / -5.2e-5 / +2.2e-5 relative to the formula
(lattice-count noise shrinking with the cell).

Why the searched box is larger than B's [-1, 1]^3: the sign of the sum only needs u in B, but
the values beside the surface (stored in the .vdb and interpolated by the mesher) need u up to
1 + (band distance) / 2: outside, the maximiser has B(u) = A(X - u) < 0, i.e. |u| > 1. With
the box [-1, 1]^3 the values outside the flat faces come out twice too steep and the mesh from
the .vdb loses 2.1% of the volume at 64^3 (measured); with [-1.5, 1.5]^3, -0.34%.

Usage: bench/bench_minkowski_peers.py [--quick] [--res 64,128] [--frep build/bin/frep]
       [--openscad /usr/bin/openscad] [--workers 1,2] [--brick 32] [--timeout 1800] [--keep DIR]
       [--tol-voxels 0.5] [--scad-dev 1[,0.5]] [--direct-mesh] [--no-sweep]
       [--only-slab | --no-slab] [--slab-res 40,48,...] [--slab-fn 64,96] [--slab-workers 0] [--repeat 3]
"""
import argparse
import math
import os
import resource
import shutil
import struct
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def exact_volume():
    pi, a, R = math.pi, 5.0, 6.0
    h, rho = R - a, math.sqrt(R * R - a * a)
    V = (2 * a) ** 3 - (4 / 3 * pi * R ** 3 - 6 * pi * h * h * (3 * R - h) / 3)
    S = 6 * (2 * a) ** 2 - 6 * pi * rho ** 2 + (4 * pi * R * R - 6 * 2 * pi * R * h)
    M = -(4 * pi * R * R - 12 * pi * R * h) / R + 12 * (2 * a) * (pi / 2) / 2 + 6 * pi * rho * math.acos(-a / R)
    chi = -4
    return V + S + M + 4 * pi / 3 * chi


MODEL = """-- (cube 10 - sphere r 6) + sphere r 1, as bench/bench_extremum.cpp (generated by bench_minkowski_peers.py)
shell(x[3], a[1]) {{ shell = min(min(min(5 - abs(x[1]), 5 - abs(x[2])), 5 - abs(x[3])), sqrt(x[1]^2 + x[2]^2 + x[3]^2) - 6); }}
ball1(x[3], a[1]) {{ ball1 = 1 - sqrt(x[1]^2 + x[2]^2 + x[3]^2); }}
my_model(x[3], a[1]) {{
  array o[8];
  o = [0, {tol:.6g}, -1.5, 1.5, -1.5, 1.5, -1.5, 1.5];
  my_model = frMinkowski(x, shell, ball1, o);
}}
"""

SCAD = """// (cube 10 - sphere r 6) + sphere r 1 (generated by bench_minkowski_peers.py)
minkowski() {{
  difference() {{ cube(10, center = true); sphere(r = 6, $fn = {n6}); }}
  sphere(r = 1, $fn = {n1});
}}
"""


SLAB_MODEL = """-- non-convex slab (+) ball r 0.3, written with min/max (generated by bench_minkowski_peers.py)
slab(x[3], a[1]) {
  b1 = min(min(min(x[1] + 1, 1 - x[1]), min(x[2] + 1, 1 - x[2])), min(x[3] + 0.25, 0.25 - x[3]));
  b2 = min(min(min(x[1] + 0.2, 1.3 - x[1]), min(x[2] + 0.2, 1.3 - x[2])), min(x[3] + 1, 1 - x[3]));
  slab = min(b1, -b2);
}
ball(x[3], a[1]) { ball = 0.09 - x[1]^2 - x[2]^2 - x[3]^2; }
my_model(x[3], a[1]) { my_model = frMinkowski(x, slab, ball); }
"""

SLAB_SCAD = """// non-convex slab (+) ball r 0.3 (generated by bench_minkowski_peers.py)
minkowski() {{
  difference() {{ translate([-1, -1, -0.25]) cube([2, 2, 0.5]); translate([-0.2, -0.2, -1]) cube([1.5, 1.5, 2]); }}
  sphere(r = 0.3, $fn = {fn});
}}
"""


def slab_exact_volume(r=0.3):
    A, L, h, c = 4 - 1.2 ** 2, 8.0, 0.5, 5 * math.pi / 4 - 1
    return h * (A + L * r + c * r * r) + 2 * A * r + math.pi * L * r * r / 2 + 4 / 3 * c * r ** 3


def slab_section(args, frep, have_scad, work):
    exact = slab_exact_volume()
    print("non-convex slab (+) ball r 0.3 (issue 17): frep mesh of the model vs OpenSCAD minkowski(), equal volume accuracy")
    print("exact volume %.6f (prism formula, see the header); load average %.2f" % (exact, os.getloadavg()[0]))
    hf = os.path.join(work, "slab.hf")
    with open(hf, "w") as f:
        f.write(SLAB_MODEL)
    frep_runs = []  # (res, wall, cpu, triangles, error)
    wflags = ["--workers", args.slab_workers] if args.slab_workers != "0" else ["--workers", "0"]
    for res in [int(r) for r in args.slab_res.split(",")]:
        stl = os.path.join(work, "slab_frep_%d.stl" % res)
        walls, cpus = [], []
        for _ in range(args.repeat):
            p, dt, err = run([frep, "mesh", hf, "-b", "-1.5,1.5", "--res", str(res), "-O", stl, "--no-progress"] + wflags,
                             args.timeout)
            if p is None:
                print("  frep mesh --res %d failed: %s" % (res, err))
                break
            walls.append(dt)
            cpus.append(CPU["last"])
        if not walls:
            continue
        tris = read_stl(stl)
        e = (volume(tris) - exact) / exact
        frep_runs.append((res, sorted(walls)[len(walls) // 2], sorted(cpus)[len(cpus) // 2], len(tris), e))
    scad_runs = []
    for fn in ([int(x) for x in args.slab_fn.split(",")] if have_scad else []):
        scad = os.path.join(work, "slab_%d.scad" % fn)
        with open(scad, "w") as f:
            f.write(SLAB_SCAD.format(fn=fn))
        out = os.path.join(work, "slab_openscad_%d.stl" % fn)
        p, dt, err = run([args.openscad, "-o", out, scad], args.timeout)
        if p is None:
            print("  openscad $fn %d failed: %s" % (fn, err))
            continue
        tris = read_stl(out)
        scad_runs.append((fn, dt, CPU["last"], len(tris), (volume(tris) - exact) / exact))
    print("  %-34s %8s %8s %10s %9s" % ("system", "wall s", "CPU s", "triangles", "vol err"))
    for res, wall, cpu, n, e in frep_runs:
        print("  %-34s %8.2f %8.2f %10d %+8.4f%%" % ("frep mesh --res %d (%s)" % (res, "in-process" if args.slab_workers == "0" else args.slab_workers + " workers"), wall, cpu, n, 100 * e))
    for fn, wall, cpu, n, e in scad_runs:
        print("  %-34s %8.2f %8.2f %10d %+8.4f%%" % ("OpenSCAD minkowski(), $fn %d" % fn, wall, cpu, n, 100 * e))
    for fn, wall, cpu, n, e in scad_runs:
        match = [r for r in frep_runs if abs(r[4]) <= abs(e)]
        if not match:
            print("  $fn %d (%+.4f%%): no frepfarm resolution tried is as accurate" % (fn, 100 * e))
            continue
        res, fwall, fcpu, fn_tris, fe = min(match, key=lambda r: r[1])
        print("  equal accuracy, OpenSCAD $fn %d (%+.4f%%, %.2f s) vs frep mesh --res %d (%+.4f%%, %.2f s): OpenSCAD / frepfarm = %.1fx wall (%.1fx CPU)" %
              (fn, 100 * e, wall, res, 100 * fe, fwall, wall / fwall, cpu / max(fcpu, 1e-9)))


def openscad_sphere_deviation(R, fn):
    """Largest distance from the sphere of radius R to OpenSCAD 2021.01's sphere(r = R, $fn = fn).

    That polyhedron has rings = (fn + 1) / 2 latitude rings at polar angles 180 (i + 0.5) / rings
    degrees, each a regular fn-gon of vertices on the sphere; its faces are planar (quads between
    rings at the same azimuths, and the two polar caps), so the deviation is R minus the smallest
    distance from the centre to a face plane."""
    fragments = max(fn, 3)
    rings = (fragments + 1) // 2
    phis = [math.pi * (i + 0.5) / rings for i in range(rings)]
    dmin = R * math.cos(phis[0])  # the polar cap polygons
    # apothem of the fn-gon of radius s: s cos(pi / fn); a quad between rings i, i + 1 is the
    # trapezoid spanned by two such chords; its plane distance from the centre:
    c = math.cos(math.pi / fragments)
    for i in range(rings - 1):
        s1, z1 = R * math.sin(phis[i]), R * math.cos(phis[i])
        s2, z2 = R * math.sin(phis[i + 1]), R * math.cos(phis[i + 1])
        # in the (radial, z) half-plane through the chord midpoints: line from (s1 c, z1) to (s2 c, z2)
        x1, x2 = s1 * c, s2 * c
        dx, dz = x2 - x1, z2 - z1
        d = abs(x1 * dz - z1 * dx) / math.hypot(dx, dz)
        dmin = min(dmin, d)
    return R - dmin


def fn_for(R, tol):
    fn = 3
    while openscad_sphere_deviation(R, fn) > tol:
        fn += 1
    return fn


def read_stl(path):
    """Triangles of an STL file (ASCII or binary) as lists of three (x, y, z) tuples."""
    with open(path, "rb") as f:
        data = f.read()
    tris = []
    if data[:5] == b"solid" and b"facet" in data[:400]:
        verts = []
        for line in data.decode("ascii", "replace").splitlines():
            p = line.split()
            if p and p[0] == "vertex":
                verts.append((float(p[1]), float(p[2]), float(p[3])))
        tris = [verts[i:i + 3] for i in range(0, len(verts) - 2, 3)]
    else:
        n = struct.unpack_from("<I", data, 80)[0]
        off = 84
        for _ in range(n):
            v = struct.unpack_from("<12f", data, off)
            tris.append([v[3:6], v[6:9], v[9:12]])
            off += 50
    return tris


def volume(tris):
    s = 0.0
    for a, b, c in tris:
        s += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
              a[2] * (b[0] * c[1] - b[1] * c[0]))
    return s / 6.0


CPU = {"last": 0.0}  # CPU seconds (user + system) of the last run, workers included


def run(cmd, timeout):
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, time.monotonic() - t0, "timeout"
    dt = time.monotonic() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    CPU["last"] = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    if p.returncode != 0:
        return None, dt, p.stderr.decode(errors="replace")[-400:]
    return p, dt, ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="64^3 only")
    ap.add_argument("--res", default="64,128")
    ap.add_argument("--frep", default=None)
    ap.add_argument("--openscad", default="/usr/bin/openscad")
    ap.add_argument("--workers", default="1,2")
    ap.add_argument("--timeout", type=float, default=1800.0)
    ap.add_argument("--keep", default=None, help="keep the models and meshes in this directory")
    ap.add_argument("--scad-dev", default="1",
                    help="OpenSCAD runs: largest sphere deviation as fractions of the voxel, e.g. 1,0.5")
    ap.add_argument("--no-sweep", action="store_true", help="skip the farm speed-up on the sweep example")
    ap.add_argument("--tol-voxels", type=float, default=0.5, help="B&B certified gap in voxels")
    ap.add_argument("--brick", type=int, default=32, help="farm brick edge (64^3 is one brick at the default 64)")
    ap.add_argument("--direct-mesh", action="store_true",
                    help="also time `frep mesh model.hf` (vertices by root finding on the model: slow with extremum nodes)")
    ap.add_argument("--only-slab", action="store_true", help="part 1 only (issue 17's comparison)")
    ap.add_argument("--no-slab", action="store_true", help="skip part 1")
    ap.add_argument("--slab-res", default="40,44,48,52,56,60,64,66,68,72,80")
    ap.add_argument("--slab-fn", default="64,96", help="OpenSCAD sphere $fn of part 1")
    ap.add_argument("--slab-workers", default="0", help="frep mesh --workers for part 1 (0: in-process, all cores)")
    ap.add_argument("--repeat", type=int, default=3, help="part 1: frep runs per resolution (median)")
    args = ap.parse_args()
    frep = args.frep
    if frep is None:
        for d in ("build", "build-peers"):
            c = os.path.join(ROOT, d, "bin", "frep")
            if os.path.exists(c):
                frep = c
                break
    if frep is None or not os.path.exists(frep):
        print("frep not found (build it, or pass --frep)")
        return 0
    have_scad = os.path.exists(args.openscad)
    resolutions = [64] if args.quick else [int(r) for r in args.res.split(",")]
    workers = [int(w) for w in args.workers.split(",")]
    scad_devs = [float(d) for d in args.scad_dev.split(",")]
    work = args.keep or tempfile.mkdtemp(prefix="bench_minkowski_peers_")
    os.makedirs(work, exist_ok=True)
    sys.stdout.reconfigure(line_buffering=True)
    if not args.no_slab:
        slab_section(args, frep, have_scad, work)
        if args.only_slab:
            if args.keep is None:
                shutil.rmtree(work, ignore_errors=True)
            return 0
        print()
    exact = exact_volume()
    lo, hi = -6.5, 6.5
    print("(cube 10 - sphere r 6) + sphere r 1: frepfarm (frMinkowski B&B: frep sample on the farm + frep mesh of the .vdb) vs OpenSCAD minkowski()")
    print("exact volume %.4f (Steiner-Federer formula for the parallel body, see the header)" % exact)
    print("frep: %s   openscad: %s" % (frep, args.openscad if have_scad else "(not installed)"))
    print("%d cores, load average %.2f (speed-ups need idle cores; the CPU columns show what each run got)" %
          (os.cpu_count(), os.getloadavg()[0]))
    rows = []
    for res in resolutions:
        voxel = (hi - lo) / (res - 1)
        tol = args.tol_voxels * voxel  # default as bench_extremum: the B&B gap = half a voxel
        hf = os.path.join(work, "mink_%d.hf" % res)
        with open(hf, "w") as f:
            f.write(MODEL.format(tol=tol))
        print("\n%d^3 over [%g, %g]^3: voxel h = %.4f, B&B certified gap %.4f" % (res, lo, hi, voxel, tol))
        frep_times, frep_cpu = {}, {}
        vdb1 = None
        for w in workers:
            vdb = os.path.join(work, "frep_%d_w%d.vdb" % (res, w))
            cmd = [frep, "sample", hf, "-b", "%g,%g" % (lo, hi), "--res", str(res), "-O", vdb,
                   "--workers", str(w), "--brick", str(args.brick), "--no-progress"]
            p, dt, err = run(cmd, args.timeout)
            if p is None:
                print("  frep sample --workers %d failed: %s" % (w, err))
                continue
            frep_times[w] = dt
            frep_cpu[w] = CPU["last"]
            vdb1 = vdb1 or vdb
        if vdb1:
            # The farm's output is the same bytes for any worker count: mesh it once.
            stl = os.path.join(work, "frep_%d.stl" % res)
            p, mesh_dt, err = run([frep, "mesh", vdb1, "-O", stl, "--threads", "1"], args.timeout)
            if p is None:
                print("  frep mesh %s failed: %s" % (vdb1, err))
            else:
                tris = read_stl(stl)
                v = volume(tris)
                for w, dt in sorted(frep_times.items()):
                    frep_times[w] = dt + mesh_dt
                    rows.append((res, "frepfarm, %d worker%s" % (w, "s" if w > 1 else ""), dt + mesh_dt, len(tris), v,
                                 "sample %.2f s (CPU %.2f s) + mesh .vdb %.2f s; h = %.4f" % (dt, frep_cpu[w], mesh_dt, voxel)))
        if args.direct_mesh:
            stl = os.path.join(work, "frep_direct_%d.stl" % res)
            cmd = [frep, "mesh", hf, "-b", "%g,%g" % (lo, hi), "--res", str(res), "-O", stl,
                   "--workers", str(max(workers)), "--brick", str(args.brick), "--no-progress"]
            p, dt, err = run(cmd, args.timeout)
            if p is None:
                print("  frep mesh (model) failed after %.1f s: %s" % (dt, err))
            else:
                tris = read_stl(stl)
                rows.append((res, "frep mesh model, %d w" % max(workers), dt, len(tris), volume(tris),
                             "vertices by root finding on the model"))
        scad_time = None
        for dev_factor in (scad_devs if have_scad else []):
            n6, n1 = fn_for(6.0, dev_factor * voxel), fn_for(1.0, dev_factor * voxel)
            d6, d1 = openscad_sphere_deviation(6.0, n6), openscad_sphere_deviation(1.0, n1)
            scad = os.path.join(work, "mink_%d_%d_%d.scad" % (res, n6, n1))
            with open(scad, "w") as f:
                f.write(SCAD.format(n6=n6, n1=n1))
            out = os.path.join(work, "openscad_%d_%d_%d.stl" % (res, n6, n1))
            p, dt, err = run([args.openscad, "-o", out, scad], args.timeout)
            if p is None:
                print("  openscad $fn %d / %d failed after %.1f s: %s" % (n6, n1, dt, err))
                continue
            tris = read_stl(out)
            if scad_time is None:
                scad_time = dt  # the ratios use the first deviation (default: one voxel)
            rows.append((res, "OpenSCAD minkowski()", dt, len(tris), volume(tris),
                         "$fn %d (r 6, dev %.4f) / %d (r 1, dev %.4f); CPU %.2f s" % (n6, d6, n1, d1, CPU["last"])))
        print("  %-24s %9s %10s %11s %9s   %s" % ("system", "wall s", "triangles", "volume", "vol err", "accuracy"))
        for r in rows:
            if r[0] != res:
                continue
            print("  %-24s %9.2f %10d %11.4f %+8.3f%%   %s" % (r[1], r[2], r[3], r[4], 100 * (r[4] - exact) / exact, r[5]))
        if scad_time:
            for w, t in sorted(frep_times.items()):
                print("  ratio frepfarm (%d worker%s) / OpenSCAD time: %.3f  (OpenSCAD / frepfarm %.2fx)" %
                      (w, "s" if w > 1 else "", t / scad_time, scad_time / t))
        if 1 in frep_times and 2 in frep_times:
            print("  frepfarm speed-up 1 -> 2 workers: %.2fx" % (frep_times[1] / frep_times[2]))
    if not args.no_sweep:
        # The farm on a sweep model: examples/extremum/keyframe_sweep.hf (a block minus a ball-end
        # tool swept through keyframes), sampled at 128^3 with 1 and 2 local workers.
        model = os.path.join(ROOT, "examples", "extremum", "keyframe_sweep.hf")
        print("\nsweep model %s: frep sample -b 2.2 --res 128 --brick 32" % os.path.relpath(model, ROOT))
        times = {}
        for w in workers:
            vdb = os.path.join(work, "sweep_w%d.vdb" % w)
            p, dt, err = run([frep, "sample", model, "-b", "2.2", "--res", "128", "-O", vdb, "--workers", str(w),
                              "--brick", str(args.brick), "--no-progress"], args.timeout)
            if p is None:
                print("  --workers %d failed: %s" % (w, err))
                continue
            times[w] = dt
            print("  %d worker%s: %.2f s wall, %.2f s CPU" % (w, "s" if w > 1 else " ", dt, CPU["last"]))
        if 1 in times and 2 in times:
            same = open(os.path.join(work, "sweep_w1.vdb"), "rb").read() == open(os.path.join(work, "sweep_w2.vdb"), "rb").read()
            print("  speed-up 1 -> 2 workers: %.2fx (outputs %s)" % (times[1] / times[2], "identical" if same else "DIFFER"))
    if args.keep is None:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
