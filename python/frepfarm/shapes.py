"""Models built by Python calls (docs/python.md, "Building models in Python").

Every Shape is one HyperFun object, and a model is the HyperFun program of the shape and all the
shapes it is made of (each object calls the earlier ones), compiled by frep_lang as a .hf file
would be: the same tape, the same values, the same exact Minkowski paths, and the same errors.
`Shape.hyperfun()` is that program; `Shape.save(path)` writes it for `frep sample|mesh|render`.
Arguments are checked here (ValueError naming the call and the argument); what only the
compiler can judge (an unbounded Minkowski operand, a bad mesh file) raises frepfarm.ModelError
with the compiler's file:line:column in the program, followed by the Python file and line
that made each shape named there.
"""
import math
import os
import re
import sys
import tempfile

from . import frepfarm as _native

_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
_FILE = "<frepfarm.shapes>"


def _caller_site():
    """file:line of the first frame outside this package: where the user made the shape."""
    frame = sys._getframe(1)
    while frame is not None and os.path.dirname(os.path.abspath(frame.f_code.co_filename)) == _PACKAGE_DIR:
        frame = frame.f_back
    return "%s:%d" % (frame.f_code.co_filename, frame.f_lineno) if frame is not None else "?"


def _num(call, what, v, positive=False, nonneg=False):
    try:
        f = float(v)
    except (TypeError, ValueError):
        raise ValueError("%s: %s must be a number, got %r" % (call, what, v)) from None
    if not math.isfinite(f):
        raise ValueError("%s: %s must be finite, got %r" % (call, what, v))
    if positive and not f > 0:
        raise ValueError("%s: %s must be > 0, got %r" % (call, what, v))
    if nonneg and not f >= 0:
        raise ValueError("%s: %s must be >= 0, got %r" % (call, what, v))
    return f


def _vec(call, what, v, n=3, positive=False):
    if isinstance(v, (int, float)):
        v = [v] * n
    try:
        v = list(v)
    except TypeError:
        raise ValueError("%s: %s must be %d numbers, got %r" % (call, what, n, v)) from None
    if len(v) != n:
        raise ValueError("%s: %s must be %d numbers, got %d" % (call, what, n, len(v)))
    return [_num(call, what, e, positive=positive) for e in v]


def _lit(v):
    """A HyperFun number: repr of the double (1e-05, 2.5); negatives as unary minus."""
    s = repr(float(v))
    return "(%s)" % s if s.startswith("-") else s


def _array(name, values):
    return ["array %s[%d];" % (name, len(values)), "%s = [%s];" % (name, ", ".join(_lit(v) for v in values))]


def _shape(call, v, dims=None):
    if not isinstance(v, Shape):
        raise ValueError("%s: expected a frepfarm.shapes.Shape, got %s" % (call, type(v).__name__))
    if dims is not None and v.dims != dims:
        raise ValueError("%s: expected a shape of %d coordinates, got %d (%s)" % (call, dims, v.dims, v.what))
    return v


def _b(shape):
    """A shape's description inside another's, cut short: shared shapes (b | b, repeated) would
    otherwise double it at every level."""
    return shape.what if len(shape.what) <= 48 else shape.what[:45] + "..."


_AXES = {"x": 1, "y": 2, "z": 3, 1: 1, 2: 2, 3: 3}


def _axis(call, axis):
    if isinstance(axis, str):
        axis = axis.lower()
    if axis not in _AXES:
        raise ValueError("%s: axis must be 'x', 'y', 'z' or 1, 2, 3, got %r" % (call, axis))
    return _AXES[axis]


