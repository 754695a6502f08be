#!/usr/bin/python3
"""Geometry acceptance suite: closed-form solids meshed by `frep mesh`, checked against their
exact volumes and signed distances (cases.py; models in models/).

Usage: run_suite.py FREP_BINARY [--quick] [--slow] [--only NAME[,NAME...]] [--jobs N]
                    [--keep DIR] [--eval-check N]

For every case and grid (--res), `frep mesh MODEL -o NAME -b BOUNDS --res N -O out.ply
--no-progress` runs twice, with --workers 2 and --workers 0; then:
  - exit code 0; no warning on stdout or stderr, except the expected "the solid is cut by the
    box's face(s) ...: the mesh is capped" on a cut case, naming exactly its faces (elsewhere, or
    naming other faces, it fails); "N extremum searches stopped at their box limit" is printed as
    a note; any other warning fails;
  - the two PLY files are byte-identical;
  - the PLY (binary, header parsed generically) is watertight and consistently oriented:
    every directed edge once and its reverse once; no degenerate (zero-area) triangle;
    positive signed volume; the report's cut_faces are the case's;
  - volume error against the closed form <= 0.5 % at the 128 grid (--res 128 or 129), and
    |error| at the finest grid <= |error| at the coarsest + a slack: the volume of a shell 2e-3
    voxel thick over the finest mesh, at least 0.01 percentage points (flat-faced solids can mesh
    exactly at a coarse grid, and the mesher keeps vertices 1e-3 of an edge off grid points);
  - max |exact signed distance| over the vertices and 10 barycentric points per triangle <= the
    report's `surface_error_bound` (out.ply.report.json; a missing key is a failure).
For a solid cut by the box the exact surface is that of solid n box, capped on the box's faces;
an open mesh's volume is judged with its boundary loops capped on the box faces ("capped").

Cases marked slow in cases.py (Minkowski morphs and radius offsets at the default search gap,
...) are left out unless --slow is given or --only names them; a few cases run on grids below
128 only (their families are too slow at 128 for the 5-minute budget) and get no 0.5 % check.
Independent cases run --jobs (2) at a time, the most expensive first.

Prints one table per case and a summary; exits 1 if any check fails (naming case, grid, check).
--quick: the grids below 100 only (no 0.5 % check). --keep DIR: keep the meshes and reports.
--eval-check N: instead of meshing, compare `frep eval` at N random points and N points 0.004
either side of the surface per case with the closed form (the sign everywhere; |f + sdf| is
printed, 0 where the model's field is an exact distance) - a check of the models themselves.
"""
import argparse
import concurrent.futures as cf
import fnmatch
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.dont_write_bytecode = True  # no __pycache__ in the source tree
import cases as C  # noqa: E402

MODELS = os.path.join(HERE, 'models')
VOLUME_TOL = 0.5  # percent, at the 128 grid
SLACK = 0.01  # percentage points: |error| at the finest grid <= |error| at the coarsest + SLACK
FLOOR = 0.1  # percentage points: an error below it at the finest grid always passes that check
GUARD = 2e-3  # voxels: or + the volume of a shell this thick over the finest mesh, if larger
BARY = np.array([[1 / 3, 1 / 3, 1 / 3],
                 [2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3],
                 [1 / 6, 5 / 12, 5 / 12], [5 / 12, 1 / 6, 5 / 12], [5 / 12, 5 / 12, 1 / 6],
                 [1 / 2, 1 / 2, 0], [0, 1 / 2, 1 / 2], [1 / 2, 0, 1 / 2]])

# ------------------------------------------------------------------------------------------------
# PLY


PLY_TYPES = {'char': 'i1', 'int8': 'i1', 'uchar': 'u1', 'uint8': 'u1', 'short': 'i2', 'int16': 'i2',
             'ushort': 'u2', 'uint16': 'u2', 'int': 'i4', 'int32': 'i4', 'uint': 'u4', 'uint32': 'u4',
             'float': 'f4', 'float32': 'f4', 'double': 'f8', 'float64': 'f8'}


