"""The Python module frepfarm (python/frepfarm_module.cpp) against exact answers: values of a
sphere, lattice volumes counted by NumPy, the .vdb read back by OpenVDB's own Python module,
closed and consistently oriented meshes, a block meshed to its 12 exact triangles."""
import math
import os

import numpy as np
import pytest

import frepfarm

SPHERE = "my_model(x[3], a[1]) { my_model = a[1]^2 - x[1]^2 - x[2]^2 - x[3]^2; }"
R = 0.93  # R^2 = 0.8649 is no sum of squares of lattice coordinates k/10 or k*0.075: no f = 0
BLOCK = """my_model(x[3], a[1]) {
  array corner[3];
  corner = [-0.5, -0.25, -0.75];
  my_model = hfBlock(x, corner, 1, 0.5, 1.5);
}"""


def sphere(r=R):
    return frepfarm.compile(SPHERE, file="sphere.hf", params=[r])


def exact_sphere(p, r=R):
    p = np.asarray(p, dtype=np.float64)
    return r * r - p[:, 0] ** 2 - p[:, 1] ** 2 - p[:, 2] ** 2


# --- compiling ------------------------------------------------------------------------------

def test_model_properties():
    m = sphere()
    assert (m.name, m.dims, m.objects) == ("my_model", 3, ["my_model"])


def test_syntax_error_is_model_error_with_file_line_column():
    with pytest.raises(frepfarm.ModelError) as e:
        frepfarm.compile("my_model(x[3], a[1]) {\n  my_model = 1 - x[1] +;\n}\n", file="bad.hf")
    assert str(e.value).startswith("bad.hf:2:24: error:")
    assert isinstance(e.value, ValueError)


def test_unknown_function_names_its_place():
    with pytest.raises(frepfarm.ModelError, match=r"^f\.hf:1:35: error: .*hfNoSuch"):
        frepfarm.compile("my_model(x[3], a[1]) { my_model = hfNoSuch(x); }", file="f.hf")


def test_load_file_and_missing_file(tmp_path):
    path = tmp_path / "ball.hf"
    path.write_text(SPHERE)
    m = frepfarm.load(str(path), params=[2.0])
    assert m.eval([1.0, 1.0, 1.0])[0] == 1.0
    with pytest.raises(OSError, match="cannot read model"):
        frepfarm.load(str(tmp_path / "missing.hf"))
    bad = tmp_path / "bad.hf"
    bad.write_text("my_model(x[3], a[1]) {\n my_model = ;\n}\n")
    with pytest.raises(frepfarm.ModelError, match="^" + str(bad) + ":2:13: error"):
        frepfarm.load(str(bad))



def test_load_refuses_fifo_device_and_huge_file_at_once(tmp_path):
    """load() reads as frep does (io::readInputFile): a FIFO with no writer, /dev/zero and a
    file above 1 GiB raise OSError naming the path at once: no hang, no GB allocation."""
    import time
    fifo = tmp_path / "model.fifo"
    os.mkfifo(fifo)
    huge = tmp_path / "huge.hf"
    with open(huge, "wb") as f:
        f.truncate((1 << 30) + 1)  # sparse: no disk used
    for path, why in [(fifo, "not a regular file"), ("/dev/zero", "not a regular file"),
                      (huge, "more than the limit of 1 GiB"), (tmp_path, "is a directory")]:
        start = time.monotonic()
        with pytest.raises(OSError) as e:
            frepfarm.load(str(path))
        assert isinstance(e.value, frepfarm.IoError)
        assert str(e.value).startswith("cannot read model '" + str(path) + "'"), str(e.value)
        assert why in str(e.value)
        assert time.monotonic() - start < 5

def test_too_many_params():
    with pytest.raises(ValueError, match="has a\\[1\\], got 2"):
        frepfarm.compile(SPHERE, params=[1, 2])


def test_object_choice_and_iso():
    src = "one(x[3], a[1]) { one = 1 - x[1]; }\ntwo(x[2], a[1]) { two = 2 - x[2]; }\n"
    m = frepfarm.compile(src, object="two", iso=0.5)
    assert (m.name, m.dims, m.objects) == ("two", 2, ["one", "two"])
    assert m.eval(np.array([[7.0, 0.25]]))[0] == 2 - 0.25 - 0.5


# --- evaluating -----------------------------------------------------------------------------

def test_eval_exact_on_dyadic_points():
    # Dyadic coordinates: every product and difference is exact, so the value is exact.
    p = np.array([[0.5, 0.25, 0.0], [0.0, 0.0, 0.0], [1.0, -2.0, 0.125], [-0.75, 0.5, 0.5]])
    m = frepfarm.compile(SPHERE, params=[1.0])
    np.testing.assert_array_equal(m.eval(p), exact_sphere(p, 1.0))


