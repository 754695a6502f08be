#!/usr/bin/python3
"""Reads a mesh file written by frep mesh with readers independent of frep's writers (the Python
standard library, numpy-stl for STL) and prints JSON: positions, normals (where the format has
them), triangles, colours (0..1, where present) and whether every edge is shared by exactly two
triangles in opposite directions (closed and consistently oriented). Also reads CLI slices.
Usage: read_mesh.py FILE [FORMAT] [--text]
--text: 'vertices N', 'triangles M', 'closed_oriented 0|1', 'normals 0|1', 'colours 0|1', then
one line per vertex: x y z [nx ny nz] [r g b]; for CLI: 'layers N', then per layer
'layer Z K' and per polyline 'polyline DIR N AREA' (signed shoelace area)."""
import json
import re
import struct
import sys
import zipfile
import xml.etree.ElementTree as ET


def ply(path):
    data = open(path, 'rb').read()
    end = data.index(b'end_header\n') + len(b'end_header\n')
    header = data[:end].decode().splitlines()
    nv = int(next(l for l in header if l.startswith('element vertex')).split()[2])
    nf = int(next(l for l in header if l.startswith('element face')).split()[2])
    coloured = 'property uchar red' in header
    fmt = '<6f3B' if coloured else '<6f'
    size = struct.calcsize(fmt)
    P, N, C, T = [], [], [], []
    at = end
    for _ in range(nv):
        v = struct.unpack_from(fmt, data, at)
        at += size
        P.append(v[0:3]); N.append(v[3:6])
        if coloured:
            C.append([c / 255 for c in v[6:9]])
    for _ in range(nf):
        n = data[at]
        T.append(list(struct.unpack_from('<3I', data, at + 1)))
        assert n == 3
        at += 13
    return P, N, T, C


def obj(path):
    P, N, T, C = [], [], [], []
    for line in open(path):
        w = line.split()
        if not w:
            continue
        if w[0] == 'v':
            P.append([float(x) for x in w[1:4]])
            if len(w) >= 7:
                C.append([float(x) for x in w[4:7]])
        elif w[0] == 'vn':
            N.append([float(x) for x in w[1:4]])
        elif w[0] == 'f':
            T.append([int(x.split('/')[0]) - 1 for x in w[1:4]])
    return P, N, T, C


def stl(path):
    from stl import mesh as stlmesh  # numpy-stl (python3-stl)
    m = stlmesh.Mesh.from_file(path)
    index, P, T = {}, [], []
    for tri in m.vectors:
        t = []
        for v in tri:
            key = tuple(float(c) for c in v)
            if key not in index:
                index[key] = len(P)
                P.append(list(key))
            t.append(index[key])
        T.append(t)
    return P, [], T, []


def numbers(text):
    return [float(x) for x in re.findall(r'[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?', text)]


def block(text, start):
    i = text.index(start)
    j = text.index('[', i)
    k = text.index(']', j)
    return text[j + 1:k]


def wrl(path):
    text = open(path).read()
    assert text.startswith('#VRML V2.0 utf8')
    p = numbers(block(text, 'point ['))
    n = numbers(block(text, 'vector ['))
    idx = [int(x) for x in numbers(block(text, 'coordIndex ['))]
    c = numbers(block(text, 'color [')) if 'color Color' in text else []
    T, cur = [], []
    for i in idx:
        if i == -1:
            T.append(cur); cur = []
        else:
            cur.append(i)
    g = lambda v: [v[i:i + 3] for i in range(0, len(v), 3)]
    return g(p), g(n), T, g(c)


def pov(path):
    text = open(path).read()
    def section(name):
        i = text.index(name)
        j = text.index('{', i)
        depth, k = 0, j
        while True:
            depth += {'{': 1, '}': -1}.get(text[k], 0)
            if depth == 0:
                return text[j + 1:k]
            k += 1
    vec = lambda s: [[float(x) for x in m.split(',')] for m in re.findall(r'<([^>]*)>', s)]
    P = vec(section('vertex_vectors'))
    N = vec(section('normal_vectors'))
    C = vec(section('texture_list')) if 'texture_list' in text else []
    T = [[int(x) for x in t[:3]] for t in vec(section('face_indices'))]
    return P, N, T, C


def threemf(path):
    z = zipfile.ZipFile(path)
    root = ET.fromstring(z.read('3D/3dmodel.model'))
    ns = {'c': 'http://schemas.microsoft.com/3dmanufacturing/core/2015/02',
          'm': 'http://schemas.microsoft.com/3dmanufacturing/material/2015/02'}
    P = [[float(v.get(a)) for a in 'xyz'] for v in root.iter('{%s}vertex' % ns['c'])]
    group = [g for g in root.iter('{%s}colorgroup' % ns['m'])]
    palette = []
    if group:
        for c in group[0].iter('{%s}color' % ns['m']):
            h = c.get('color')
            palette.append([int(h[i:i + 2], 16) / 255 for i in (1, 3, 5)])
    T, C = [], [None] * len(P)
    for t in root.iter('{%s}triangle' % ns['c']):
        v = [int(t.get(a)) for a in ('v1', 'v2', 'v3')]
        T.append(v)
        if t.get('p1') is not None and palette:
            for vi, pa in zip(v, ('p1', 'p2', 'p3')):
                col = palette[int(t.get(pa))]
                assert C[vi] is None or C[vi] == col, 'a vertex has two colours'
                C[vi] = col
    return P, [], T, C if palette else []