def read_ply(path):
    """Binary little-endian PLY: returns positions (n, 3) float64 and triangles (m, 3) int64.
    The header is parsed generically (any element order, any scalar properties; faces as a list
    property); only triangles are accepted."""
    data = open(path, 'rb').read()
    end = data.index(b'end_header\n') + len(b'end_header\n')
    lines = data[:end].decode('latin-1').splitlines()
    if lines[0] != 'ply':
        raise ValueError('not a PLY file')
    fmt = None
    elements = []  # (name, count, [(prop, type) | (prop, ('list', ctype, itype))])
    for l in lines[1:]:
        w = l.split()
        if not w or w[0] in ('comment', 'obj_info', 'end_header'):
            continue
        if w[0] == 'format':
            fmt = w[1]
        elif w[0] == 'element':
            elements.append((w[1], int(w[2]), []))
        elif w[0] == 'property':
            if w[1] == 'list':
                elements[-1][2].append((w[4], ('list', PLY_TYPES[w[2]], PLY_TYPES[w[3]])))
            else:
                elements[-1][2].append((w[2], PLY_TYPES[w[1]]))
    if fmt != 'binary_little_endian':
        raise ValueError('PLY format %s, expected binary_little_endian' % fmt)
    at = end
    P = T = None
    for name, count, props in elements:
        if all(not isinstance(t, tuple) for _, t in props):
            dt = np.dtype([(p, '<' + t) for p, t in props])
            arr = np.frombuffer(data, dtype=dt, count=count, offset=at)
            at += dt.itemsize * count
            if name == 'vertex':
                P = np.stack([arr['x'], arr['y'], arr['z']], axis=1).astype(np.float64)
            continue
        # one list property (faces), possibly with scalars: fixed size if every list has 3 entries
        if len(props) == 1 and isinstance(props[0][1], tuple):
            _, (_, ct, it) = props[0]
            dt = np.dtype([('n', '<' + ct), ('i', '<' + it, (3,))])
            arr = np.frombuffer(data, dtype=dt, count=count, offset=at) if count else np.zeros(0, dt)
            if count and not np.all(arr['n'] == 3):
                raise ValueError('non-triangle faces')
            at += dt.itemsize * count
            if name == 'face':
                T = arr['i'].astype(np.int64)
            continue
        raise ValueError('unsupported PLY element layout: %s' % name)
    if at != len(data):
        raise ValueError('PLY has %d trailing bytes' % (len(data) - at))
    if P is None or T is None:
        raise ValueError('PLY without vertex or face element')
    return P, T


# ------------------------------------------------------------------------------------------------
# Mesh checks


def edge_check(T, nv):
    """Directed edges: each must appear once and its reverse once. Returns (directed duplicates,
    directed edges without their reverse, boundary edges (a, b) as an array)."""
    E = np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]])
    key = E[:, 0] * nv + E[:, 1]
    uk, cnt = np.unique(key, return_counts=True)
    dup = int((cnt > 1).sum())
    rev = E[:, 1] * nv + E[:, 0]
    pos = np.clip(np.searchsorted(uk, rev), 0, len(uk) - 1)
    missing = uk[pos] != rev if len(uk) else np.zeros(len(rev), bool)
    return dup, int(missing.sum()), E[missing]


def signed_volume(P, T, origin):
    a, b, c = P[T[:, 0]] - origin, P[T[:, 1]] - origin, P[T[:, 2]] - origin
    return float(np.einsum('ij,ij->i', a, np.cross(b, c)).sum() / 6.0)