def test_eval_batches_agree_with_formula_and_single_points():
    rng = np.random.default_rng(7)
    p = rng.uniform(-2, 2, size=(1000, 3))  # four batches of 256, the last partial
    m = sphere()
    v = m.eval(p)
    assert v.shape == (1000,) and v.dtype == np.float64
    np.testing.assert_allclose(v, exact_sphere(p), rtol=0, atol=1e-15)
    single = np.array([m.eval(q)[0] for q in p[::97]])
    np.testing.assert_array_equal(single, v[::97])
    # Fortran order and float32 input are converted, not misread.
    np.testing.assert_array_equal(m.eval(np.asfortranarray(p)), v)
    np.testing.assert_array_equal(m.eval(p.astype(np.float32)), m.eval(p.astype(np.float32).astype(np.float64)))


def test_eval_shape_errors():
    m = sphere()
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        m.eval(np.zeros((4, 2)))
    with pytest.raises(ValueError):
        m.eval(np.zeros((2, 2, 3)))
    assert m.eval(np.zeros((0, 3))).shape == (0,)


# --- sampling -------------------------------------------------------------------------------

def lattice_points(v):
    i, j, k = np.meshgrid(*[np.arange(n) for n in v.dims], indexing="ij")
    idx = np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1)
    return idx, np.asarray(v.origin) + idx * v.voxel


def test_sample_inside_volume_is_the_lattice_count():
    m = sphere()
    v = m.sample((-1.2, -1.2, -1.2), (1.2, 1.2, 1.2), res=33)
    assert v.dims == [33, 33, 33] and v.voxel == 2.4 / 32
    _, pts = lattice_points(v)
    inside = np.count_nonzero(m.eval(pts) >= 0)
    assert v.inside_volume() == inside * v.voxel ** 3
    assert abs(v.inside_volume() - 4 / 3 * math.pi * R ** 3) < 0.03 * 4 / 3 * math.pi * R ** 3


def read_back(v, tmp_path):
    import pyopenvdb
    path = str(tmp_path / "ball.vdb")
    v.write_vdb(path)
    assert not [f for f in os.listdir(tmp_path) if f != "ball.vdb"], "a temporary file was left"
    return pyopenvdb.read(path, "my_model")


@pytest.mark.parametrize("via", ["write_vdb", "to_pyopenvdb"])
def test_vdb_read_by_pyopenvdb(tmp_path, via):
    import pyopenvdb
    m = sphere()
    v = m.sample((-1.2, -1.2, -1.2), (1.2, 1.2, 1.2), res=33)
    g = read_back(v, tmp_path) if via == "write_vdb" else v.to_pyopenvdb()
    assert isinstance(g, pyopenvdb.FloatGrid)
    assert g.gridClass == pyopenvdb.GridClass.LEVEL_SET
    assert g.transform.voxelSize()[0] == pytest.approx(v.voxel, rel=1e-12)
    # Every active voxel: OpenVDB's negative-inside sign, and -f itself where the file says so.
    exact = g.metadata.get("frep_sign") == "value = -f"
    n = 0
    for item in g.citerOnValues():
        if item["count"] != 1:
            continue
        ijk = item["min"]
        f = m.eval(np.array(g.transform.indexToWorld(ijk)))[0]
        # A true signed distance (the default) is the distance to the meshed zero set: its sign
        # may differ from f's only within a small fraction of a voxel of the surface.
        if exact or abs(item["value"]) > 0.1 * v.voxel:
            assert (item["value"] < 0) == (f > 0), (ijk, item["value"], f)
        if exact:
            assert item["value"] == np.float32(-f)
        n += 1
    assert n == g.activeVoxelCount() > 1000
    # Inside count from OpenVDB's dense copy = the lattice count.
    lo = [int(round(c)) for c in g.transform.worldToIndex(tuple(v.origin))]
    dense = np.zeros(tuple(v.dims), dtype=np.float32)
    g.copyToArray(dense, ijk=tuple(lo))
    _, pts = lattice_points(v)
    fv = m.eval(pts).reshape(dense.shape)
    agree = (dense < 0) == (fv > 0)
    assert np.all(agree | (np.abs(dense) < 0.1 * v.voxel))


def test_write_vdb_errors_leave_nothing(tmp_path):
    v = sphere().sample((-1, -1, -1), (1, 1, 1), res=9)
    with pytest.raises(OSError):
        v.write_vdb(str(tmp_path))  # a directory
    with pytest.raises(OSError):
        v.write_vdb(str(tmp_path / "no" / "such" / "dir.vdb"))
    assert os.listdir(tmp_path) == []


def test_sample_argument_errors():
    m = sphere()
    with pytest.raises(ValueError, match="hi must exceed lo"):
        m.sample((0, 0, 0), (1, 0, 1), res=8)
    with pytest.raises(ValueError, match="res"):
        m.sample((0, 0, 0), (1, 1, 1), res=1)
    with pytest.raises(ValueError, match="band"):
        m.sample((0, 0, 0), (1, 1, 1), res=8, band=0)


# --- meshing --------------------------------------------------------------------------------