class Shape:
    """One HyperFun object: a field over x[1..dims], inside where f >= 0.

    Operators: a | b (union), a & b (intersection), a - b (difference), ~a (complement), as
    HyperFun's |, &, \\ and ~ (the R-functions with alpha = 0)."""

    def __init__(self, what, dims, children, emit, grid=None):
        self.what = what          # the call that made it, e.g. "ball(1.0)"
        self.dims = dims
        self.site = _caller_site()
        self._children = tuple(children)
        self._emit = emit         # (name, child names, files) -> lines of the object's body
        self._grid = grid         # a pyopenvdb grid that compile() writes to a temporary .vdb
        self._models = {}

    def __repr__(self):
        return "<frepfarm.shapes.Shape %s, x[%d], made at %s>" % (self.what, self.dims, self.site)

    # --- set operations ---------------------------------------------------------------------
    def __or__(self, other):
        return _binary("|", self, other)

    def __and__(self, other):
        return _binary("&", self, other)

    def __sub__(self, other):
        return _binary("\\", self, other)

    def __invert__(self):
        return Shape("~" + _b(self), self.dims, [self], lambda n, k, f: ["%s = ~%s(x, a);" % (n, k[0])])

    # --- transforms (methods return new shapes) ----------------------------------------------
    def translate(self, *v):
        v = _vec("translate", "offset", v[0] if len(v) == 1 else v)
        return _mapped(self, "translate(%s)" % v, ["d = hfShift3D(xt, %s);" % ", ".join(map(_lit, v))])

    def rotate(self, angle, axis="z"):
        """Turns the shape by angle radians about the axis (right-handed) through the origin."""
        ax = _axis("rotate", axis)
        th = _num("rotate", "angle", angle)
        return _mapped(self, "rotate(%r, %r)" % (th, axis), ["d = hfRotate3D%s(xt, %s);" % ("XYZ"[ax - 1], _lit(th))])

    def scale(self, *s):
        """Scales about the origin; the field is multiplied by the smallest factor, so a
        distance field stays 1-Lipschitz (and exact under a uniform scale)."""
        s = _vec("scale", "factor", s[0] if len(s) == 1 else s, positive=True)
        return _mapped(self, "scale(%s)" % s, ["d = hfScale3D(xt, %s);" % ", ".join(map(_lit, s))], factor=min(s))

    def twist(self, angle0, angle1, z0, z1, axis="z"):
        """Turns each cross-section about axis by an angle lerped from angle0 at z0 to angle1 at z1."""
        ax = _axis("twist", axis)
        v = [_num("twist", n, e) for n, e in (("z0", z0), ("z1", z1), ("angle0", angle0), ("angle1", angle1))]
        if v[0] == v[1]:
            raise ValueError("twist: z0 and z1 must differ")
        return _mapped(self, "twist", ["d = frTwist(xt, %d, %s);" % (ax, ", ".join(map(_lit, v)))])

    def taper(self, scale0, scale1, z0, z1, axis="z"):
        """Scales the cross-sections by scale0 below z0 ... scale1 above z1 (linear between)."""
        ax = _axis("taper", axis)
        v = [_num("taper", "z0", z0), _num("taper", "z1", z1),
             _num("taper", "scale0", scale0, positive=True), _num("taper", "scale1", scale1, positive=True)]
        if v[0] == v[1]:
            raise ValueError("taper: z0 and z1 must differ")
        return _mapped(self, "taper", ["d = frTaper(xt, %d, %s);" % (ax, ", ".join(map(_lit, v)))])

    # --- what a shape compiles to -----------------------------------------------------------
    def hyperfun(self, name="my_model"):
        """The HyperFun program: one object per shape, the last one named `name`."""
        return _program(self, name, {})[0]

    def save(self, path, name="my_model"):
        """Writes the program as a .hf file (frep sample/mesh/render read it as any model).
        A volume() made from a pyopenvdb grid has no file: save that grid first and use volume(path)."""
        if any(s._grid is not None for s in _topological(self)):
            raise ValueError("save: the model holds a pyopenvdb grid; write it with pyopenvdb.write and use volume(path)")
        text = self.hyperfun(name)
        tmp = "%s.tmp%d" % (path, os.getpid())
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, path)

    def compile(self, iso=0.0):
        """The frepfarm.Model of this shape (cached): f - iso."""
        key = float(iso)
        if key not in self._models:
            self._models[key] = _compile(self, key)
        return self._models[key]

    # The Model's calls (docs/python.md), on the compiled shape; keywords pass through.
    def eval(self, points, **kw):
        return self.compile().eval(points, **kw)

    def sample(self, lo, hi, **kw):
        return self.compile().sample(lo, hi, **kw)

    def mesh(self, lo, hi, **kw):
        return self.compile().mesh(lo, hi, **kw)

    def measure(self, lo=(-10,) * 3, hi=(10,) * 3, **kw):
        return self.compile().measure(lo, hi, **kw)

    def grid(self, lo, hi, res=64, fixed=()):
        from .grids import dense_grid
        return dense_grid(self.compile(), lo, hi, res=res, fixed=fixed)

    def to_pyopenvdb(self, lo, hi, **kw):
        """The sampled level set (sample's keywords) as a pyopenvdb.FloatGrid."""
        return self.sample(lo, hi, **kw).to_pyopenvdb()


