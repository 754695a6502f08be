"""The geometry acceptance suite's cases: closed-form solids, their exact volumes and exact
signed distances (numpy, negative inside, world units), the object to mesh and its box.

Each case: the model file (tests/geometry/models/), the object (-o), the -b box, the grids
(--res values), the exact volume, the exact signed distance of the solid meshed (for a solid
cut by the box: of solid n box, whose faces on the box's planes are part of the surface), and a
one-line derivation. The models are written from the formulas, not from any example of the
repository.

Grids: most cases use --res 32, 64, 128 (256 for a few cheap ones). Cases whose faces must lie
on lattice planes use --res 33, 65, 129 (257) over a box whose longest extent is 2: voxels 1/16,
1/32, 1/64 (1/128), and every such face is a multiple of 1/16 from the box's minimum corner.
frep mesh puts grid points at lo + i * voxel, voxel = longest extent / (res - 1); the box's
longest axis (and its minimum faces) are therefore always lattice planes. The -b boxes around
uncut solids leave at least 2.2 voxels of the coarsest grid on every side (margin()).

slow=True: too slow for the suite's 5-minute budget (a morph of a ball and a polytope of planes
and radius offsets at the default search gap, two sweeps); run_suite.py runs them with --slow or when --only names them.
Their families are covered in the budget by *_tol cases whose models give the search an explicit
gap of 0.01 (gap=0.01 here), on grids 16-32 only (no 0.5 % check at 128).
"""
import math
from dataclasses import dataclass

import numpy as np

PI = math.pi

# ---------------------------------------------------------------------------------------------
# Exact signed distances (negative inside). p: (n, 3) float64.


def _v(a):
    return np.asarray(a, dtype=np.float64)


def sd_box(p, lo, hi):
    """Axis-aligned box [lo, hi]: exact (outside: norm of the excess; inside: -min face gap)."""
    lo, hi = _v(lo), _v(hi)
    c, h = (lo + hi) / 2, (hi - lo) / 2
    q = np.abs(p - c) - h
    out = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    ins = np.minimum(q.max(axis=1), 0.0)
    return out + ins


def rot_matrix(rx, ry, rz):
    """R = Rz Ry Rx, right-handed rotations by the given angles (radians)."""
    cx, sx, cy, sy, cz, sz = math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def sd_rot_block(p, corner, size, rot):
    """Block with corner `corner` and edges R (lx, 0, 0), R (0, ly, 0), R (0, 0, lz)."""
    R = rot_matrix(*rot)
    local = (p - _v(corner)) @ R  # R^T (p - c), row-wise
    return sd_box(local, (0, 0, 0), size)


def sd_ball(p, c, r):
    return np.linalg.norm(p - _v(c), axis=1) - r


def dist_segment(p, a, b):
    a, b = _v(a), _v(b)
    d = b - a
    t = np.clip(((p - a) @ d) / (d @ d), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1)


def sd_capsule(p, a, b, r):
    return dist_segment(p, a, b) - r


def _rho_h(p, c, axis):
    """Distance from the axis line through c along `axis` (0, 1, 2) and the coordinate along it."""
    q = p - _v(c)
    others = [i for i in range(3) if i != axis]
    return np.hypot(q[:, others[0]], q[:, others[1]]), q[:, axis]


def sd_torus(p, c, R, r, axis=2):
    rho, h = _rho_h(p, c, axis)
    return np.hypot(rho - R, h) - r


def _sd_rect2(u, v, ulo, uhi, vlo, vhi):
    """2D box [ulo, uhi] x [vlo, vhi], exact."""
    qu = np.abs(u - (ulo + uhi) / 2) - (uhi - ulo) / 2
    qv = np.abs(v - (vlo + vhi) / 2) - (vhi - vlo) / 2
    return np.hypot(np.maximum(qu, 0), np.maximum(qv, 0)) + np.minimum(np.maximum(qu, qv), 0)


def sd_cylinder(p, c, R, hlo, hhi, axis=2):
    """Finite cylinder: radius R around the axis through c, axis coordinate in [hlo, hhi]
    (absolute). Exact: a solid of revolution is its (rho, h) section's 2D distance."""
    rho, _ = _rho_h(p, c, axis)
    h = p[:, axis]
    return _sd_rect2(rho, h, -R, R, hlo, hhi)