def glb(path):
    data = open(path, 'rb').read()
    magic, version, length = struct.unpack_from('<4sII', data, 0)
    assert magic == b'glTF' and version == 2 and length == len(data)
    jlen, jtype = struct.unpack_from('<I4s', data, 12)
    assert jtype == b'JSON'
    gltf = json.loads(data[20:20 + jlen])
    blen, btype = struct.unpack_from('<I4s', data, 20 + jlen)
    assert btype == b'BIN\x00'
    bin_ = data[28 + jlen:28 + jlen + blen]
    def accessor(i):
        a = gltf['accessors'][i]
        v = gltf['bufferViews'][a['bufferView']]
        off = v.get('byteOffset', 0) + a.get('byteOffset', 0)
        comps = {'SCALAR': 1, 'VEC3': 3}[a['type']]
        code = {5126: 'f', 5125: 'I'}[a['componentType']]
        flat = struct.unpack_from('<%d%s' % (a['count'] * comps, code), bin_, off)
        return [list(flat[k:k + comps]) for k in range(0, len(flat), comps)] if comps > 1 else list(flat)
    prim = gltf['meshes'][0]['primitives'][0]
    P = accessor(prim['attributes']['POSITION'])
    N = accessor(prim['attributes']['NORMAL'])
    C = accessor(prim['attributes']['COLOR_0']) if 'COLOR_0' in prim['attributes'] else []
    idx = accessor(prim['indices'])
    T = [idx[k:k + 3] for k in range(0, len(idx), 3)]
    return P, N, T, C


def cli(path):
    data = open(path, 'rb').read()
    end = data.index(b'$$HEADEREND') + len(b'$$HEADEREND')
    header = data[:end].decode()
    layers = []
    if '$$BINARY' in header:
        at = end
        while at < len(data):
            (cmd,) = struct.unpack_from('<H', data, at); at += 2
            if cmd == 127:
                (z,) = struct.unpack_from('<f', data, at); at += 4
                layers.append({'z': z, 'polylines': []})
            elif cmd == 130:
                pid, direction, n = struct.unpack_from('<iii', data, at); at += 12
                pts = struct.unpack_from('<%df' % (2 * n), data, at); at += 8 * n
                layers[-1]['polylines'].append({'dir': direction, 'points': [pts[k:k + 2] for k in range(0, 2 * n, 2)]})
            else:
                raise ValueError('unknown CLI command %d' % cmd)
    else:
        for line in data[end:].decode().splitlines():
            if line.startswith('$$LAYER/'):
                layers.append({'z': float(line[8:]), 'polylines': []})
            elif line.startswith('$$POLYLINE/'):
                v = line[11:].split(',')
                n = int(v[2])
                pts = [float(x) for x in v[3:]]
                assert len(pts) == 2 * n
                layers[-1]['polylines'].append({'dir': int(v[1]), 'points': [pts[k:k + 2] for k in range(0, 2 * n, 2)]})
    units = re.search(r'\$\$UNITS/([^\n]*)', header).group(1)
    count = int(re.search(r'\$\$LAYERS/(\d+)', header).group(1))
    return {'units': float(units), 'declared_layers': count, 'layers': layers, 'binary': '$$BINARY' in header}


def oriented_closed(T):
    directed = {}
    for t in T:
        for k in range(3):
            e = (t[k], t[(k + 1) % 3])
            directed[e] = directed.get(e, 0) + 1
    return all(c == 1 and directed.get((b, a), 0) == 1 for (a, b), c in directed.items())


def area(points):
    return 0.5 * sum(points[i][0] * points[i + 1][1] - points[i + 1][0] * points[i][1] for i in range(len(points) - 1))


def main():
    args = [a for a in sys.argv[1:] if a != '--text']
    text = '--text' in sys.argv
    path = args[0]
    fmt = args[1] if len(args) > 1 else path.rsplit('.', 1)[-1].lower()
    if fmt == 'cli':
        d = cli(path)
        if not text:
            print(json.dumps(d))
            return
        print('layers', len(d['layers']), d['declared_layers'])
        for layer in d['layers']:
            print('layer %.9g %d' % (layer['z'], len(layer['polylines'])))
            for pl in layer['polylines']:
                closed = pl['points'][0] == pl['points'][-1]
                print('polyline %d %d %.12g %d' % (pl['dir'], len(pl['points']), area(pl['points']), closed))
        return
    reader = {'ply': ply, 'obj': obj, 'stl': stl, 'wrl': wrl, 'pov': pov, 'inc': pov, '3mf': threemf, 'glb': glb}[fmt]
    P, N, T, C = reader(path)
    if text:
        print('vertices', len(P))
        print('triangles', len(T))
        print('closed_oriented', int(oriented_closed(T)))
        print('normals', int(len(N) == len(P) and len(P) > 0))
        print('colours', int(len(C) == len(P) and len(P) > 0))
        for i, p in enumerate(P):
            row = list(p) + (list(N[i]) if len(N) == len(P) else []) + (list(C[i]) if len(C) == len(P) else [])
            print(' '.join('%.9g' % v for v in row))
        return
    print(json.dumps({'positions': P, 'normals': N, 'triangles': T, 'colours': C,
                      'closed_oriented': oriented_closed(T)}))


if __name__ == '__main__':
    main()
