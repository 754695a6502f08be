#!/usr/bin/env python3
"""Exact comparison of two .vdb files by OpenVDB itself (python3-openvdb): the same grids (name,
class, transform, background, file and grid metadata except the --ignore'd keys) and the same
tree: every tile and voxel with its value and active state, in iteration order.

usage: same_vdb.py A.vdb B.vdb [--ignore KEY ...]      exit 0 same, 1 different
"""
import sys

import pyopenvdb as vdb


def describe(path, ignore):
    grids, file_meta = vdb.readAll(path)
    out = {"file": {k: v for k, v in file_meta.items() if k not in ignore}, "grids": []}
    for g in grids:
        t = g.transform
        out["grids"].append({
            "name": g.name, "class": g.gridClass, "background": g.background,
            "voxel": t.voxelSize(), "origin": t.indexToWorld((0, 0, 0)),
            "meta": {k: v for k, v in g.metadata.items() if k not in ignore},
            "tree": [(v["min"], v["max"], v["value"], v["active"]) for v in g.citerAllValues()],
        })
    return out


def main():
    args = sys.argv[1:]
    ignore = set()
    while "--ignore" in args:
        i = args.index("--ignore")
        ignore.add(args[i + 1])
        del args[i:i + 2]
    a, b = describe(args[0], ignore), describe(args[1], ignore)
    if a == b:
        n = sum(len(g["tree"]) for g in a["grids"])
        print(f"{args[1]}: same grids as {args[0]} ({n} tiles and voxels; ignored: {sorted(ignore) or 'none'})")
        return 0
    for ga, gb in zip(a["grids"], b["grids"]):
        for k in ga:
            if ga[k] != gb[k]:
                print(f"grid {ga['name']}: {k} differs")
    if a["file"] != b["file"] or len(a["grids"]) != len(b["grids"]):
        print("file metadata or grid count differs")
    return 1


if __name__ == "__main__":
    sys.exit(main())
