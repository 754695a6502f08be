"""frepfarm.shapes (models built by Python calls) against closed forms: ball, box and set
operation values, transforms, offsets, a projection and a sweep, Minkowski sums against
Steiner's formula through the certified measure, the same values as the .hf file it writes,
errors that name the Python line, NumPy grids and pyopenvdb grids in and out."""
import inspect
import math
import os

import numpy as np
import pytest

import frepfarm
from frepfarm import shapes as fs

RNG = np.random.default_rng(32)
PTS = RNG.uniform(-2, 2, (500, 3))


def norm(p):
    return np.sqrt(np.sum(np.asarray(p) ** 2, axis=1))


def box_distance(p, half):
    """Signed distance to the box [-half, half], positive inside (exact)."""
    q = np.abs(p) - np.asarray(half)
    outside = np.sqrt(np.sum(np.maximum(q, 0) ** 2, axis=1))
    inside = np.minimum(np.max(q, axis=1), 0)
    return -(outside + inside)


# --- values against closed forms --------------------------------------------------------------

def test_ball_is_its_signed_distance():
    c = np.array([0.25, -0.5, 1.0])
    got = fs.ball(1.25, center=c).eval(PTS)
    np.testing.assert_allclose(got, 1.25 - norm(PTS - c), rtol=0, atol=1e-12)


def test_box_is_its_signed_distance():
    got = fs.box((1, 2, 3), center=(0.5, 0, 0)).eval(PTS)
    np.testing.assert_allclose(got, box_distance(PTS - [0.5, 0, 0], [0.5, 1, 1.5]), rtol=0, atol=1e-12)


@pytest.mark.parametrize("op,formula", [
    ("|", lambda a, b: a + b + np.sqrt(a * a + b * b)),
    ("&", lambda a, b: a + b - np.sqrt(a * a + b * b)),
    ("-", lambda a, b: a - b - np.sqrt(a * a + b * b)),
])
def test_set_operations_are_hyperfuns_r_functions(op, formula):
    a, b = fs.ball(1), fs.ball(0.75, center=(1, 0, 0))
    shape = {"|": a | b, "&": a & b, "-": a - b}[op]
    fa, fb = 1 - norm(PTS), 0.75 - norm(PTS - [1, 0, 0])
    np.testing.assert_allclose(shape.eval(PTS), formula(fa, fb), rtol=1e-12, atol=1e-12)


