#!/usr/bin/python3
"""Minkowski sums of any operands: frepfarm vs OpenSCAD and manifold-3d at equal accuracy (issue 30).

Cases (every operand written the way a user would, HyperFun primitives or STL files):
  box_ball        hfBlock (+) hfSphere: the per-voxel baseline of operands written in HyperFun
  box_stl_ball    the same box as an STL file (+) frBall: the baseline of mesh operands
  slab_hf_ball    L-shaped slab hfBlock \\ hfBlock (+) hfSphere r 0.3 (non-convex)
  slab_stl_ball   the same slab as an STL file (+) frBall
  tetra_ball      regular tetrahedron (min of 4 planes) (+) hfSphere
  octa_ball       regular octahedron (min of 8 planes) (+) hfSphere
  octa_stl_ball   the octahedron as an STL file (+) hfSphere
  bunny_ball      Stanford bunny (npm `bunny`, holes fanned shut) (+) frBall (non-convex)
  bunny_tetra     bunny (+) a tetrahedral tool as an STL file (mesh (+) mesh)
  bunny_ltool     bunny (+) an L-shaped tool as an STL file (mesh (+) non-convex mesh)
  bunny_block     bunny (+) hfBlock
  morph_blocks    frMorphMinkowski of two hfBlocks, t = 0.6: (0.4 A) (+) (0.6 B)
Exact volumes: Steiner's formula V + S r + M r^2 + 4/3 pi r^3 for convex polytopes (+) ball (M the
sum of edge length x exterior angle / 2), the slab's prism formula (bench_minkowski_peers.py),
the box for the morph; polyhedral sums (bunny (+) tool / block) are exact in both peers, whose
volume is the reference; bunny (+) ball has no closed form: the reference is frep at --ref-res
(the exact offset path, so only meshing error; printed).

For each case: frep mesh at several resolutions and simplification tolerances (--tolerances:
0.1 voxel, frep's default; 0.02; 0, the marching tetrahedra's triangles kept), each with its
default farm (2 local workers, or in-process for a grid of at most 64^3 points, docs/cli.md; the
run's line says which), OpenSCAD minkowski() (sphere $fn from --fn) and manifold-3d
minkowskiSum (node; the whole process and the operation alone). A run under 1 s is timed by the
median of 5 (any program). Equal accuracy: for each peer
run, the fastest frep run whose |volume error| is at most the peer's (both triangle counts
printed); the ratio peer / frep of wall times is printed. Also the
per-voxel time of each case against the box (+) ball of the same form (box_ball for HyperFun
operands, box_stl_ball for meshes) at the same resolution and the first tolerance, and whether
every frep mesh is closed (unpaired edges 0). Never fails on time.

Usage: bench/bench_minkowski_general.py [--quick] [--only case,...] [--frep build/bin/frep]
       [--res 12,16,20,24,32,48,64,72,96,128] [--tolerances 0.1,0.02,0] [--timeout 300] [--keep DIR] [--no-peers]
"""
import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from bench_minkowski_peers import read_stl, slab_exact_volume, volume  # noqa: E402