def capped_volume(P, T, boundary, glo, ghi, origin):
    """Volume with each boundary loop closed by a fan in the box face it lies on (the missing cap
    triangles (b, a, c) for every open directed edge a -> b, c the face's centre)."""
    vol = signed_volume(P, T, origin)
    if len(boundary) == 0:
        return vol
    A, B = P[boundary[:, 0]], P[boundary[:, 1]]
    scale = float(np.max(ghi - glo))
    centre = (glo + ghi) / 2
    apex = np.tile(A.mean(axis=0), (len(A), 1))
    for axis in range(3):
        for val in (glo[axis], ghi[axis]):
            on = (np.abs(A[:, axis] - val) < 1e-6 * scale) & (np.abs(B[:, axis] - val) < 1e-6 * scale)
            c = centre.copy()
            c[axis] = val
            apex[on] = c
    a, b, c = B - origin, A - origin, apex - origin
    return vol + float(np.einsum('ij,ij->i', a, np.cross(b, c)).sum() / 6.0)


def grid_box(bounds, res):
    """frep mesh's grid (GridSpec::fromBounds): origin lo, voxel = longest / (res - 1), the points
    that fit in the box."""
    lo, hi = np.array(bounds[:3], float), np.array(bounds[3:], float)
    voxel = float(np.max(hi - lo)) / (res - 1)
    dims = np.floor((hi - lo) / voxel + 1e-9) + 1
    return lo, lo + (dims - 1) * voxel, voxel


def sample_points(P, T):
    V = P[T]  # (m, 3, 3)
    S = np.einsum('kj,mjd->mkd', BARY, V).reshape(-1, 3)
    return np.concatenate([P, S])


# ------------------------------------------------------------------------------------------------
# Running frep


RUN_TIMEOUT = 600  # seconds for one frep run


def run_frep(frep, case, res, workers, out):
    cmd = [frep, 'mesh', os.path.join(MODELS, case.file), '-o', case.name,
           '-b', ','.join(repr(float(v)) for v in case.bounds), '--res', str(res), '-O', out,
           '--no-progress', '--workers', str(workers)]
    for attempt in range(6):
        t0 = time.time()
        try:
            p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               timeout=RUN_TIMEOUT)
        except subprocess.TimeoutExpired:
            return 'timeout', 'frep timed out after %d s' % RUN_TIMEOUT, time.time() - t0, cmd
        except OSError as e:  # the binary being rebuilt under us (text file busy, missing)
            text = 'cannot run %s: %s' % (frep, e)
            time.sleep(60)
            continue
        dt = time.time() - t0
        text = p.stdout + p.stderr
        # frep-worker being rebuilt (local workers cannot start), or a shell's exec failure
        rebuilt = (p.returncode == 7 and 'worker' in text) or p.returncode in (126, 127) or 'Text file busy' in text
        if rebuilt and attempt < 5:
            time.sleep(60)
            continue
        return p.returncode, text, dt, cmd
    return 'not run', text, 0.0, cmd


def classify_warnings(text, case):
    """frep's warnings, each ('fail' | 'note', line). The cut warning ("the solid is cut by the
    box's face(s) F: the mesh is capped there") is expected on a cut case naming exactly its faces,
    a failure anywhere else; a warning about open edges or an open mesh is a failure; a search
    that stopped before its tolerance is a note (also in the report); anything else fails."""
    out = []
    for l in text.splitlines():
        if 'warn' not in l.lower():
            continue
        l = l.strip()
        m = re.search(r"cut by the box's faces? (.*?): the mesh is capped", l)
        if m:
            faces = tuple(f.strip() for f in m.group(1).split(','))
            if case.cut and sorted(faces) == sorted(case.cut_faces):
                continue
            out.append(('fail', l + ' [expected: %s]' % (', '.join(case.cut_faces) or 'no cut face')))
        elif re.search(r'\bopen\b|open edge|not closed|not watertight', l, re.I):
            out.append(('fail', l))
        elif 'extremum searches stopped' in l:
            out.append(('note', l))
        else:
            out.append(('fail', l))
    return out