def _binary(op, a, b):
    if not isinstance(b, Shape):
        return NotImplemented
    call = {"|": "union", "&": "intersection", "\\": "difference"}[op]
    if a.dims != b.dims:
        raise ValueError("%s: shapes of %d and %d coordinates (%s, %s)" % (call, a.dims, b.dims, a.what, b.what))
    return Shape("(%s %s %s)" % (_b(a), op, _b(b)), a.dims, [a, b],
                 lambda n, k, f: ["%s = %s(x, a) %s %s(x, a);" % (n, k[0], op, k[1])])


def _mapped(child, what, lines, factor=1.0):
    """child read through moved coordinates xt (a copy of x that the hf* call changes)."""
    if child.dims < 3:
        raise ValueError("%s: needs a shape of 3 or more coordinates, got %d" % (what, child.dims))
    n = child.dims
    copy = _array("xt", [0] * n)[:1] + ["xt = [%s];" % ", ".join("x[%d]" % (i + 1) for i in range(n))]
    scale = "" if factor == 1.0 else "%s * " % _lit(factor)

    def emit(name, kids, files):
        return copy + lines + ["%s = %s%s(xt, a);" % (name, scale, kids[0])]
    return Shape("%s.%s" % (_b(child), what), n, [child], emit)


# --- primitives -----------------------------------------------------------------------------

def ball(radius, center=(0, 0, 0)):
    """Solid ball; f = radius - |x - center| (frBall: the exact signed distance)."""
    r = _num("ball", "radius", radius, nonneg=True)
    c = _vec("ball", "center", center)
    return Shape("ball(%r)" % r, 3, [], lambda n, k, f: _array("c", c) + ["%s = frBall(x, %s, c);" % (n, _lit(r))])


def box(size, center=(0, 0, 0)):
    """Axis-aligned box of edges size (3 numbers or one) around center (frBlock: exact distance)."""
    s = _vec("box", "size", size, positive=True)
    c = _vec("box", "center", center)
    corner = [c[i] - s[i] / 2 for i in range(3)]
    return Shape("box(%s)" % s, 3, [],
                 lambda n, k, f: _array("c", corner) + ["%s = frBlock(x, %s, c);" % (n, ", ".join(map(_lit, s)))])


def cylinder(radius, axis="z", center=(0, 0, 0), length=None):
    """Cylinder about an axis through center (hfCylinderX/Y/Z: R^2 - u^2 - v^2); infinite, or
    cut to length (centred) by a slab."""
    ax = _axis("cylinder", axis)
    r = _num("cylinder", "radius", radius, positive=True)
    c = _vec("cylinder", "center", center)
    body = ["%%s = hfCylinder%s(x, c, %s)" % ("XYZ"[ax - 1], _lit(r))]
    if length is not None:
        h = _num("cylinder", "length", length, positive=True) / 2
        body[0] += " & (%s - abs(x[%d] - %s))" % (_lit(h), ax, _lit(c[ax - 1]))
    return Shape("cylinder(%r)" % r, 3, [], lambda n, k, f: _array("c", c) + [body[0] % n + ";"])


def torus(major, minor, axis="z", center=(0, 0, 0)):
    """Torus around an axis (hfTorusX/Y/Z); a ring torus needs major >= minor > 0."""
    ax = _axis("torus", axis)
    R = _num("torus", "major", major, positive=True)
    r0 = _num("torus", "minor", minor, positive=True)
    c = _vec("torus", "center", center)
    return Shape("torus(%r, %r)" % (R, r0), 3, [], lambda n, k, f: _array("c", c) + [
        "%s = hfTorus%s(x, c, %s, %s);" % (n, "XYZ"[ax - 1], _lit(R), _lit(r0))])


def ellipsoid(semi_axes, center=(0, 0, 0)):
    """Ellipsoid with semi-axes (a, b, c): the signed Euclidean distance (hfDEllipsoid)."""
    s = _vec("ellipsoid", "semi_axes", semi_axes, positive=True)
    c = _vec("ellipsoid", "center", center)
    return Shape("ellipsoid(%s)" % s, 3, [], lambda n, k, f: _array("c", c) + [
        "%s = hfDEllipsoid(x, c, %s);" % (n, ", ".join(map(_lit, s)))])