# ---------------------------------------------------------------------------------------------
# Convex polytopes as meshes: Steiner's formula, planes for .hf, STL and OpenSCAD polyhedra.


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def unit(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


def outward(verts, tris):
    """Triangles oriented outward (convex: away from the centroid)."""
    c = [sum(v[k] for v in verts) / len(verts) for k in range(3)]
    out = []
    for t in tris:
        a, b, d = (verts[i] for i in t)
        n = cross(sub(b, a), sub(d, a))
        out.append(t if dot(n, sub(a, c)) > 0 else (t[0], t[2], t[1]))
    return out


TETRA_V = [[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]
TETRA_T = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
OCTA_V = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
OCTA_T = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]


# A non-convex tool: the L prism ([0,2]x[0,1] ∪ [0,1]x[0,2]) x [0,1], centred, triangles outward
# (the L faces fanned from the reflex corner; outward() assumes a convex body).
def l_tool(s):
    L = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    v = [[s * (x - 0.75), s * (y - 0.75), s * (z - 0.5)] for z in (0, 1) for (x, y) in L]
    cap = [(3, 4, 5), (3, 5, 0), (3, 0, 1), (3, 1, 2)]
    t = [(a + 6, b + 6, c + 6) for (a, b, c) in cap] + [(a, c, b) for (a, b, c) in cap]
    for i in range(6):
        j = (i + 1) % 6
        t += [(i, j, j + 6), (i, j + 6, i + 6)]
    return v, t


def scaled(verts, s):
    return [[s * x for x in v] for v in verts]


def steiner_volume(verts, tris, r):
    """V + S r + M r^2 + 4/3 pi r^3 of a convex polytope (triangulated; coplanar edges add 0)."""
    tris = outward(verts, tris)
    V = S = 0.0
    normals = []
    for a, b, c in tris:
        pa, pb, pc = verts[a], verts[b], verts[c]
        n = cross(sub(pb, pa), sub(pc, pa))
        V += dot(pa, cross(pb, pc)) / 6
        S += math.sqrt(dot(n, n)) / 2
        normals.append(unit(n))
    edges = {}
    for i, t in enumerate(tris):
        for k in range(3):
            e = tuple(sorted((t[k], t[(k + 1) % 3])))
            edges.setdefault(e, []).append(i)
    M = 0.0
    for (a, b), fs in edges.items():
        angle = math.acos(max(-1.0, min(1.0, dot(normals[fs[0]], normals[fs[1]]))))
        M += math.sqrt(dot(sub(verts[a], verts[b]), sub(verts[a], verts[b]))) * angle / 2
    return V + S * r + M * r * r + 4 / 3 * math.pi * r ** 3


def hf_planes(verts, tris):
    """min over the faces of (d - n . X) with unit n: the polytope as HyperFun text."""
    terms = []
    for a, b, c in outward(verts, tris):
        n = unit(cross(sub(verts[b], verts[a]), sub(verts[c], verts[a])))
        d = dot(n, verts[a])
        terms.append("(%.17g - (%.17g * x[1] + %.17g * x[2] + %.17g * x[3]))" % (d, n[0], n[1], n[2]))
    while len(terms) > 1:
        terms = ["min(%s, %s)" % (terms[i], terms[i + 1]) if i + 1 < len(terms) else terms[i] for i in range(0, len(terms), 2)]
    return terms[0]


def write_stl(path, verts, tris):
    with open(path, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", 0, 0, 0))
            for i in t:
                f.write(struct.pack("<3f", *verts[i]))
            f.write(b"\0\0")


def scad_polyhedron(verts, tris):
    # OpenSCAD wants faces clockwise seen from outside.
    faces = [(t[0], t[2], t[1]) for t in outward(verts, tris)]
    return "polyhedron(points = %s, faces = %s);" % (json.dumps(verts), json.dumps([list(f) for f in faces]))


def slab_mesh():
    """The L slab [-1,1]^2 x [-.25,.25] minus [-.2,1.3]^2 x R: the L hexagon extruded."""
    L = [(-1, -1), (1, -1), (1, -0.2), (-0.2, -0.2), (-0.2, 1), (-1, 1)]
    verts = [[x, y, z] for z in (-0.25, 0.25) for (x, y) in L]
    cap = [(3, 4, 5), (3, 5, 0), (3, 0, 1), (3, 1, 2)]
    tris = []
    for a, b, c in cap:
        tris += [(a + 6, b + 6, c + 6), (a, c, b)]
    for i in range(6):
        j = (i + 1) % 6
        tris += [(i, j, j + 6), (i, j + 6, i + 6)]
    return verts, tris


def bunny_mesh(npm_dir):
    """The npm `bunny` (Stanford, 2503 vertices) centred, scaled to extent 2, holes fanned shut."""
    js = "const b = require('bunny'); console.log(JSON.stringify({p: b.positions, c: b.cells}));"
    out = subprocess.run(["node", "-e", js], cwd=npm_dir, stdout=subprocess.PIPE, check=True).stdout
    d = json.loads(out)
    verts, tris = [list(map(float, p)) for p in d["p"]], [tuple(c) for c in d["c"]]
    lo = [min(v[k] for v in verts) for k in range(3)]
    hi = [max(v[k] for v in verts) for k in range(3)]
    s = 2.0 / max(hi[k] - lo[k] for k in range(3))
    verts = [[(v[k] - 0.5 * (lo[k] + hi[k])) * s for k in range(3)] for v in verts]
    directed = {}
    for t in tris:
        for k in range(3):
            directed[(t[k], t[(k + 1) % 3])] = True
    nxt = {}
    for (a, b) in directed:
        if (b, a) not in directed:
            nxt[b] = a  # the hole's boundary, walked the other way round
    seen = set()
    for start in list(nxt):
        if start in seen:
            continue
        loop, v = [], start
        while v not in seen:
            seen.add(v)
            loop.append(v)
            v = nxt[v]
        c = [sum(verts[i][k] for i in loop) / len(loop) for k in range(3)]
        verts.append(c)
        ci = len(verts) - 1
        for i in range(len(loop)):
            tris.append((loop[i], loop[(i + 1) % len(loop)], ci))
    # Orientation: outward if the signed volume is positive.
    vol = sum(dot(verts[a], cross(verts[b], verts[c])) for a, b, c in tris) / 6
    if vol < 0:
        tris = [(a, c, b) for a, b, c in tris]
    return verts, tris


def ensure_npm(work):
    npm_dir = os.path.join(ROOT, "build", "peers")
    if not os.path.isdir(os.path.join(npm_dir, "node_modules", "manifold-3d")) or \
       not os.path.isdir(os.path.join(npm_dir, "node_modules", "bunny")):
        os.makedirs(npm_dir, exist_ok=True)
        subprocess.run(["npm", "install", "--prefix", npm_dir, "--no-audit", "--no-fund", "manifold-3d", "bunny"],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    ok = os.path.isdir(os.path.join(npm_dir, "node_modules", "manifold-3d"))
    if ok:  # the peer script resolves 'manifold-3d' from its own folder's node_modules
        shutil.copy(os.path.join(HERE, "peers", "manifold_minkowski.mjs"), npm_dir)
    return npm_dir, ok


# ---------------------------------------------------------------------------------------------


def timed(cmd, timeout, repeats=5, short=1.0):
    """Runs cmd; a run shorter than `short` seconds is repeated up to `repeats` times and timed by
    the median, as one run of a few milliseconds is mostly the scheduler's noise (frep and the
    peers alike)."""
    times = []
    while True:
        t0 = time.monotonic()
        try:
            p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout)
        except subprocess.TimeoutExpired:
            return None, timeout, "timeout after %g s" % timeout
        times.append(time.monotonic() - t0)
        if p.returncode != 0:
            return None, times[-1], p.stderr.decode(errors="replace")[-300:]
        if times[0] >= short or len(times) >= repeats:
            return p, sorted(times)[len(times) // 2], ""


def unpaired_edges(tris_xyz):
    ids, count = {}, {}
    for t in tris_xyz:
        idx = [ids.setdefault(tuple(v), len(ids)) for v in t]
        for k in range(3):
            e = (idx[k], idx[(k + 1) % 3])
            count[e] = count.get(e, 0) + 1
    return sum(1 for (a, b), n in count.items() if count.get((b, a), 0) != n)


def build_cases(work, npm_dir, have_npm):
    cases = []
    blk = "hfBlock(x, v, %g, %g, %g)"

    def add(name, model, box, exact, scad=None, manifold=None, what=""):
        path = os.path.join(work, name + ".hf")
        with open(path, "w") as f:
            f.write(model)
        form = "stl" if 'frMesh(x, "' in model else "hf"  # which baseline is "of the same form"
        cases.append(dict(name=name, hf=path, box=box, exact=exact, scad=scad, manifold=manifold, what=what, form=form))

    # box (+) ball, hfBlock / hfSphere: the baseline.
    bx = [1.0, 1.0, 0.5]
    box_v = [[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.25, 0.25)]
    box_t = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    add("box_ball",
        "opa(x[3], a[1]) { array v[3]; v = [-0.5, -0.5, -0.25]; opa = " + blk % tuple(bx) + "; }\n"
        "opb(x[3], a[1]) { array c[3]; c = [0, 0, 0]; opb = hfSphere(x, c, 0.25); }\n"
        "my_model(x[3], a[1]) { my_model = frMinkowski(x, opa, opb); }\n",
        1.0, steiner_volume(box_v, box_t, 0.25),
        scad="minkowski() { translate([-0.5, -0.5, -0.25]) cube([1, 1, 0.5]); sphere(r = 0.25, $fn = FN); }",
        manifold={"a": {"cube": bx, "corner": [-0.5, -0.5, -0.25]}, "b": {"sphere": 0.25}}, what="convex, r 0.25")
    # The same box as an STL file (+) frBall: the baseline of the cases whose operand is a mesh.
    box_stl = os.path.join(work, "box.stl")
    write_stl(box_stl, box_v, outward(box_v, box_t))
    add("box_stl_ball",
        'opa(x[3], a[1]) { opa = frMesh(x, "box.stl"); }\n'
        "opb(x[3], a[1]) { opb = frBall(x, 0.25); }\n"
        "my_model(x[3], a[1]) { my_model = frMinkowski(x, opa, opb); }\n",
        1.0, steiner_volume(box_v, box_t, 0.25),
        scad="minkowski() { import(\"%s\"); sphere(r = 0.25, $fn = FN); }" % box_stl,
        manifold={"a": {"stl": box_stl}, "b": {"sphere": 0.25}}, what="convex STL, r 0.25")
    slab_v, slab_t = slab_mesh()
    slab_stl = os.path.join(work, "slab.stl")
    write_stl(slab_stl, slab_v, slab_t)
    scad_slab = ("difference() { translate([-1, -1, -0.25]) cube([2, 2, 0.5]); translate([-0.2, -0.2, -1]) cube([1.5, 1.5, 2]); }")
    add("slab_hf_ball",
        "s1(x[3], a[1]) { array v[3]; v = [-1, -1, -0.25]; s1 = hfBlock(x, v, 2, 2, 0.5); }\n"
        "s2(x[3], a[1]) { array v[3]; v = [-0.2, -0.2, -1]; s2 = hfBlock(x, v, 1.5, 1.5, 2); }\n"
        "slab(x[3], a[1]) { slab = s1(x, a) \\ s2(x, a); }\n"
        "opb(x[3], a[1]) { array c[3]; c = [0, 0, 0]; opb = hfSphere(x, c, 0.3); }\n"
        "my_model(x[3], a[1]) { my_model = frMinkowski(x, slab, opb); }\n",
        1.5, slab_exact_volume(), scad="minkowski() { %s sphere(r = 0.3, $fn = FN); }" % scad_slab,
        manifold={"a": {"stl": slab_stl}, "b": {"sphere": 0.3}}, what="non-convex, r 0.3")
    add("slab_stl_ball",
        'slab(x[3], a[1]) { slab = frMesh(x, "slab.stl"); }\n'
        "opb(x[3], a[1]) { opb = frBall(x, 0.3); }\n"
        "my_model(x[3], a[1]) { my_model = frMinkowski(x, slab, opb); }\n",
        1.5, slab_exact_volume(), scad="minkowski() { import(\"%s\"); sphere(r = 0.3, $fn = FN); }" % slab_stl,
        manifold={"a": {"stl": slab_stl}, "b": {"sphere": 0.3}}, what="non-convex STL, r 0.3")
    for name, (V, T, s) in {"tetra": (TETRA_V, TETRA_T, 0.6), "octa": (OCTA_V, OCTA_T, 0.8)}.items():
        v = scaled(V, s)
        stl = os.path.join(work, name + ".stl")
        write_stl(stl, v, outward(v, T))
        ex = steiner_volume(v, T, 0.25)
        add(name + "_ball",
            "opa(x[3], a[1]) { opa = %s; }\n" % hf_planes(v, T) +
            "opb(x[3], a[1]) { array c[3]; c = [0, 0, 0]; opb = hfSphere(x, c, 0.25); }\n"
            "my_model(x[3], a[1]) { my_model = frMinkowski(x, opa, opb); }\n",
            1.3, ex, scad="minkowski() { %s sphere(r = 0.25, $fn = FN); }" % scad_polyhedron(v, T),
            manifold={"a": {"stl": stl}, "b": {"sphere": 0.25}}, what="convex planes, r 0.25")
        if name == "octa":
            add("octa_stl_ball",
                'opa(x[3], a[1]) { opa = frMesh(x, "octa.stl"); }\n'
                "opb(x[3], a[1]) { array c[3]; c = [0, 0, 0]; opb = hfSphere(x, c, 0.25); }\n"
                "my_model(x[3], a[1]) { my_model = frMinkowski(x, opa, opb); }\n",
                1.3, ex, scad="minkowski() { import(\"%s\"); sphere(r = 0.25, $fn = FN); }" % stl,
                manifold={"a": {"stl": stl}, "b": {"sphere": 0.25}}, what="convex STL, r 0.25")
    if have_npm:
        bv, bt = bunny_mesh(npm_dir)
        bunny = os.path.join(work, "bunny.stl")
        write_stl(bunny, bv, bt)
        tool_v = scaled(TETRA_V, 0.06)
        tool = os.path.join(work, "tool.stl")
        write_stl(tool, tool_v, outward(tool_v, TETRA_T))
        add("bunny_ball",
            'opa(x[3], a[1]) { opa = frMesh(x, "bunny.stl"); }\n'
            "opb(x[3], a[1]) { opb = frBall(x, 0.05); }\n"
            "my_model(x[3], a[1]) { my_model = frMinkowski(x, opa, opb); }\n",
            1.15, None, scad="minkowski() { import(\"%s\"); sphere(r = 0.05, $fn = FN); }" % bunny,
            manifold={"a": {"stl": bunny}, "b": {"sphere": 0.05}}, what="non-convex mesh (%d triangles), r 0.05" % len(bt))
        add("bunny_tetra",
            'opa(x[3], a[1]) { opa = frMesh(x, "bunny.stl"); }\n'
            'opb(x[3], a[1]) { opb = frMesh(x, "tool.stl"); }\n'
            "my_model(x[3], a[1]) { my_model = frMinkowski(x, opa, opb); }\n",
            1.15, "peer", scad="minkowski() { import(\"%s\"); import(\"%s\"); }" % (bunny, tool),
            manifold={"a": {"stl": bunny}, "b": {"stl": tool}}, what="mesh (+) convex mesh")
        ltool_v, ltool_t = l_tool(0.05)
        ltool = os.path.join(work, "ltool.stl")
        write_stl(ltool, ltool_v, ltool_t)
        add("bunny_ltool",
            'opa(x[3], a[1]) { opa = frMesh(x, "bunny.stl"); }\n'
            'opb(x[3], a[1]) { opb = frMesh(x, "ltool.stl"); }\n'
            "my_model(x[3], a[1]) { my_model = frMinkowski(x, opa, opb); }\n",
            1.15, "peer", scad="minkowski() { import(\"%s\"); import(\"%s\"); }" % (bunny, ltool),
            manifold={"a": {"stl": bunny}, "b": {"stl": ltool}}, what="mesh (+) non-convex mesh")
        add("bunny_block",
            'opa(x[3], a[1]) { opa = frMesh(x, "bunny.stl"); }\n'
            "opb(x[3], a[1]) { array v[3]; v = [-0.05, -0.04, -0.03]; opb = hfBlock(x, v, 0.1, 0.08, 0.06); }\n"
            "my_model(x[3], a[1]) { my_model = frMinkowski(x, opa, opb); }\n",
            1.15, "peer", scad="minkowski() { import(\"%s\"); translate([-0.05, -0.04, -0.03]) cube([0.1, 0.08, 0.06]); }" % bunny,
            manifold={"a": {"stl": bunny}, "b": {"cube": [0.1, 0.08, 0.06], "corner": [-0.05, -0.04, -0.03]}},
            what="mesh (+) box")
    t = 0.6
    add("morph_blocks",
        "opa(x[3], a[1]) { array v[3]; v = [-0.1, -0.4, -0.3]; opa = hfBlock(x, v, 0.5, 0.9, 0.4); }\n"
        "opb(x[3], a[1]) { array v[3]; v = [-0.6, -0.1, -0.35]; opb = hfBlock(x, v, 1.0, 0.3, 0.8); }\n"
        "my_model(x[3], a[1]) { my_model = frMorphMinkowski(x, opa, opb, 0.6); }\n",
        0.7, 0.8 * 0.54 * 0.64,
        scad="minkowski() { scale(0.4) translate([-0.1, -0.4, -0.3]) cube([0.5, 0.9, 0.4]); "
             "scale(0.6) translate([-0.6, -0.1, -0.35]) cube([1.0, 0.3, 0.8]); }",
        manifold={"a": {"cube": [0.5, 0.9, 0.4], "corner": [-0.1, -0.4, -0.3], "scale": 1 - t},
                  "b": {"cube": [1.0, 0.3, 0.8], "corner": [-0.6, -0.1, -0.35], "scale": t}}, what="t 0.6")
    return cases


# The per-voxel baseline of each operand form: box (+) ball written with hfBlock / hfSphere, and
# the same box as an STL file (+) frBall.
BASELINES = {"hf": "box_ball", "stl": "box_stl_ball"}


def sphere_radius(case):
    for o in (case["manifold"] or {}).values():
        if "sphere" in o:
            return o["sphere"]
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frep", default=os.path.join(ROOT, "build", "bin", "frep"))
    ap.add_argument("--openscad", default="/usr/bin/openscad")
    ap.add_argument("--res", default="12,16,20,24,32,48,64,72,96,128")
    ap.add_argument("--fn", default="12,24,48", help="peers' sphere segments ($fn), one run each")
    ap.add_argument("--tolerances", default="0.1,0.02,0",
                    help="frep mesh --tolerance values, each at every --res (the first: the per-voxel baseline)")
    ap.add_argument("--ref-res", type=int, default=320, help="bunny (+) ball: frep's reference resolution")
    ap.add_argument("--quick", action="store_true", help="--res 64,128 and no reference run")
    ap.add_argument("--only", default="")
    ap.add_argument("--timeout", type=float, default=300)
    ap.add_argument("--keep", default=None)
    ap.add_argument("--no-peers", action="store_true")
    args = ap.parse_args()
    if not os.path.exists(args.frep):
        print("frep not found (build it, or pass --frep)")
        return 0
    sys.stdout.reconfigure(line_buffering=True)
    work = args.keep or tempfile.mkdtemp(prefix="bench_minkowski_general_")
    os.makedirs(work, exist_ok=True)
    npm_dir, have_npm = ensure_npm(work)
    have_scad = os.path.exists(args.openscad) and not args.no_peers
    have_manifold = have_npm and not args.no_peers
    resolutions = [32, 64] if args.quick else [int(r) for r in args.res.split(",")]
    fns = [12] if args.quick else [int(f) for f in args.fn.split(",")]
    tolerances = [float(t) for t in args.tolerances.split(",")]
    cases = build_cases(work, npm_dir, have_npm)
    if args.only:
        keep = set(args.only.split(","))
        cases = [c for c in cases if c["name"] in keep or c["name"] in BASELINES.values()]
    print("Minkowski sums of any operands: frep mesh (default workers) vs OpenSCAD %s and manifold-3d %s" %
          ("(found)" if have_scad else "(not installed)", "(found)" if have_manifold else "(not installed)"))
    print("%d cores, load average %.2f; work in %s" % (os.cpu_count(), os.getloadavg()[0], work))
    base = {}
    summary = []
    for case in cases:
        name, box = case["name"], case["box"]
        print("\n== %s (%s), box [-%g, %g]^3" % (name, case["what"], box, box))
        frep_runs = []
        for res, tol in [(r, t) for t in tolerances for r in resolutions]:
            # The simplifier's tolerance is the user's accuracy knob: 0.1 voxel by default, 0 keeps
            # the marching tetrahedra's triangles (more of them, a smaller volume error).
            label = "frep --res %d" % res + ("" if tol == tolerances[0] else " --tolerance %g" % tol)
            stl = os.path.join(work, "%s_frep_%d_%g.stl" % (name, res, tol))
            p, dt, err = timed([args.frep, "mesh", case["hf"], "-o", "my_model", "-b", "%g" % box, "--res", str(res),
                                "--tolerance", "%g" % tol, "-O", stl, "--no-progress"], args.timeout)
            if p is None:
                print("  %s failed: %s" % (label, err.strip()))
                continue
            tris = read_stl(stl)
            report = open(stl + ".report.json", "rb").read()
            path = "search" if b"searches\": 0" not in report else "exact"
            where = "in-process" if b"\"in_process_rule\": \"" in report else "farm"
            frep_runs.append(dict(res=res, tol=tol, label=label, wall=dt, tris=len(tris), vol=volume(tris),
                                  open=unpaired_edges(tris), path=path, where=where))
        peers = []
        r = sphere_radius(case)
        for fn in (fns if r else [0]):
            if have_scad and case["scad"]:
                scad = os.path.join(work, "%s_%d.scad" % (name, fn))
                with open(scad, "w") as f:
                    f.write(case["scad"].replace("FN", str(fn)))
                out = os.path.join(work, "%s_openscad_%d.stl" % (name, fn))
                p, dt, err = timed([args.openscad, "-o", out, scad], args.timeout)
                if p is None:
                    print("  OpenSCAD%s failed: %s" % (" $fn %d" % fn if r else "", err.strip()[-200:]))
                else:
                    tris = read_stl(out)
                    peers.append(dict(who="OpenSCAD" + (" $fn %d" % fn if r else ""), wall=dt, op=None, tris=len(tris), vol=volume(tris)))
            if have_manifold and case["manifold"]:
                job = json.loads(json.dumps(case["manifold"]))
                for o in job.values():
                    if "sphere" in o:
                        o["segments"] = fn
                p, dt, err = timed(["node", os.path.join(npm_dir, "manifold_minkowski.mjs"), json.dumps(job)], args.timeout)
                if p is None:
                    print("  manifold-3d failed: %s" % err.strip()[-200:])
                else:
                    res = json.loads(p.stdout.decode().strip().splitlines()[-1])
                    peers.append(dict(who="manifold-3d" + (" %d segments" % fn if r else ""), wall=dt, op=res["seconds"],
                                      tris=res["triangles"], vol=res["volume"]))
        exact, ref_note = case["exact"], "closed form"
        if exact == "peer":
            exacts = [pp["vol"] for pp in peers if pp["who"].startswith("manifold")] or [pp["vol"] for pp in peers]
            exact, ref_note = (exacts[-1], "the peers' exact polyhedral sum") if exacts else (None, "")
        if exact is None and not args.quick:
            stl = os.path.join(work, "%s_ref.stl" % name)
            p, dt, err = timed([args.frep, "mesh", case["hf"], "-o", "my_model", "-b", "%g" % box, "--res", str(args.ref_res),
                                "-O", stl, "--no-progress"], 4 * args.timeout)
            if p is not None:
                exact, ref_note = volume(read_stl(stl)), "frep --res %d (%.1f s)" % (args.ref_res, dt)
        print("  reference volume %s (%s)" % ("%.6f" % exact if exact else "none", ref_note))
        print("  %-30s %8s %9s %10s %10s %6s" % ("system", "wall s", "op s", "triangles", "vol err", "open"))

        def err_of(v):
            return (v - exact) / exact if exact else float("nan")
        for fr in frep_runs:
            print("  %-30s %8.3f %9s %10d %+9.4f%% %6d  (%s path, %s)" % (fr["label"], fr["wall"], "", fr["tris"],
                                                                        100 * err_of(fr["vol"]), fr["open"], fr["path"], fr["where"]))
            if name in BASELINES.values() and fr["tol"] == tolerances[0]:
                base[(case["form"], fr["res"])] = fr["wall"]
        for pp in peers:
            print("  %-30s %8.3f %9s %10d %+9.4f%%" % (pp["who"], pp["wall"], "%.2f" % pp["op"] if pp["op"] is not None else "",
                                                        pp["tris"], 100 * err_of(pp["vol"])))
        for fr in frep_runs:
            key = (case["form"], fr["res"])
            if key in base and name not in BASELINES.values() and fr["tol"] == tolerances[0]:
                print("  per-voxel time at --res %d: %.2fx %s's (the box (+) ball of the same form)" %
                      (fr["res"], fr["wall"] / base[key], BASELINES[case["form"]]))
        for pp in peers:
            if not exact:
                continue
            e = abs(err_of(pp["vol"]))
            # Both write float32 vertices (STL): a relative volume error below 1e-6 is the file's
            # rounding, so an exact peer is matched by any frep run within that.
            match = [fr for fr in frep_runs if abs(err_of(fr["vol"])) <= max(e, 1e-6)]
            if match:
                fr = min(match, key=lambda x: x["wall"])
                line = "  equal accuracy vs %s (%.4f%%, %d triangles): %s (%.4f%%, %d) %.3f s; %s / frep = %.2fx" % (
                    pp["who"], 100 * e, pp["tris"], fr["label"], 100 * abs(err_of(fr["vol"])), fr["tris"], fr["wall"],
                    pp["who"].split()[0], pp["wall"] / fr["wall"])
            else:
                best = min(frep_runs, key=lambda x: abs(err_of(x["vol"]))) if frep_runs else None
                line = "  %s is exact here (%.4f%%): frep's closest %s (%.4f%%) %s s vs %.3f s" % (
                    pp["who"], 100 * e, best["label"] if best else "-", 100 * abs(err_of(best["vol"])) if best else 0,
                    "%.3f" % best["wall"] if best else "-", pp["wall"])
            print(line)
            summary.append((name, line.strip()))
    print("\nsummary (equal accuracy)")
    for name, line in summary:
        print("  %-14s %s" % (name, line))
    if args.keep is None:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