def check_grid(frep, case, res, tmp):
    """Runs one grid (both worker settings) and checks it. Returns a row dict."""
    row = {'grid': res, 'fail': []}
    out2 = os.path.join(tmp, '%s_%d_w2.ply' % (case.name, res))
    out0 = os.path.join(tmp, '%s_%d_w0.ply' % (case.name, res))
    rc2, text2, t2, cmd2 = run_frep(frep, case, res, 2, out2)
    rc0, text0, t0, _ = run_frep(frep, case, res, 0, out0)
    row['cmd'] = ' '.join(cmd2)
    row['s2'], row['s0'] = t2, t0
    row['notes'] = []
    for rc, text, w in ((rc2, text2, 2), (rc0, text0, 0)):
        if rc != 0:
            msg = ' | '.join(l for l in text.splitlines() if 'error' in l.lower() or 'timed out' in l)[:300]
            row['fail'].append('exit %s with --workers %d: %s' % (rc, w, msg))
        for kind, line in classify_warnings(text, case):
            if kind == 'fail':
                row['fail'].append('warning with --workers %d: %s' % (w, line[:240]))
            elif w == 2:
                row['notes'].append(line[:240])
    if rc2 != 0 or not os.path.exists(out2):
        return row
    if os.path.exists(out0) and open(out2, 'rb').read() != open(out0, 'rb').read():
        row['fail'].append('PLY bytes differ between --workers 2 and --workers 0')
    try:
        P, T = read_ply(out2)
    except Exception as e:  # noqa: BLE001
        row['fail'].append('unreadable PLY: %s' % e)
        return row
    glo, ghi, voxel = grid_box(case.bounds, res)
    row['voxel'] = voxel
    row['tris'] = len(T)
    if case.bbox is not None and not case.cut:
        lo, hi = np.array(case.bbox[0]), np.array(case.bbox[1])
        if np.any(lo < glo + voxel) or np.any(hi > ghi - voxel):
            row['fail'].append('suite error: the solid is not a voxel inside the grid box')
    if len(T) == 0:
        row['fail'].append('empty mesh')
        return row
    dup, missing, boundary = edge_check(T, len(P))
    row['open'] = missing
    row['dup'] = dup
    row['watertight'] = dup == 0 and missing == 0
    if not row['watertight']:
        row['fail'].append('not watertight: %d directed edges without their reverse (open), %d repeated' %
                           (missing, dup))
    V = P[T]
    area = 0.5 * np.linalg.norm(np.cross(V[:, 1] - V[:, 0], V[:, 2] - V[:, 0]), axis=1)
    repeated = (T[:, 0] == T[:, 1]) | (T[:, 1] == T[:, 2]) | (T[:, 0] == T[:, 2])
    degenerate = int((repeated | (area <= 1e-12 * voxel * voxel)).sum())
    row['min_area_vox'] = float(area.min() / voxel ** 2)
    row['area'] = float(area.sum())
    if degenerate:
        row['fail'].append('%d degenerate triangles (zero area; smallest %.3g voxel^2)' %
                           (degenerate, row['min_area_vox']))
    origin = (glo + ghi) / 2
    vol = signed_volume(P, T, origin)
    row['volume'] = vol
    if missing and not dup:
        row['capped'] = capped_volume(P, T, boundary, glo, ghi, origin)
        row['err_capped'] = 100.0 * (row['capped'] - case.volume) / case.volume
    row['err'] = 100.0 * (vol - case.volume) / case.volume
    if vol <= 0:
        row['fail'].append('signed volume %.6g is not positive' % vol)
    S = sample_points(P, T)
    d = np.abs(case.sdf(S))
    i = int(np.argmax(d))
    row['dev'] = float(d[i])
    row['dev_at'] = S[i]
    try:
        rep = json.load(open(out2 + '.report.json'))
    except Exception as e:  # noqa: BLE001
        rep = {}
        row['fail'].append('no report: %s' % e)
    row['simp_bound'] = rep.get('output', {}).get('simplification', {}).get('error_bound')
    faces = tuple(rep.get('output', {}).get('cut_faces', []) or ())
    if sorted(faces) != sorted(case.cut_faces):
        row['fail'].append("report's cut_faces %s, expected %s" % (list(faces), list(case.cut_faces)))
    ext = rep.get('extremum', {})
    if ext.get('uncertified'):
        row['notes'].append('report: %d uncertified extremum searches, widest gap %s' %
                            (ext['uncertified'], ext.get('widest_uncertified_gap')))
    bound = rep.get('surface_error_bound')
    row['bound'] = bound
    if bound is None:
        row['fail'].append("report has no 'surface_error_bound' (max deviation %.3g = %.3f voxel)" %
                           (row['dev'], row['dev'] / voxel))
    elif not (row['dev'] <= bound):
        row['fail'].append('max deviation %.4g (%.3f voxel) > surface_error_bound %.4g at (%.4f, %.4f, %.4f)' %
                           ((row['dev'], row['dev'] / voxel, bound) + tuple(row['dev_at'])))
    return row