def half_space(normal, point=(0, 0, 0)):
    """{x : normal . (x - point) <= 0}, f = normal . (point - x) / |normal| (a distance). An
    intersection of half-spaces is a convex polytope, which Minkowski operations treat exactly."""
    nv = _vec("half_space", "normal", normal)
    p = _vec("half_space", "point", point)
    length = math.sqrt(sum(e * e for e in nv))
    if length == 0:
        raise ValueError("half_space: normal must not be zero")
    u = [e / length for e in nv]
    d = sum(u[i] * p[i] for i in range(3))
    terms = " - ".join("%s * x[%d]" % (_lit(u[i]), i + 1) for i in range(3))
    return Shape("half_space(%s)" % nv, 3, [], lambda n, k, f: ["%s = %s - %s;" % (n, _lit(d), terms)])


def segment(length, axis="x", start=(0, 0, 0)):
    """Segment from start along an axis (frXLine ...): f = minus the distance to it (no interior;
    as a Minkowski operand it sweeps the other operand along it)."""
    ax = _axis("segment", axis)
    L = _num("segment", "length", length)
    c = _vec("segment", "start", start)
    return Shape("segment(%r)" % L, 3, [], lambda n, k, f: _array("c", c) + [
        "%s = fr%sLine(x, %s, c);" % (n, "XYZ"[ax - 1], _lit(L))])


def disc(radius, axis="z", center=(0, 0, 0)):
    """Flat disc normal to an axis (frXDisc ...): f = minus the distance to it."""
    ax = _axis("disc", axis)
    r = _num("disc", "radius", radius, nonneg=True)
    c = _vec("disc", "center", center)
    return Shape("disc(%r)" % r, 3, [], lambda n, k, f: _array("c", c) + [
        "%s = fr%sDisc(x, %s, c);" % (n, "XYZ"[ax - 1], _lit(r))])


def _path_literal(call, path):
    path = os.path.abspath(os.fspath(path))
    if '"' in path or "\n" in path:
        raise ValueError("%s: the path %r holds a quote or a newline, which HyperFun strings cannot" % (call, path))
    return '"%s"' % path


def mesh(path):
    """A closed triangle mesh file (.stl, .obj, .ply) as its exact signed distance (frMesh)."""
    lit = _path_literal("mesh", path)
    return Shape("mesh(%s)" % lit, 3, [], lambda n, k, f: ["%s = frMesh(x, %s);" % (n, lit)])


def volume(source, grid_name=None):
    """A float grid as a field (frVolume: trilinear; level sets are negative inside, so f = -value):
    a .vdb path (grid_name: which grid, default the first float grid) or a pyopenvdb.FloatGrid."""
    if isinstance(source, (str, bytes, os.PathLike)):
        lit = _path_literal("volume", source)
        if grid_name is not None and (not isinstance(grid_name, str) or '"' in grid_name or "\n" in grid_name):
            raise ValueError("volume: grid_name must be a string without quotes or newlines, got %r" % (grid_name,))
        name = "" if grid_name is None else ', "%s"' % grid_name
        return Shape("volume(%s)" % lit, 3, [], lambda n, k, f: ["%s = frVolume(x, %s%s);" % (n, lit, name)])
    if not hasattr(source, "gridClass") or not hasattr(source, "copyFromArray"):
        raise ValueError("volume: expected a .vdb path or a pyopenvdb grid, got %s" % type(source).__name__)
    grid = source

    def emit(name, kids, files):
        return ["%s = frVolume(x, %s);" % (name, _path_literal("volume", files[id(grid)]))]
    return Shape("volume(<pyopenvdb %s>)" % type(grid).__name__, 3, [], emit, grid=grid)


def formula(expression, dims=3):
    """Any HyperFun expression in x[1] ... x[dims] (and the library functions): f itself."""
    if not isinstance(expression, str) or not expression.strip() or ";" in expression:
        raise ValueError("formula: expected one HyperFun expression without ';', got %r" % (expression,))
    if dims not in range(1, 11):
        raise ValueError("formula: dims must be 1 to 10, got %r" % (dims,))
    return Shape("formula(%r)" % expression, dims, [], lambda n, k, f: ["%s = %s;" % (n, expression)])