def sd_annulus_cyl(p, c, Ri, Ro, hlo, hhi, axis=2):
    """Ri <= rho <= Ro, hlo <= h <= hhi (absolute). Exact (2D section, Ri > 0)."""
    rho, _ = _rho_h(p, c, axis)
    return _sd_rect2(rho, p[:, axis], Ri, Ro, hlo, hhi)


def _sd_extrude(d2, h, hlo, hhi):
    """Prism over a 2D region with exact distance d2, h in [hlo, hhi]: exact."""
    dz = np.abs(h - (hlo + hhi) / 2) - (hhi - hlo) / 2
    return np.minimum(np.maximum(d2, dz), 0) + np.hypot(np.maximum(d2, 0), np.maximum(dz, 0))


def sd_rounded_rect_prism(p, lo, hi, r):
    """(block [lo, hi]) + zdisc(r): the rounded rectangle [lo, hi]_xy + disc(r) extruded over z."""
    lo, hi = _v(lo), _v(hi)
    d2 = _sd_rect2(p[:, 0], p[:, 1], lo[0], hi[0], lo[1], hi[1]) - r
    return _sd_extrude(d2, p[:, 2], lo[2], hi[2])


def sd_discus(p, c, r, s, axis=0):
    """disc(r) normal to `axis` at c, + ball(s): dist(X, disc) - s."""
    rho, h = _rho_h(p, c, axis)
    return np.hypot(np.maximum(rho - r, 0), h) - s


def sd_disc_cut(u, v, cu, cv, R, h):
    """2D: the disc |(u, v) - (cu, cv)| <= R cut to v <= h. Exact: outside, the nearest of the
    radial projection (when it is on the kept arc) and the nearest point of the chord; inside,
    the smaller of the two gaps."""
    du, dv = u - cu, v - cv
    dc = np.hypot(du, dv)
    inside = (dc <= R) & (v <= h)
    d_in = -np.minimum(R - dc, h - v)
    with np.errstate(invalid='ignore', divide='ignore'):
        pv = cv + R * dv / np.where(dc > 0, dc, 1)
        pu = cu + R * du / np.where(dc > 0, dc, 1)
    radial = np.where(pv <= h, np.hypot(u - pu, v - pv), np.inf)
    a = math.sqrt(max(R * R - (h - cv) ** 2, 0.0))
    cu_ = np.clip(u, cu - a, cu + a)
    chord = np.hypot(u - cu_, v - h)
    d_out = np.minimum(radial, chord)
    return np.where(inside, d_in, d_out)


def sd_ball_cut_top(p, c, R, ztop):
    """Ball (c, R) n {z <= ztop}: a solid of revolution about the vertical axis through c."""
    rho, _ = _rho_h(p, c, 2)
    return sd_disc_cut(rho, p[:, 2], 0.0, c[2], R, ztop)


def sd_torus_cut_below(p, c, R, r, zcut):
    """Torus (axis z through c) n {z >= zcut}: in (rho, -z) the tube's disc cut to -z <= -zcut."""
    rho, _ = _rho_h(p, c, 2)
    return sd_disc_cut(rho, -p[:, 2], R, -c[2], r, -zcut)


def dist_arc(p, c, R, a0, a1):
    """Distance to the circular arc centre c, radius R, in the plane z = c_z, angles [a0, a1]."""
    q = p - _v(c)
    phi = np.arctan2(q[:, 1], q[:, 0])
    phi = np.where(phi < a0, phi + 2 * PI, phi)
    on = (phi >= a0) & (phi <= a1)
    rho = np.hypot(q[:, 0], q[:, 1])
    d_on = np.hypot(rho - R, q[:, 2])
    e0 = _v(c) + R * np.array([math.cos(a0), math.sin(a0), 0.0])
    e1 = _v(c) + R * np.array([math.cos(a1), math.sin(a1), 0.0])
    d_end = np.minimum(np.linalg.norm(p - e0, axis=1), np.linalg.norm(p - e1, axis=1))
    return np.where(on, d_on, d_end)


# ---------------------------------------------------------------------------------------------
# Volumes


def v_ball(r):
    return 4.0 / 3.0 * PI * r ** 3


def v_steiner_box(size, r):
    """Box a x b x c (+) ball r: V + S r + M r^2 + 4/3 pi r^3."""
    a, b, c = size
    return a * b * c + 2 * (a * b + b * c + c * a) * r + PI * (a + b + c) * r ** 2 + v_ball(r)


def v_capsule(a, b, r):
    return PI * r * r * float(np.linalg.norm(_v(b) - _v(a))) + v_ball(r)