def run_case(frep, name, grids, keep):
    case = C.BY_NAME[name]  # by name: the cases' lambdas do not pickle
    tmp = tempfile.mkdtemp(prefix='geom_%s_' % case.name)
    rows = []
    try:
        for g in grids:
            rows.append(check_grid(frep, case, g, tmp))
        fails = []
        for r in rows:
            # an open mesh (a solid cut by the box, not capped) is judged by its capped volume;
            # its open rims are a failure of their own (watertight)
            if 'err' in r:
                r['eff_err'] = r.get('err_capped', r['err'])
            if r['grid'] in (128, 129) and 'eff_err' in r and abs(r['eff_err']) > VOLUME_TOL:
                r['fail'].append('volume error %+.3f %% > %.1f %%%s' %
                                 (r['eff_err'], VOLUME_TOL, ' (open mesh, rims capped)' if 'err_capped' in r else ''))
        done = [r for r in rows if 'eff_err' in r]
        if len(done) >= 2:
            # slack: meshes of flat-faced solids can be exact at a coarse grid; at the finest a
            # vertex may still sit up to GUARD voxel off the surface (the mesher's end guard of
            # 1e-3 of an edge up to sqrt(3) voxels long, the caps' 2e-3 voxel inset): that shell's
            # volume, at least SLACK percentage points
            fine = done[-1]
            slack = max(SLACK, 100.0 * GUARD * fine['voxel'] * fine['area'] / case.volume)
            # below FLOOR the error has converged into the mesher's own noise (a crease that
            # falls within a hundredth of a voxel of lattice points is chamfered up to half a
            # voxel at one grid and not another): "falling" is judged above it
            if abs(fine['eff_err']) > max(abs(done[0]['eff_err']) + slack, FLOOR):
                fails.append('volume error at the finest grid (%d: %+.4f %%) exceeds the coarsest (%d: %+.4f %%) '
                             'by more than %.4f' % (fine['grid'], fine['eff_err'], done[0]['grid'],
                                                    done[0]['eff_err'], slack))
        return {'case': case.name, 'rows': rows, 'case_fail': fails}
    finally:
        if keep:
            os.makedirs(keep, exist_ok=True)
            for f in os.listdir(tmp):
                shutil.move(os.path.join(tmp, f), os.path.join(keep, f))
        shutil.rmtree(tmp, ignore_errors=True)


# ------------------------------------------------------------------------------------------------
# Output


def fmt_row(r):
    def g(k, f, dflt='-'):
        v = r.get(k)
        return dflt if v is None else f % v
    wt = '-' if 'watertight' not in r else ('yes' if r['watertight'] else 'NO (%d open)' % r['open'] if r['open'] else 'NO')
    err = g('err', '%+.3f')
    if 'err_capped' in r:
        err += ' (capped %+.3f)' % r['err_capped']
    return '  %5d %9s %10s %26s %10s %8s %10s %10s %-13s %6s %6s' % (
        r['grid'], g('tris', '%d'), g('volume', '%.6f'), err, g('dev', '%.3g'),
        '-' if 'dev' not in r or 'voxel' not in r else '%.3f' % (r['dev'] / r['voxel']),
        g('bound', '%.3g', 'missing'), g('simp_bound', '%.3g'), wt, g('s2', '%.2f'), g('s0', '%.2f'))


