#!/usr/bin/env python3
"""Renders a binary PLY written by `frep mesh` (float x y z nx ny nz, uchar/uint faces) to a PNG
with POV-Ray (Debian package povray), for previews in the README and docs.

    docs/tools/render_ply.py part.ply part.png [--width 640] [--elevation 25] [--azimuth 35]
                             [--flat] [--edges]

--flat ignores the vertex normals (faceted shading: sharp edges look sharp); --edges draws every
triangle's edges (to show an adaptive mesh's triangles).
"""
import argparse
import math
import os
import struct
import subprocess
import tempfile


def read_ply(path):
    with open(path, "rb") as f:
        header, counts = [], {}
        while True:
            line = f.readline().decode("ascii").strip()
            header.append(line)
            if line.startswith("element"):
                _, name, n = line.split()
                counts[name] = int(n)
            if line == "end_header":
                break
        nv, nf = counts["vertex"], counts["face"]
        data = f.read(nv * 24)
        verts = [struct.unpack_from("<6f", data, 24 * i) for i in range(nv)]
        faces = []
        for _ in range(nf):
            (k,) = struct.unpack("<B", f.read(1))
            faces.append(struct.unpack("<%dI" % k, f.read(4 * k)))
    return verts, faces


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("ply")
    ap.add_argument("png")
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--elevation", type=float, default=25.0)
    ap.add_argument("--azimuth", type=float, default=35.0)
    ap.add_argument("--flat", action="store_true")
    ap.add_argument("--edges", action="store_true")
    a = ap.parse_args()
    verts, faces = read_ply(a.ply)
    lo = [min(v[i] for v in verts) for i in range(3)]
    hi = [max(v[i] for v in verts) for i in range(3)]
    centre = [(l + h) / 2 for l, h in zip(lo, hi)]
    radius = max(h - l for l, h in zip(lo, hi))
    el, az = math.radians(a.elevation), math.radians(a.azimuth)
    # z is up in frepfarm models; POV-Ray's y is up: swap y and z.
    def pov(p):
        return "<%.6f,%.6f,%.6f>" % (p[0], p[2], p[1])
    eye = [centre[0] + 3.0 * radius * math.cos(el) * math.cos(az),
           centre[1] + 3.0 * radius * math.cos(el) * math.sin(az),
           centre[2] + 3.0 * radius * math.sin(el)]
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "scene.pov")
        with open(scene, "w") as s:
            s.write('#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\nbackground { rgb <1,1,1> }\n')
            s.write("camera { location %s look_at %s angle 35 }\n" % (pov(eye), pov(centre)))
            s.write("light_source { %s rgb 1.0 }\n" % pov([eye[0] + radius, eye[1] - radius, eye[2] + 2 * radius]))
            s.write("light_source { %s rgb 0.35 shadowless }\n" % pov([centre[0] - 3 * radius, centre[1] + radius, centre[2]]))
            s.write("mesh2 {\n vertex_vectors { %d,\n" % len(verts))
            s.write(",\n".join(pov(v[:3]) for v in verts))
            if not a.flat:
                s.write("}\n normal_vectors { %d,\n" % len(verts))
                s.write(",\n".join(pov(v[3:]) for v in verts))
            s.write("}\n face_indices { %d,\n" % len(faces))
            s.write(",\n".join("<%d,%d,%d>" % tuple(f[:3]) for f in faces))
            s.write("}\n texture { pigment { rgb <0.93,0.55,0.25> } finish { phong 0.4 diffuse 0.75 ambient 0.12 } }\n}\n")
            if a.edges:
                edges = {tuple(sorted((f[i], f[(i + 1) % 3]))) for f in faces for i in range(3)}
                r = radius * 0.0015
                s.write("union {\n")
                for i, j in sorted(edges):
                    s.write(" cylinder { %s, %s, %.6f }\n" % (pov(verts[i][:3]), pov(verts[j][:3]), r))
                s.write(" pigment { rgb <0.25,0.12,0.05> }\n}\n")
        height = int(a.width * 0.75)
        subprocess.run(["povray", "-D", "+A", "+W%d" % a.width, "+H%d" % height, "+I" + scene, "+O" + a.png],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


if __name__ == "__main__":
    main()