# --- blends, offsets, morphs ------------------------------------------------------------------

def _fn2(call, fn, a, b, *params):
    a, b = _shape(call, a), _shape(call, b, a.dims)
    p = ", ".join(_lit(v) for v in params)
    return Shape("%s(%s, %s)" % (call, _b(a), _b(b)), a.dims, [a, b],
                 lambda n, k, f: ["%s = %s(%s(x, a), %s(x, a), %s);" % (n, fn, k[0], k[1], p)])


def union(a, b, alpha=0.0):
    """R-function union with parameter alpha in (-1, 1]: 1 gives max (frUnion)."""
    return _fn2("union", "frUnion", a, b, _alpha("union", alpha))


def intersection(a, b, alpha=0.0):
    return _fn2("intersection", "frIntersection", a, b, _alpha("intersection", alpha))


def difference(a, b, alpha=0.0):
    return _fn2("difference", "frSubtraction", a, b, _alpha("difference", alpha))


def _alpha(call, alpha):
    v = _num(call, "alpha", alpha)
    if not -1 < v <= 1:
        raise ValueError("%s: alpha must be in (-1, 1], got %r" % (call, alpha))
    return v


def blend_union(a, b, amount, width_a=1.0, width_b=1.0):
    """Union plus a blend bump amount / (1 + (fa/width_a)^2 + (fb/width_b)^2) (frBlendUnion)."""
    return _fn2("blend_union", "frBlendUnion", a, b, _num("blend_union", "amount", amount),
                _num("blend_union", "width_a", width_a, positive=True),
                _num("blend_union", "width_b", width_b, positive=True))


def blend_intersection(a, b, amount, width_a=1.0, width_b=1.0):
    return _fn2("blend_intersection", "frBlendIntersection", a, b, _num("blend_intersection", "amount", amount),
                _num("blend_intersection", "width_a", width_a, positive=True),
                _num("blend_intersection", "width_b", width_b, positive=True))


def smooth_union(a, b, m=1):
    """C^m R-union (frUnionSmooth)."""
    return _fn2("smooth_union", "frUnionSmooth", a, b, _num("smooth_union", "m", m, nonneg=True))


def morph(a, b, t):
    """Metamorphosis f_a (1 - t) + f_b t (frMorph)."""
    return _fn2("morph", "frMorph", a, b, _num("morph", "t", t))


def offset(shape, amount):
    """f + amount (frOffset): a uniform offset for a distance field."""
    s = _shape("offset", shape)
    v = _num("offset", "amount", amount)
    return Shape("offset(%s, %r)" % (_b(s), v), s.dims, [s],
                 lambda n, k, f: ["%s = frOffset(%s(x, a), %s);" % (n, k[0], _lit(v))])


def offset_normal(shape, distance):
    """f(x + d grad f / |grad f|) (frOffsetNormal): d > 0 grows the solid."""
    s = _shape("offset_normal", shape)
    v = _num("offset_normal", "distance", distance)
    return Shape("offset_normal(%s, %r)" % (_b(s), v), s.dims, [s],
                 lambda n, k, f: ["%s = frOffsetNormal(%s(x, a), %s);" % (n, k[0], _lit(v))])


def offset_radius(shape, radius):
    """Constant-radius offset (frOffsetR): r > 0 dilates by a ball of radius r, r < 0 erodes."""
    s = _shape("offset_radius", shape)
    r = _num("offset_radius", "radius", radius)
    return Shape("offset_radius(%s, %r)" % (_b(s), r), s.dims, [s],
                 lambda n, k, f: ["%s = frOffsetR(x, %s, %s);" % (n, k[0], _lit(r))])


# --- operations on whole objects: Minkowski, projection, sweep ----------------------------------

def _options(call, method, tol, box, k):
    """The trailing options array [method, tol, lo1, hi1, ...] of the extremum calls."""
    if method is None and tol is None and box is None:
        return []
    o = [_num(call, "method", 0 if method is None else method), _num(call, "tol", 0 if tol is None else tol, nonneg=True)]
    if o[0] not in (0, 1, 2):
        raise ValueError("%s: method must be 0 (branch and bound), 1 (grid) or 2 (sampled operand), got %r" % (call, method))
    if box is not None:
        lo, hi = box
        lo, hi = _vec(call, "box lo", lo, k), _vec(call, "box hi", hi, k)
        for i in range(k):
            if not hi[i] > lo[i]:
                raise ValueError("%s: box hi must exceed lo on every axis" % call)
            o += [lo[i], hi[i]]
    return o