HEAD = '  %5s %9s %10s %26s %10s %8s %10s %10s %-13s %6s %6s' % (
    'grid', 'triangles', 'volume', 'error %', 'max dev', 'dev/vox', 'bound', 'simp.bnd', 'watertight', 's(w2)', 's(w0)')


def print_case(case, res):
    print('\n%s  [%s, %s]  exact V = %.6f%s' % (case.name, case.family, case.file, case.volume,
                                                 '' if set(case.grids) & {128, 129} else
                                                 '  (grids below 128: no 0.5 % volume check)'))
    print('  ' + case.why)
    print('  -b %s' % ','.join(repr(float(v)) for v in case.bounds))
    print(HEAD)
    for r in res['rows']:
        print(fmt_row(r))
        for f in r['fail']:
            print('      FAIL: %s' % f)
        if r['fail']:
            print('      (repeat: %s)' % r.get('cmd', ''))
        for n in r.get('notes', []):
            print('      note: %s' % n)
    for f in res['case_fail']:
        print('    FAIL: %s' % f)
    sys.stdout.flush()


# ------------------------------------------------------------------------------------------------
# --eval-check: the models against their closed forms, point by point


def eval_at(frep, case, pt):
    cmd = [frep, 'eval', os.path.join(MODELS, case.file), '-o', case.name, '--at', ','.join('%.9g' % v for v in pt)]
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    m = re.search(r'^value: (\S+)', p.stdout, re.M)
    if p.returncode != 0 or not m:
        raise RuntimeError('%s: %s' % (' '.join(cmd), p.stdout + p.stderr))
    return float(m.group(1))


def eval_check(frep, case, n, rng):
    """n random points of the box with |sdf| > 0.01, and n points 0.004 (plus twice the case's
    search gap) either side of the surface (bisected on the closed form between random inside and
    outside points)."""
    lo, hi = np.array(case.bounds[:3]), np.array(case.bounds[3:])
    q = lo + (hi - lo) * rng.random((20000, 3))
    d = case.sdf(q)
    far = q[np.abs(d) > 0.01 + 2 * case.gap][:n]
    ins, outs = q[d < -0.01], q[d > 0.01]
    near = []
    for k in range(4 * n):
        if len(near) >= n or not len(ins) or not len(outs):
            break
        a, b = ins[rng.integers(len(ins))], outs[rng.integers(len(outs))]
        for _ in range(60):
            m = (a + b) / 2
            if case.sdf(m[None])[0] <= 0:
                a = m
            else:
                b = m
        u = (b - a) / max(np.linalg.norm(b - a), 1e-300)
        s = (a + b) / 2
        off = 0.004 + 2 * case.gap  # a search with an explicit gap may read that much low
        cand = [s - off * u / np.linalg.norm(u), s + off * u / np.linalg.norm(u)]
        for c in cand:
            if abs(case.sdf(c[None])[0]) > 0.0015 + case.gap:
                near.append(c)
    pts = np.array(list(far) + near[:n])
    d = case.sdf(pts)
    out = []
    bad = 0
    for q, dv in zip(pts, d):
        v = eval_at(frep, case, q)
        ok = (v >= 0) == (dv <= 0)
        bad += not ok
        out.append((q, dv, v, ok))
    return out, bad