def v_prism_rounded(size, r, s=0.0):
    """(block lx x ly x lz) + zdisc(r) [+ ball(s)]: Q = rounded-rectangle prism, then Steiner
    V(Q) + S(Q) s + pi (lz + P/2) s^2 + 4/3 pi s^3 (P, A: the base's perimeter and area)."""
    lx, ly, lz = size
    A = lx * ly + 2 * (lx + ly) * r + PI * r * r
    P = 2 * (lx + ly) + 2 * PI * r
    return A * lz + (2 * A + P * lz) * s + PI * (lz + P / 2) * s * s + v_ball(s)


def v_cap(R, k):
    """Spherical cap of height k."""
    return PI * k * k * (3 * R - k) / 3


# ---------------------------------------------------------------------------------------------


@dataclass
class Case:
    name: str           # the object meshed (-o) and the case's name
    file: str           # under tests/geometry/models/
    bounds: tuple       # -b: xmin, ymin, zmin, xmax, ymax, zmax
    volume: float
    sdf: object         # numpy function (n, 3) -> (n,), negative inside
    why: str            # the derivation, one line
    grids: tuple = (32, 64, 128)
    bbox: tuple = None  # the solid's own box (lo, hi), to check that -b holds it (None: cut cases)
    cut: bool = False   # the solid leaves -b: the expected mesh is solid n box, capped
    cut_faces: tuple = ()  # the faces of the box it reaches, as frep names them ('x-min', ...)
    family: str = ''
    slow: bool = False  # too slow for the 5-minute budget: run with --slow (or --only NAME)
    gap: float = 0.0    # an explicit search gap in the model's options: values may be that much low


def pad(lo, hi, m=0.08):
    """-b around the box [lo, hi] with a margin of m world units on every side."""
    return tuple(round(v - m, 6) for v in lo) + tuple(round(v + m, 6) for v in hi)


def boxbb(lo, hi, r=0.0):
    return (tuple(v - r for v in lo), tuple(v + r for v in hi))


LATTICE = (33, 65, 129)
LATTICE_FINE = (33, 65, 129, 257)
FINE = (32, 64, 128, 256)
BOX1 = (-1.0, -1.0, -1.0, 1.0, 1.0, 1.0)

CASES = []


def margin(lo, hi, grids):
    """A margin m of at least 0.06 and 2.2 voxels of the coarsest grid: m >= 2.2 (L + 2m) / (g - 1)."""
    L = max(h - l for l, h in zip(lo, hi))
    g = min(grids)
    return max(0.06, 2.2 * L / (g - 1 - 4.4))


def add(**kw):
    c = Case(**kw)
    if c.bbox is not None and not c.cut and c.bounds != BOX1:
        lo, hi = c.bbox
        c.bounds = pad(lo, hi, margin(lo, hi, c.grids))
    CASES.append(c)
    return c


def _shift(v, d):
    return tuple(a + b for a, b in zip(v, d))


def _box_case(name, file, family, lo, hi, r, why, grids=(32, 64, 128), bounds=None):
    """Box [lo, hi] (+) ball(r) (r = 0: the box itself)."""
    size = tuple(h - l for l, h in zip(lo, hi))
    if r > 0:
        sdf = lambda p, lo=lo, hi=hi, r=r: sd_box(p, lo, hi) - r
        vol = v_steiner_box(size, r)
    else:
        sdf = lambda p, lo=lo, hi=hi: sd_box(p, lo, hi)
        vol = size[0] * size[1] * size[2]
    bb = boxbb(lo, hi, r)
    return add(name=name, file=file, family=family, bounds=bounds or pad(*bb), volume=vol, sdf=sdf,
               why=why, grids=grids, bbox=bb)


def _ball_case(name, file, family, c, r, why, grids=(32, 64, 128)):
    bb = boxbb(c, c, r)
    return add(name=name, file=file, family=family, bounds=pad(*bb), volume=v_ball(r),
               sdf=lambda p, c=c, r=r: sd_ball(p, c, r), why=why, grids=grids, bbox=bb)


def _capsule_case(name, file, family, a, b, r, why, grids=(32, 64, 128)):
    lo = tuple(min(x, y) - r for x, y in zip(a, b))
    hi = tuple(max(x, y) + r for x, y in zip(a, b))
    return add(name=name, file=file, family=family, bounds=pad(lo, hi), volume=v_capsule(a, b, r),
               sdf=lambda p, a=a, b=b, r=r: sd_capsule(p, a, b, r), why=why, grids=grids, bbox=(lo, hi))


