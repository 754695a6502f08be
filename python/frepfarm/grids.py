"""Models to NumPy grids (docs/python.md): f on every point of a regular lattice of a box.
NumPy is imported when a grid is made, so `import frepfarm` works without it (an optional extra)."""


def _numpy(call):
    try:
        import numpy
    except ImportError:
        raise ModuleNotFoundError("%s works on NumPy arrays, and numpy is not installed: pip install "
                                  "'frepfarm[numpy]' (or numpy; the calls that return no array work without it)"
                                  % call, name="numpy") from None
    return numpy


class DenseGrid:
    """values[i, j, k] = f(origin + voxel * (i, j, k)); inside where values >= 0."""

    def __init__(self, values, origin, voxel):
        self.values = values
        self.origin = origin
        self.voxel = voxel

    def points(self):
        """The (nx, ny, nz, 3) world points of the lattice."""
        np = _numpy("DenseGrid.points")
        axes = [self.origin[a] + self.voxel * np.arange(self.values.shape[a]) for a in range(3)]
        return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)

    def inside_volume(self):
        """Lattice points with f >= 0 times the voxel volume."""
        np = _numpy("DenseGrid.inside_volume")
        return float(np.count_nonzero(self.values >= 0)) * self.voxel ** 3


def dense_grid(model, lo, hi, res=64, fixed=()):
    """f of a frepfarm.Model on the lattice of `res` points along the box's longest edge, from lo
    (up to hi on every axis): a DenseGrid. fixed: x[4] and above of higher-dimensional models."""
    np = _numpy("grid")
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,) or not np.all(np.isfinite(lo)) or not np.all(np.isfinite(hi)):
        raise ValueError("box: lo and hi must be 3 finite numbers each")
    if not np.all(hi > lo):
        raise ValueError("box: hi must exceed lo on every axis")
    if not (isinstance(res, int) and 2 <= res <= 1024):
        raise ValueError("res: expected a whole number 2 to 1024 of points along the longest axis")
    fixed = [float(v) for v in fixed]
    if len(fixed) != max(model.dims - 3, 0):
        raise ValueError("fixed: the model has x[%d], so fixed needs %d values" % (model.dims, max(model.dims - 3, 0)))
    voxel = float(np.max(hi - lo)) / (res - 1)
    # 1e-9 voxel of slack: an edge that is a whole number of voxels keeps its last point.
    counts = [int(np.floor((hi[a] - lo[a]) / voxel + 1e-9)) + 1 for a in range(3)]
    grid = DenseGrid(np.empty(counts), lo.copy(), voxel)
    pts = grid.points().reshape(-1, 3)
    if fixed:
        pts = np.hstack([pts, np.tile(fixed, (pts.shape[0], 1))])
    grid.values = model.eval(pts).reshape(counts)
    return grid