# ------------------------------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('frep')
    ap.add_argument('--quick', action='store_true')
    ap.add_argument('--only', default='')
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--keep', default='')
    ap.add_argument('--eval-check', type=int, default=0)
    ap.add_argument('--slow', action='store_true', help='also the cases marked slow')
    a = ap.parse_args()
    frep = os.path.abspath(a.frep)
    selected = [c for c in C.CASES if a.slow or not c.slow]
    if a.only:
        pats = a.only.split(',')
        selected = [c for c in C.CASES if any(fnmatch.fnmatch(c.name, p) for p in pats)
                    and (a.slow or not c.slow or c.name in pats)]
        if not selected:
            print('no case matches %s; cases: %s' % (a.only, ' '.join(c.name for c in C.CASES)))
            return 2
    if a.eval_check:
        rng = np.random.default_rng(1)
        total_bad = 0
        for c in selected:
            res, bad = eval_check(frep, c, a.eval_check, rng)
            total_bad += bad
            errs = [abs(v + dv) for _, dv, v, _ in res]
            print('%-28s sign mismatches %d/%d; |f + sdf| max %.3g (0 where f is an exact distance)' %
                  (c.name, bad, len(res), max(errs)))
            for q, dv, v, ok in res:
                if not ok:
                    print('    at (%.4f, %.4f, %.4f): frep %.6g, closed form sdf %.6g' % (q[0], q[1], q[2], v, dv))
        return 1 if total_bad else 0

    t_start = time.time()
    jobs = []
    for c in selected:
        grids = [g for g in c.grids if g < 100] if a.quick else list(c.grids)
        jobs.append((c, grids))
    # longest first, so that the pool's tail is short
    est = {c.name: i for i, c in enumerate(selected)}
    jobs.sort(key=lambda j: (-COST.get(j[0].name, 1.0), est[j[0].name]))
    results = {}
    with cf.ProcessPoolExecutor(max_workers=max(1, a.jobs)) as ex:
        futs = {ex.submit(run_case, frep, c.name, g, a.keep): c for c, g in jobs}
        for f in cf.as_completed(futs):
            c = futs[f]
            try:
                results[c.name] = f.result()
            except Exception as e:  # noqa: BLE001
                results[c.name] = {'case': c.name, 'rows': [], 'case_fail': ['suite error: %r' % e]}
            print_case(c, results[c.name])
    wall = time.time() - t_start

    print('\n==== summary (%d cases, %.1f s wall, %d at a time) ====' % (len(selected), wall, a.jobs))
    failures = []
    for c in selected:
        r = results[c.name]
        for row in r['rows']:
            for f in row['fail']:
                failures.append('%s --res %d: %s' % (c.name, row['grid'], f))
        for f in r['case_fail']:
            failures.append('%s: %s' % (c.name, f))
        cpu = sum(row.get('s2', 0) + row.get('s0', 0) for row in r['rows'])
        nf = sum(len(row['fail']) for row in r['rows']) + len(r['case_fail'])
        print('  %-28s %-4s  %6.1f s  %s' % (c.name, 'ok' if nf == 0 else 'FAIL', cpu,
                                             '' if nf == 0 else '%d failed checks' % nf))
    if failures:
        print('\n%d failed checks:' % len(failures))
        for f in failures:
            print('  ' + f)
        return 1
    print('\nall checks passed')
    return 0


# Seconds of both runs at all grids (measured 2026-12-06, 2 cores shared, load ~3), to start the
# expensive cases first so that the pool's tail is short; unlisted cases count 1.
COST = {'sweep_torus': 30, 'steiner_planes_hfsphere': 27, 'morph_ball_block_tol': 25, 'sweep_rotate_halfturn': 19,
        'sweep_halfarc': 16, 'prim_ball': 14, 'prim_torus': 12, 'sweepkeys_capsule': 12.5, 'project_capsule4': 11,
        'project_ball5': 11, 'erode_frball_frball': 10, 'project_box4': 10, 'project_ball4': 10,
        'prim_frblock_lattice': 10, 'morph_frblocks_tol': 10, 'offsetr_planes_tol': 8}

if __name__ == '__main__':
    sys.exit(main())