# --- Steiner: convex (+) ball ----------------------------------------------------------------
F = 'steiner.hf'
_box_case('steiner_frblock_frball', F, 'steiner',
          _shift((-0.43, -0.31, -0.22), (0.05, -0.03, 0.02)), _shift((0.47, 0.39, 0.28), (0.05, -0.03, 0.02)), 0.17,
          'Steiner: 0.9x0.7x0.5 box (+) ball 0.17 (frBlock, frBall at (0.05,-0.03,0.02)): abc + 2(ab+bc+ca)r + pi(a+b+c)r^2 + 4/3 pi r^3',
          grids=(32, 64, 128))
_box_case('steiner_hfblock_frball', F, 'steiner', (-0.37, -0.52, -0.29), (0.24, 0.53, 0.19), 0.22,
          'Steiner: hfBlock 0.61x1.05x0.48 (+) frBall 0.22')
_box_case('steiner_planes_hfsphere', F, 'steiner', (-0.2, -0.25, -0.55), (0.55, 0.2, 0.3), 0.2,
          'Steiner: min/max box 0.75x0.45x0.85 (+) hfSphere 0.2 at (0.1,0,-0.05)')
_R4 = (0.3, -0.2, 0.5)
_c4 = (-0.2, -0.3, -0.1)
_s4 = (0.8, 0.5, 0.3)
_pts4 = np.array([[i * _s4[0], j * _s4[1], k * _s4[2]] for i in (0, 1) for j in (0, 1) for k in (0, 1)]) @ rot_matrix(*_R4).T + _c4
add(name='steiner_rotblock_frball', file=F, family='steiner',
    bounds=pad(tuple(_pts4.min(0) - 0.12), tuple(_pts4.max(0) + 0.12)),
    bbox=(tuple(_pts4.min(0) - 0.12), tuple(_pts4.max(0) + 0.12)),
    volume=v_steiner_box(_s4, 0.12), sdf=lambda p: sd_rot_block(p, _c4, _s4, _R4) - 0.12,
    why='Steiner (rotation-invariant): 0.8x0.5x0.3 frBlock turned by Rz(0.5)Ry(-0.2)Rx(0.3) (+) frBall 0.12')
_box_case('steiner_lines_frball', F, 'steiner', (-0.35, -0.2, -0.3), (0.35, 0.25, 0.3), 0.14,
          'Steiner: xline 0.7 (+) yline 0.45 (+) zline 0.6 = 0.7x0.45x0.6 box, (+) ball 0.14 (frMinkowskiSum)',
          grids=(32, 64, 128))
_ball_case('ballball_frball', F, 'steiner', (0.05, -0.08, 0.15), 0.63,
           'ball 0.35 (+) ball 0.28 = ball 0.63 at c1 + c2 (frBall): 4/3 pi 0.63^3', grids=(32, 64, 128))
_ball_case('ballball_hfsphere', F, 'steiner', (0.1, 0.15, 0.02), 0.65,
           'ball 0.4 (+) ball 0.25 = ball 0.65 at c1 + c2 (hfSphere): 4/3 pi 0.65^3')
_box_case('offsetr_planes', F, 'steiner', (-0.5, -0.35, -0.2), (0.4, 0.3, 0.25), 0.15,
          'frOffsetR 0.15 of a 0.9x0.65x0.45 min/max box = box (+) ball 0.15: Steiner').slow = True
_box_case('offsetr_hfblock', F, 'steiner', (-0.2, -0.25, -0.4), (0.35, 0.15, 0.35), 0.1,
          'frOffsetR 0.1 of hfBlock 0.55x0.4x0.75 = box (+) ball 0.1: Steiner').slow = True
_box_case('offsetr_planes_tol', F, 'steiner', (-0.5, -0.35, -0.2), (0.4, 0.3, 0.25), 0.15,
          'frOffsetR 0.15 (B&B gap 0.01) of a 0.9x0.65x0.45 min/max box = box (+) ball 0.15: Steiner',
          grids=(16, 24, 32)).gap = 0.01

# --- Sweeps ------------------------------------------------------------------------------------
F = 'sweeps.hf'
_capsule_case('sweep_capsule', F, 'sweep', (-0.6, 0.2, 0.1), (0.5, -0.1, 0.35), 0.2,
              'ball 0.2 swept along a segment (frSweep, linear motion): capsule pi r^2 L + 4/3 pi r^3')