def _object_call(call, fn, shapes, dims, before=(), after=(), options=()):
    """name = fn(x, before..., A, B, ..., after... [, o]): the operands are objects, not values."""
    def emit(name, kids, files):
        lines = _array("o", options) if options else []
        args = ["x"] + list(before) + list(kids) + list(after) + (["o"] if options else [])
        return lines + ["%s = %s(%s);" % (name, fn, ", ".join(args))]
    return Shape("%s(%s)" % (call, ", ".join(_b(s) for s in shapes)), dims, shapes, emit)


def minkowski_sum(a, b, *more, method=None, tol=None, box=None):
    """A ⊕ B (⊕ C ...): exact for balls, boxes, discs, segments, meshes and convex polytopes
    (docs/language.md), else a certified search (method 0), a grid (1) or a sampled operand (2);
    box: (lo, hi) of the searched operand."""
    shapes = [_shape("minkowski_sum", a)] + [_shape("minkowski_sum", s, a.dims) for s in (b,) + more]
    o = _options("minkowski_sum", method, tol, box, a.dims)
    fn = "frMinkowski" if len(shapes) == 2 else "frMinkowskiSum"
    return _object_call("minkowski_sum", fn, shapes, a.dims, options=o)


def minkowski_diff(a, b, method=None, tol=None, box=None):
    """A ⊖ B = {x : x + B ⊂ A} (frMinkowskiDiff)."""
    a, b = _shape("minkowski_diff", a), _shape("minkowski_diff", b, a.dims)
    o = _options("minkowski_diff", method, tol, box, a.dims)
    return _object_call("minkowski_diff", "frMinkowskiDiff", [a, b], a.dims, options=o)


def minkowski_morph(a, b, t, method=None, tol=None, box=None):
    """((1 - t) A) ⊕ (t B), t in [0, 1] (frMorphMinkowski)."""
    a, b = _shape("minkowski_morph", a), _shape("minkowski_morph", b, a.dims)
    tv = _num("minkowski_morph", "t", t)
    if not 0 <= tv <= 1:
        raise ValueError("minkowski_morph: t must be in [0, 1], got %r" % (t,))
    o = _options("minkowski_morph", method, tol, box, a.dims)
    return _object_call("minkowski_morph", "frMorphMinkowski", [a, b], a.dims, after=[_lit(tv)], options=o)


def project(shape, *axes, method=None, tol=None, box=None):
    """Projection along coordinates (1-based, e.g. 4 for x[4]): max of f over them (frProject).
    The result has dims - len(axes) coordinates, the others in order."""
    s = _shape("project", shape)
    if not axes:
        raise ValueError("project: give at least one coordinate to project along")
    for ax in axes:
        if not isinstance(ax, int) or not 1 <= ax <= s.dims or list(axes).count(ax) > 1:
            raise ValueError("project: coordinates must be distinct whole numbers 1 to %d, got %r" % (s.dims, axes))
    if len(axes) >= s.dims:
        raise ValueError("project: projecting along every coordinate leaves none")
    o = _options("project", method, tol, box, len(axes))
    return _object_call("project", "frProject", [s], s.dims - len(axes), after=[str(a) for a in axes], options=o)