def test_max_union_blend_and_complement():
    a, b = fs.ball(1), fs.ball(0.75, center=(1, 0, 0))
    fa, fb = 1 - norm(PTS), 0.75 - norm(PTS - [1, 0, 0])
    np.testing.assert_allclose(fs.union(a, b, alpha=1).eval(PTS), np.maximum(fa, fb), atol=1e-12)
    np.testing.assert_allclose(fs.intersection(a, b, alpha=1).eval(PTS), np.minimum(fa, fb), atol=1e-12)
    blend = fa + fb + np.sqrt(fa ** 2 + fb ** 2) + 0.5 / (1 + (fa / 0.4) ** 2 + (fb / 0.3) ** 2)
    np.testing.assert_allclose(fs.blend_union(a, b, 0.5, 0.4, 0.3).eval(PTS), blend, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose((~a).eval(PTS), -fa, atol=1e-12)


def test_transforms_move_the_solid():
    p = PTS
    moved = fs.ball(1).translate(1, 2, 3).eval(p + [1, 2, 3])
    np.testing.assert_allclose(moved, 1 - norm(p), atol=1e-12)
    # A box along x turned by 90 degrees about z lies along y (right-handed).
    turned = fs.box((2, 0.5, 0.5)).rotate(math.pi / 2, "z").eval(p)
    np.testing.assert_allclose(turned, box_distance(p, [0.25, 1, 0.25]), atol=1e-12)
    # Uniform scale: the field is scaled too, so it stays the distance.
    np.testing.assert_allclose(fs.ball(0.5).scale(3).eval(p), 1.5 - norm(p), atol=1e-12)


def test_offsets():
    b = fs.ball(1)
    np.testing.assert_allclose(fs.offset(b, 0.25).eval(PTS), 1.25 - norm(PTS), atol=1e-12)
    away = PTS[norm(PTS) > 0.2]  # the normal is undefined at the centre
    np.testing.assert_allclose(fs.offset_normal(b, 0.25).eval(away), 1.25 - norm(away), atol=1e-9)
    # frOffsetR of a ball is a ball: max of f over a ball of radius r, certified to 1e-3.
    np.testing.assert_allclose(fs.offset_radius(b, 0.25).eval(PTS[:50]), 1.25 - norm(PTS[:50]), atol=2e-3)


def test_projection_of_a_4d_ball():
    ball4 = fs.formula("1 - x[1]^2 - x[2]^2 - x[3]^2 - x[4]^2", dims=4)
    p = fs.project(ball4, 4)
    assert p.dims == 3
    q = PTS[:40] / 2
    np.testing.assert_allclose(p.eval(q), 1 - np.sum(q ** 2, axis=1), atol=2e-3)


def test_sweep_of_a_ball_is_a_capsule():
    s = fs.sweep(fs.ball(0.25), [0, 1], [(0, 0, 0), (2, 0, 0)])
    q = PTS[:60]
    along = np.clip(q[:, 0], 0, 2)
    capsule = 0.25 - norm(q - np.stack([along, 0 * along, 0 * along], axis=1))
    np.testing.assert_allclose(s.eval(q), capsule, atol=2e-3)


def steiner_box_ball(a, b, c, r):
    """Volume of box(a, b, c) ⊕ ball(r): V + S r + (π/4 Σ edges) r² + 4/3 π r³ (Steiner)."""
    return a * b * c + 2 * (a * b + b * c + c * a) * r + math.pi * (a + b + c) * r * r + 4 / 3 * math.pi * r ** 3


def test_minkowski_sum_of_box_and_ball_matches_steiner():
    s = fs.minkowski_sum(fs.box((1, 2, 3)), fs.ball(0.25))
    m = s.measure(lo=(-2,) * 3, hi=(2,) * 3, tolerance=0.005)
    exact = steiner_box_ball(1, 2, 3, 0.25)
    assert m["volume"]["lower"] <= exact <= m["volume"]["upper"]
    assert m["tolerance_reached"] and m["volume"]["upper"] - m["volume"]["lower"] <= 0.005 * exact * 1.01
    # Exact algebra (no search): outside, the field is the distance to the rounded box.
    q = np.array([[0.5 + 0.25 + 0.1, 0, 0], [0, 1 + 0.25 + 0.3, 0], [0.5, 1, 1.5 + 0.25 + 0.2]])
    np.testing.assert_allclose(s.eval(q), [-0.1, -0.3, -0.2], atol=1e-12)


def test_minkowski_difference_shrinks_the_box():
    s = fs.minkowski_diff(fs.box((1, 2, 3)), fs.ball(0.25))
    inside = PTS[np.all(np.abs(PTS) < [0.25, 0.75, 1.25], axis=1)]
    np.testing.assert_allclose(s.eval(inside), box_distance(inside, [0.25, 0.75, 1.25]), atol=1e-12)


# --- the same model as a .hf file -------------------------------------------------------------

def test_shape_and_its_hf_file_give_the_same_bits(tmp_path):
    s = fs.minkowski_sum(fs.box((1, 0.5, 0.5)), fs.ball(0.2)).rotate(0.3, "x") | fs.torus(1, 0.2).translate(0, 0, 1)
    path = tmp_path / "model.hf"
    s.save(str(path))
    from_file = frepfarm.load(str(path))
    assert from_file.name == "my_model"
    assert np.array_equal(from_file.eval(PTS), s.eval(PTS))
    assert np.array_equal(frepfarm.compile(s.hyperfun()).eval(PTS), s.eval(PTS))


def test_shared_operands_are_one_object():
    b = fs.ball(1)
    text = ((b | b.translate(1, 0, 0)) & b).hyperfun()
    assert text.count("frBall") == 1
    # Reused on both sides 40 times: the ball, 40 moves and 40 unions, descriptions kept short.
    s = b
    for _ in range(40):
        s = s | s.translate(0.01, 0, 0)
    assert s.hyperfun().count("(x[3], a[1])") == 81 and len(s.what) < 120


# --- errors ----------------------------------------------------------------------------------

def test_bad_arguments_name_the_call():
    with pytest.raises(ValueError, match=r"^ball: radius must be >= 0"):
        fs.ball(-1)
    with pytest.raises(ValueError, match=r"^box: size must be 3 numbers"):
        fs.box((1, 2))
    with pytest.raises(ValueError, match=r"^union: shapes of 3 and 4 coordinates"):
        fs.ball(1) | fs.formula("x[4]", dims=4)
    with pytest.raises(ValueError, match=r"^sweep: times must be 2 or more strictly increasing"):
        fs.sweep(fs.ball(1), [0, 0], [(0, 0, 0), (1, 0, 0)])
    with pytest.raises(ValueError, match=r"^rotate: axis must be"):
        fs.ball(1).rotate(1, "w")


def test_compiler_errors_name_the_python_line():
    line = inspect.currentframe().f_lineno + 1
    bad = fs.formula("1 - x[1]^2 +")
    with pytest.raises(frepfarm.ModelError) as e:
        bad.compile()
    msg = str(e.value)
    assert msg.startswith("<frepfarm.shapes>:4:26: error: expected an expression, found ';'")
    assert "made at %s:%d" % (__file__, line) in msg


def test_unbounded_minkowski_operand_names_its_python_line():
    line = inspect.currentframe().f_lineno + 1
    slab = fs.formula("1 - x[1]^2 - x[2]^2")  # an infinite cylinder, no closed form
    with pytest.raises(frepfarm.ModelError) as e:
        fs.minkowski_sum(fs.ball(1), slab).compile()
    msg = str(e.value)
    assert "is not bounded within ±1000 (along x[3])" in msg
    assert "shape2: formula('1 - x[1]^2 - x[2]^2'), made at %s:%d" % (__file__, line) in msg


def test_missing_mesh_file_names_the_path_and_the_python_line():
    line = inspect.currentframe().f_lineno + 1
    part = fs.mesh("/nonexistent/part.stl") | fs.ball(1)
    with pytest.raises(frepfarm.ModelError) as e:
        part.compile()
    msg = str(e.value)
    assert "error: cannot open file '/nonexistent/part.stl' (No such file or directory)" in msg
    assert 'shape1: mesh("/nonexistent/part.stl"), made at %s:%d' % (__file__, line) in msg


# --- NumPy and pyopenvdb grids ------------------------------------------------------------------

def test_dense_grid_values_and_points():
    g = fs.ball(1).grid((-1, -1, -0.5), (1, 1, 0.5), res=21)
    assert g.values.shape == (21, 21, 11) and g.voxel == pytest.approx(0.1)
    pts = g.points().reshape(-1, 3)
    np.testing.assert_allclose(g.values.ravel(), 1 - norm(pts), atol=1e-12)
    assert g.inside_volume() == np.count_nonzero(1 - norm(pts) >= 0) * g.voxel ** 3


def test_dense_grid_of_a_4d_model_takes_fixed_coordinates():
    m = frepfarm.compile("my_model(x[4], a[1]) { my_model = 1 - x[1]^2 - x[2]^2 - x[3]^2 - x[4]^2; }")
    from frepfarm.grids import dense_grid
    g = dense_grid(m, (-1,) * 3, (1,) * 3, res=5, fixed=[0.5])
    pts = g.points().reshape(-1, 3)
    np.testing.assert_allclose(g.values.ravel(), 0.75 - np.sum(pts ** 2, axis=1), atol=1e-12)
    with pytest.raises(ValueError, match="fixed"):
        dense_grid(m, (-1,) * 3, (1,) * 3, res=5)


def test_pyopenvdb_level_set_as_a_primitive(tmp_path):
    vdb = pytest.importorskip("pyopenvdb")
    g = vdb.createLevelSetSphere(radius=1.0, center=(0, 0, 0), voxelSize=0.05, halfWidth=3.0)
    v = fs.volume(g)
    # Level sets are negative inside: f = -value; beyond the band the background (0.15).
    got = v.eval([[0, 0, 0], [0.95, 0, 0], [1.05, 0, 0], [3, 0, 0]])
    np.testing.assert_allclose(got, [0.15, 0.05, -0.05, -0.15], atol=1e-6)
    assert not [n for n in os.listdir(os.environ.get("TMPDIR", "/tmp")) if n.startswith("frepfarm-shapes-")]
    # Composes like any shape: cut by a half-space.
    cut = v & fs.half_space((1, 0, 0))
    assert cut.eval([[0.5, 0, 0]])[0] < 0 < cut.eval([[-0.9, 0, 0]])[0]
    # No file holds the grid: a .hf of it could not be read back.
    with pytest.raises(ValueError, match="^save: the model holds a pyopenvdb grid"):
        cut.save(str(tmp_path / "cut.hf"))
    assert not os.listdir(tmp_path)


def test_pyopenvdb_round_trip_keeps_the_surface():
    pytest.importorskip("pyopenvdb")
    shape = fs.ball(1) - fs.box(1).translate(1, 0, 0)
    grid = shape.to_pyopenvdb((-1.2,) * 3, (1.2,) * 3, res=64)
    assert grid.gridClass == "level set" and "frep_grid_checksum" in grid
    back = fs.volume(grid)
    a, b = shape.eval(PTS / 1.8), back.eval(PTS / 1.8)
    near = np.abs(a) < 0.05
    voxel = grid.transform.voxelSize()[0]
    assert near.sum() > 20 and np.max(np.abs(a[near] - b[near])) < voxel
    far = np.abs(a) > 2 * voxel
    assert np.array_equal(np.sign(a[far]), np.sign(b[far]))
    assert "frep_grid_checksum" in grid  # the caller's grid is left as it was