_capsule_case('sweepkeys_capsule', F, 'sweep', (0.45, -0.35, -0.3), (-0.3, 0.4, 0.25), 0.25,
              'frBall 0.25 through two keyframes (frSweepKeys): capsule pi r^2 L + 4/3 pi r^3')
add(name='sweep_torus', file=F, family='sweep',
    bbox=((-0.73, -0.73, -0.13), (0.73, 0.73, 0.23)), bounds=pad((-0.73, -0.73, -0.13), (0.73, 0.73, 0.23)),
    volume=2 * PI * PI * 0.55 * 0.18 ** 2, sdf=lambda p: sd_torus(p, (0, 0, 0.05), 0.55, 0.18),
    why='ball 0.18 swept around a circle of radius 0.55 (frSweep, cos/sin): torus, Pappus 2 pi^2 R r^2')
add(name='sweep_halfarc', file=F, family='sweep', slow=True,
    bbox=((-0.6, -0.35, -0.15), (0.7, 0.45, 0.15)), bounds=pad((-0.6, -0.35, -0.15), (0.7, 0.45, 0.15)),
    volume=PI * 0.5 * PI * 0.15 ** 2 + v_ball(0.15),
    sdf=lambda p: dist_arc(p, (0.05, -0.2, 0.0), 0.5, 0.0, PI) - 0.15,
    why='ball 0.15 swept along a half circle R 0.5 (frSweep, t in [0, 0.5]): Pappus theta R pi r^2 + two half balls 4/3 pi r^3')
_box_case('sweep_block_line', F, 'sweep', (-0.5, -0.1, -0.15), (0.5, 0.15, 0.05), 0.0,
          'frBlock 0.3x0.25x0.2 swept by 0.7 along x (frSweep): the block 1.0x0.25x0.2')
_Ro = math.sqrt(0.6 ** 2 + 0.1 ** 2)
add(name='sweep_turn_annulus', file=F, family='sweep', slow=True,
    bbox=((-_Ro, -_Ro, -0.15), (_Ro, _Ro, 0.2)), bounds=pad((-_Ro, -_Ro, -0.15), (_Ro, _Ro, 0.2)),
    volume=PI * (_Ro ** 2 - 0.25 ** 2) * 0.35,
    sdf=lambda p: sd_annulus_cyl(p, (0, 0, 0), 0.25, _Ro, -0.15, 0.2),
    why='block 0.25..0.6 x -0.1..0.1 x -0.15..0.2 turned a full turn about z (frSweep rotation): annulus pi (Ro^2 - Ri^2) h, Ro^2 = 0.6^2 + 0.1^2')
_rh = math.sqrt(0.5 ** 2 + 0.1 ** 2)
_ah = math.atan2(-0.1, 0.5)
add(name='sweep_rotate_halfturn', file=F, family='sweep',
    bbox=((-_rh - 0.15, -0.25, -0.15), (_rh + 0.15, _rh + 0.15, 0.15)),
    bounds=pad((-_rh - 0.15, -0.25, -0.15), (_rh + 0.15, _rh + 0.15, 0.15)),
    volume=PI * _rh * PI * 0.15 ** 2 + v_ball(0.15),
    sdf=lambda p: dist_arc(p, (0.0, 0.0, 0.0), _rh, _ah, _ah + PI) - 0.15,
    why='ball 0.15 at (0.5,-0.1,0) turned by pi about z (frSweep rotation only): Pappus pi rho pi r^2 + 4/3 pi r^3, rho^2 = 0.26')

# --- Projections -------------------------------------------------------------------------------
F = 'project.hf'
_ball_case('project_ball4', F, 'project', (0.1, -0.05, 0.12), 0.45,
           '4D ball 0.45 projected along x4 (frProject): the 3D ball 0.45')
_capsule_case('project_capsule4', F, 'project', (-0.5, 0.1, -0.2), (0.4, -0.3, 0.1), 0.22,
              '4D: ball 0.22 whose centre moves with x4 in [0, 1], projected along x4: capsule pi r^2 L + 4/3 pi r^3')
_box_case('project_box4', F, 'project', (-0.4, -0.3, -0.25), (0.35, 0.45, 0.2), 0.0,
          '4D box projected along x4: the 3D box 0.75x0.75x0.45')
_ball_case('project_ball5', F, 'project', (-0.08, 0.11, 0.03), 0.4,
           '5D ball 0.4 (quadratic field) projected along x4, x5: the 3D ball 0.4')