def sweep(shape, times, positions, angles=None, method=None, tol=None):
    """The shape moved through keyframes (frSweepKeys): at times[i] (increasing) it is translated
    by positions[i] (and turned by angles[i] = (rx, ry, rz) radians); piecewise linear between.
    A shape of dims + 1 coordinates is time-varying (its last coordinate is the time)."""
    s = _shape("sweep", shape)
    n = s.dims if s.dims == 3 else s.dims - 1
    if n != 3:
        raise ValueError("sweep: expected a 3D shape (or 4D, time-varying), got %d coordinates" % s.dims)
    ts = [_num("sweep", "times", t) for t in times]
    if len(ts) < 2 or any(ts[i + 1] <= ts[i] for i in range(len(ts) - 1)):
        raise ValueError("sweep: times must be 2 or more strictly increasing numbers, got %r" % (times,))
    if len(positions) != len(ts):
        raise ValueError("sweep: %d times but %d positions" % (len(ts), len(positions)))
    ps = [e for p in positions for e in _vec("sweep", "position", p)]
    rs = None
    if angles is not None:
        if len(angles) != len(ts):
            raise ValueError("sweep: %d times but %d angles" % (len(ts), len(angles)))
        rs = [e for r in angles for e in _vec("sweep", "angles", r)]
    o = _options("sweep", method, tol, None, 0)

    def emit(name, kids, files):
        lines = _array("ts", ts) + _array("ps", ps) + (_array("rs", rs) if rs else []) + (_array("o", o) if o else [])
        args = ["x", kids[0], "ts", "ps"] + (["rs"] if rs else []) + (["o"] if o else [])
        return lines + ["%s = frSweepKeys(%s);" % (name, ", ".join(args))]
    return Shape("sweep(%s)" % _b(s), 3, [s], emit)


# --- compiling ----------------------------------------------------------------------------------

def _topological(root):
    order, seen, stack = [], set(), [(root, False)]
    while stack:
        node, done = stack.pop()
        if done:
            order.append(node)
            continue
        if id(node) in seen:
            continue
        seen.add(id(node))
        stack.append((node, True))
        for c in reversed(node._children):
            if id(c) not in seen:
                stack.append((c, False))
    return order


def _program(root, name, files):
    """(text, [(first line, last line, shape, object name)]) of the program for root."""
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
        raise ValueError("name: expected a HyperFun name, got %r" % (name,))
    order = _topological(root)
    names = {id(s): "shape%d" % (i + 1) for i, s in enumerate(order)}
    names[id(root)] = name
    lines, spans = [], []
    for s in order:
        obj = names[id(s)]
        first = len(lines) + 1
        lines.append("-- %s, made at %s" % (s.what[:200].replace("\n", " "), s.site))
        lines.append("%s(x[%d], a[1])" % (obj, s.dims))
        lines.append("{")
        body = s._emit(obj, [names[id(c)] for c in s._children], files)
        # HyperFun wants every array declaration before the statements.
        lines += ["  " + ln for ln in body if ln.startswith("array ")]
        lines += ["  " + ln for ln in body if not ln.startswith("array ")]
        lines.append("}")
        spans.append((first, len(lines), s, obj))
    return "\n".join(lines) + "\n", spans


def _explain(message, spans):
    """The compiler's diagnostics, each (with its source line and caret) followed by the Python
    sites of the shape whose object holds it and of the shapes it names."""
    by_name = {obj.lower(): (s, obj) for _, _, s, obj in spans}
    out, notes = [], []
    for line in message.split("\n"):
        m = re.match(re.escape(_FILE) + r":(\d+):\d+: ", line)
        if m:
            out += notes
            row = int(m.group(1))
            owner = [(s, obj) for first, last, s, obj in spans if first <= row <= last]
            named = [by_name[w.lower()] for w in re.findall(r"'(\w+)'", line) if w.lower() in by_name]
            notes = ["  %s: %s, made at %s" % (obj, s.what[:200], s.site)
                     for s, obj in owner + [n for n in named if n not in owner]]
        out.append(line)
    return "\n".join(out + notes)


def _compile(root, iso):
    grids = [s._grid for s in _topological(root) if s._grid is not None]
    with tempfile.TemporaryDirectory(prefix="frepfarm-shapes-") as tmp:
        files = {}
        if grids:
            import pyopenvdb
            for i, g in enumerate(grids):
                if id(g) in files:
                    continue  # one grid in several volume() shapes
                path = files[id(g)] = os.path.join(tmp, "grid%d.vdb" % i)
                if "frep_grid_checksum" in g:
                    # The checksum is of the bytes frep wrote; pyopenvdb writes other bytes, so
                    # frep would read the grid as rewritten by a foreign tool (with a warning).
                    g = g.deepCopy()
                    del g["frep_grid_checksum"]
                pyopenvdb.write(path, grids=[g])
        text, spans = _program(root, "my_model", files)
        try:
            # frVolume reads the file's bytes here, once: the model keeps the grid.
            return _native.compile(text, file=_FILE, object="my_model", iso=iso)
        except _native.ModelError as e:
            raise _native.ModelError(_explain(str(e), spans)) from None