def check_closed(tri, nv):
    """Every directed edge once, its reverse once: closed, manifold, consistently oriented."""
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]).astype(np.int64)
    key = e[:, 0] * nv + e[:, 1]
    rev = e[:, 1] * nv + e[:, 0]
    assert len(np.unique(key)) == len(key), "a directed edge appears twice"
    assert np.array_equal(np.sort(key), np.sort(rev)), "an edge has no opposite"
    assert np.all(tri < nv)
    return len(key) // 2


def enclosed_volume(v, tri):
    a, b, c = v[tri[:, 0]], v[tri[:, 1]], v[tri[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6


def test_sphere_mesh_is_watertight_and_on_the_surface():
    m = sphere()
    mesh = m.mesh((-1.2, -1.2, -1.2), (1.2, 1.2, 1.2), res=49)
    v, n, t = mesh.vertices, mesh.normals, mesh.triangles
    assert v.shape[1] == 3 and t.shape[1] == 3 and t.dtype == np.uint32 and n.shape == v.shape
    edges = check_closed(t, len(v))
    assert len(v) - edges + len(t) == 2  # Euler characteristic of a sphere
    assert np.max(np.abs(np.linalg.norm(v, axis=1) - R)) < 1e-4  # roots on f = 0
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1, atol=1e-12)
    assert np.all(np.einsum("ij,ij->i", n, v) > 0)  # outward
    vol = enclosed_volume(v, t)
    assert 0 < 4 / 3 * math.pi * R ** 3 - vol < 0.01 * 4 / 3 * math.pi * R ** 3  # chords cut inside


def test_a_sphere_cut_by_the_box_is_capped_and_closed():
    # As frep mesh: the solid cut by the box's top face is meshed as solid ∩ box, capped
    # just inside that face; closed, every vertex in the box, the volume of the ball minus its cap.
    m = sphere()
    top = 0.25 * R
    lo, hi = (-1.2, -1.2, -1.2), (1.2, 1.2, top)
    mesh = m.mesh(lo, hi, res=49)
    v, t = mesh.vertices, mesh.triangles
    edges = check_closed(t, len(v))
    assert len(v) - edges + len(t) == 2
    voxel = 2.4 / 48
    grid_top = voxel * math.ceil(top / voxel - 1e-9)  # the world lattice, the box rounded outward
    assert grid_top - 3e-3 * voxel <= v[:, 2].max() <= grid_top
    h = R - grid_top
    exact = 4 / 3 * math.pi * R ** 3 - math.pi * h * h * (3 * R - h) / 3
    assert abs(enclosed_volume(v, t) - exact) < 0.01 * exact


def test_block_simplifies_to_twelve_exact_triangles(tmp_path):
    m = frepfarm.compile(BLOCK)
    # The box puts no lattice plane on a face: with faces exactly on grid points (box -1..1,
    # res 41) the mesher's end guard offsets every vertex and the simplifier keeps 2010 triangles.
    mesh = m.mesh((-1.013, -1.013, -1.013), (1, 1, 1), res=40, simplify=0.1)
    v, t = mesh.vertices, mesh.triangles
    assert (len(v), len(t)) == (8, 12)
    check_closed(t, len(v))
    corners = {(x, y, z) for x in (-0.5, 0.5) for y in (-0.25, 0.25) for z in (-0.75, 0.75)}
    assert {tuple(p) for p in np.round(v, 9)} == corners
    assert enclosed_volume(v, t) == pytest.approx(1 * 0.5 * 1.5, rel=1e-9)


def test_mesh_write_formats(tmp_path):
    mesh = sphere().mesh((-1, -1, -1), (1, 1, 1), res=17)
    for ext in ("ply", "obj", "stl"):
        mesh.write(str(tmp_path / f"ball.{ext}"))
    ply = (tmp_path / "ball.ply").read_bytes()
    assert f"element vertex {len(mesh.vertices)}\n".encode() in ply
    assert f"element face {len(mesh.triangles)}\n".encode() in ply
    stl = (tmp_path / "ball.stl").read_bytes()
    assert len(stl) == 84 + 50 * len(mesh.triangles)
    obj = (tmp_path / "ball.obj").read_text().splitlines()
    assert sum(1 for line in obj if line.startswith("v ")) == len(mesh.vertices)
    with pytest.raises(ValueError, match=r"\.ply"):
        mesh.write(str(tmp_path / "ball.xyz"))
    assert sorted(os.listdir(tmp_path)) == ["ball.obj", "ball.ply", "ball.stl"]


def test_keyboard_interrupt_stays_python():
    import signal
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_mesh_refuses_simplify_out_of_range():
    """simplify=inf and 5e-324 spun without end (found by tests/fuzz/fuzz_python.py)."""
    m = sphere()
    for bad in [math.inf, math.nan, 5e-324, -1.0, 1e31]:
        with pytest.raises(ValueError, match="simplify: expected 0"):
            m.mesh([-1, -1, -1], [1, 1, 1], res=6, simplify=bad)
    assert len(m.mesh([-1, -1, -1], [1, 1, 1], res=6, simplify=1e-30).triangles) > 0