# --- Erosions ----------------------------------------------------------------------------------
F = 'erosion.hf'
_box_case('erode_frblock_frball', F, 'erosion', (-0.35, -0.2, -0.25), (0.45, 0.3, 0.15), 0.0,
          'frBlock 1.2x0.9x0.8 (-) frBall 0.2: (a-2r)(b-2r)(c-2r) = 0.8x0.5x0.4', grids=(32, 64, 128))
_box_case('erode_hfblock_hfsphere', F, 'erosion', (-0.35, -0.3, -0.25), (0.45, 0.2, 0.35), 0.0,
          'hfBlock 1.1x0.8x0.9 (-) hfSphere 0.15: 0.8x0.5x0.6')
_box_case('erode_frblock_offball', F, 'erosion', (-0.35, -0.05, -0.43), (0.35, 0.35, 0.17), 0.0,
          'frBlock 1.0x0.7x0.9 (-) frBall 0.15 at c0 = (0.05,-0.1,0.08): the 0.7x0.4x0.6 box moved by -c0')
_ball_case('erode_frball_frball', F, 'erosion', (0.14, -0.11, 0.1), 0.45,
           'frBall 0.7 (-) frBall 0.25: ball 0.45 at c1 - c2', grids=FINE)
_ball_case('erode_hfsphere_hfsphere', F, 'erosion', (-0.13, 0.05, 0.05), 0.45,
           'hfSphere 0.65 (-) hfSphere 0.2: ball 0.45 at c1 - c2')

# --- Minkowski morphs: ((1 - t) A) (+) (t B) ----------------------------------------------------
F = 'morph.hf'


def _lerp(a, b, t):
    return tuple((1 - t) * x + t * y for x, y in zip(a, b))


_box_case('morph_frblocks', F, 'morph',
          _lerp((-0.3, -0.2, -0.25), (-0.1, -0.5, -0.2), 0.35), _lerp((0.5, 0.2, 0.25), (0.2, 0.4, 0.4), 0.35), 0.0,
          'frMorphMinkowski of frBlocks, t = 0.35: the box [(1-t) lo_A + t lo_B, (1-t) hi_A + t hi_B]')
_box_case('morph_hfblocks', F, 'morph',
          _lerp((-0.1, -0.4, -0.3), (-0.6, -0.1, -0.35), 0.6), _lerp((0.4, 0.5, 0.1), (0.4, 0.2, 0.45), 0.6), 0.0,
          'frMorphMinkowski of hfBlocks, t = 0.6: the box of lerped corners')
_box_case('morph_ball_block', F, 'morph',
          _shift((-0.2, -0.15, -0.1), (0.05, 0.0, -0.05)), _shift((0.2, 0.15, 0.1), (0.05, 0.0, -0.05)), 0.25,
          'frMorphMinkowski(frBall 0.5, frBlock 0.8x0.6x0.4, 0.5) = 0.4x0.3x0.2 box (+) ball 0.25: Steiner')
_box_case('morph_hfsphere_planes', F, 'morph',
          _shift((-0.15, -0.09, -0.18), (-0.14, 0.07, 0.105)), _shift((0.18, 0.12, 0.06), (-0.14, 0.07, 0.105)), 0.42,
          'frMorphMinkowski(hfSphere 0.6, min/max box 1.1x0.7x0.8, 0.3) = 0.33x0.21x0.24 box (+) ball 0.42: Steiner').slow = True
_box_case('morph_frblocks_tol', F, 'morph',
          _lerp((-0.3, -0.2, -0.25), (-0.1, -0.5, -0.2), 0.35), _lerp((0.5, 0.2, 0.25), (0.2, 0.4, 0.4), 0.35), 0.0,
          'frMorphMinkowski of frBlocks, t = 0.35, B&B gap 0.01: the box of lerped corners', grids=(16, 24, 32)).gap = 0.01
_box_case('morph_ball_block_tol', F, 'morph',
          _shift((-0.2, -0.15, -0.1), (0.05, 0.0, -0.05)), _shift((0.2, 0.15, 0.1), (0.05, 0.0, -0.05)), 0.25,
          'frMorphMinkowski(frBall 0.5, frBlock 0.8x0.6x0.4, 0.5), B&B gap 0.01 = 0.4x0.3x0.2 box (+) ball 0.25: Steiner',
          grids=(16, 24)).gap = 0.01

# --- Roerdink's basic-set sums -----------------------------------------------------------------
F = 'roerdink.hf'
_lo, _hi = (-0.3, -0.35, -0.2), (0.4, 0.15, 0.2)
add(name='roerdink_block_zdisc', file=F, family='roerdink',
    bbox=((-0.5, -0.55, -0.2), (0.6, 0.35, 0.2)), bounds=pad((-0.5, -0.55, -0.2), (0.6, 0.35, 0.2)),
    volume=v_prism_rounded((0.7, 0.5, 0.4), 0.2),
    sdf=lambda p: sd_rounded_rect_prism(p, (-0.3, -0.35, -0.2), (0.4, 0.15, 0.2), 0.2),
    why='frBlock 0.7x0.5x0.4 (+) frZDisc 0.2: rounded-rectangle prism lz (lx ly + 2(lx+ly) r + pi r^2)', grids=(32, 64, 128))
add(name='roerdink_block_zdisc_ball', file=F, family='roerdink',
    bbox=((-0.6, -0.45, -0.25), (0.5, 0.5, 0.25)), bounds=pad((-0.6, -0.45, -0.25), (0.5, 0.5, 0.25)),
    volume=v_prism_rounded((0.6, 0.45, 0.3), 0.15, 0.1),
    sdf=lambda p: sd_rounded_rect_prism(p, (-0.35, -0.2, -0.15), (0.25, 0.25, 0.15), 0.15) - 0.1,
    why='frBlock 0.6x0.45x0.3 (+) frZDisc 0.15 (+) frBall 0.1: Steiner of the prism Q, V + S s + pi (lz + P/2) s^2 + 4/3 pi s^3')
add(name='roerdink_zline_zdisc', file=F, family='roerdink',
    bbox=((-0.25, -0.4, -0.4), (0.35, 0.2, 0.5)), bounds=pad((-0.25, -0.4, -0.4), (0.35, 0.2, 0.5)),
    volume=PI * 0.3 ** 2 * 0.9, sdf=lambda p: sd_cylinder(p, (0.05, -0.1, 0), 0.3, -0.4, 0.5),
    why='frZLine 0.9 (+) frZDisc 0.3: the cylinder pi r^2 l')
add(name='roerdink_discus', file=F, family='roerdink',
    bbox=((-0.02, -0.42, -0.55), (0.22, 0.52, 0.39)), bounds=pad((-0.02, -0.42, -0.55), (0.22, 0.52, 0.39)),
    volume=2 * PI * 0.35 ** 2 * 0.12 + PI * PI * 0.35 * 0.12 ** 2 + v_ball(0.12),
    sdf=lambda p: sd_discus(p, (0.1, 0.05, -0.08), 0.35, 0.12, axis=0),
    why='frXDisc 0.35 (+) frBall 0.12 (discus): 2 pi r^2 s + pi^2 r s^2 + 4/3 pi s^3 (Steiner of a disc; Pappus)')

# --- Solids cut by the grid's box (expected: solid n box, capped on the box faces) ---------------
F = 'cut.hf'
_k = 0.75 - (0.5 - 0.1)
add(name='cut_ball_top', file=F, family='cut', cut=True, cut_faces=('z-max',), bounds=(-1.0, -1.0, -1.0, 1.0, 1.0, 0.5), grids=LATTICE,
    volume=v_ball(0.75) - v_cap(0.75, _k),
    sdf=lambda p: sd_ball_cut_top(p, (0.05, -0.1, 0.1), 0.75, 0.5),
    why='hfSphere 0.75 at z 0.1 under the box top z = 0.5: 4/3 pi R^3 - pi k^2 (3R - k)/3, k = 0.35')
add(name='cut_cylinder_long', file=F, family='cut', cut=True, cut_faces=('z-min', 'z-max'), bounds=(-0.5, -0.6, -0.75, 0.7, 0.5, 0.75),
    volume=PI * 0.4 ** 2 * 1.5, sdf=lambda p: sd_cylinder(p, (0.1, -0.05, 0), 0.4, -0.75, 0.75),
    why='hfCylinderZ 0.4 (z in [-2, 2]) in a box 1.5 high (its longest axis): pi R^2 1.5')
add(name='cut_block_side', file=F, family='cut', cut=True, cut_faces=('x-max',), bounds=(-0.75, -0.5, -0.4, 0.75, 0.5, 0.4),
    volume=1.3 * 0.8 * 0.6, sdf=lambda p: sd_box(p, (-0.55, -0.4, -0.3), (0.75, 0.4, 0.3)),
    why='frBlock x from -0.55 to 1.45 in a box ending at x = 0.75 (its longest axis): 1.3 x 0.8 x 0.6')
add(name='cut_torus_half', file=F, family='cut', cut=True, cut_faces=('z-min',), bounds=(-0.9, -0.9, 0.0, 0.9, 0.9, 0.3),
    volume=PI * PI * 0.6 * 0.2 ** 2, sdf=lambda p: sd_torus_cut_below(p, (0, 0, 0), 0.6, 0.2, 0.0),
    why='hfTorusZ R 0.6 r 0.2 in a box whose bottom z = 0 is its mid-plane: half of 2 pi^2 R r^2')

# --- Primitives, faces on lattice planes ---------------------------------------------------------
F = 'primitives.hf'
_box_case('prim_frblock_lattice', F, 'primitive', (-0.5625, -0.375, -0.25), (0.4375, 0.375, 0.375), 0.0,
          'frBlock 1.0x0.75x0.625, every face on a lattice plane: abc', grids=LATTICE_FINE, bounds=BOX1)
_box_case('prim_hfblock_lattice', F, 'primitive', (-0.25, -0.6875, -0.4375), (0.625, 0.4375, 0.0625), 0.0,
          'hfBlock 0.875x1.125x0.5, every face on a lattice plane: abc', grids=LATTICE, bounds=BOX1)
_box_case('prim_planes_lattice', F, 'primitive', (-0.8125, -0.5, -0.125), (0.3125, 0.5625, 0.75), 0.0,
          'min/max of planes 1.125x1.0625x0.875, every face on a lattice plane: abc', grids=LATTICE, bounds=BOX1)
add(name='prim_cylinder_lattice', file=F, family='primitive', bounds=BOX1, grids=LATTICE,
    bbox=((-0.36, -0.54, -0.5), (0.5, 0.32, 0.625)),
    volume=PI * 0.43 ** 2 * 1.125, sdf=lambda p: sd_cylinder(p, (0.07, -0.11, 0), 0.43, -0.5, 0.625),
    why='hfCylinderZ 0.43 & slab -0.5 <= z <= 0.625 (caps on lattice planes): pi R^2 h')
add(name='prim_block_on_boxface', file=F, family='primitive', bounds=BOX1, grids=LATTICE, cut=True, cut_faces=('x-min',),
    volume=1.25 * 1.0 * 0.75, sdf=lambda p: sd_box(p, (-1.0, -0.5, -0.375), (0.25, 0.5, 0.375)),
    why='frBlock 1.25x1.0x0.75 whose face x = -1 is the grid box face (f = 0 on those grid points): abc')
_ball_case('prim_ball', F, 'primitive', (0.13, -0.07, 0.21), 0.61, 'hfSphere 0.61: 4/3 pi R^3', grids=FINE)
add(name='prim_torus', file=F, family='primitive',
    bbox=((-0.64, -0.62, -0.21), (0.70, 0.72, 0.13)), bounds=pad((-0.64, -0.62, -0.21), (0.70, 0.72, 0.13)),
    volume=2 * PI * PI * 0.5 * 0.17 ** 2, sdf=lambda p: sd_torus(p, (0.03, 0.05, -0.04), 0.5, 0.17),
    why='hfTorusZ R 0.5 r 0.17: 2 pi^2 R r^2', grids=FINE)
_R7, _c7, _s7 = (0.25, 0.6, -0.4), (-0.3, -0.35, -0.2), (0.9, 0.6, 0.45)
_pts7 = np.array([[i * _s7[0], j * _s7[1], k * _s7[2]] for i in (0, 1) for j in (0, 1) for k in (0, 1)]) @ rot_matrix(*_R7).T + _c7
add(name='prim_rotblock', file=F, family='primitive',
    bbox=(tuple(_pts7.min(0)), tuple(_pts7.max(0))), bounds=pad(tuple(_pts7.min(0)), tuple(_pts7.max(0))),
    volume=0.9 * 0.6 * 0.45, sdf=lambda p: sd_rot_block(p, _c7, _s7, _R7),
    why='frBlock 0.9x0.6x0.45 turned by Rz(-0.4)Ry(0.6)Rx(0.25): abc')

BY_NAME = {c.name: c for c in CASES}
assert len(BY_NAME) == len(CASES), 'duplicate case names'
