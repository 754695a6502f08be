"""frepfarm: F-rep solids in the HyperFun language (inside is f >= 0), evaluated, sampled,
meshed and measured by the frepfarm core (docs/python.md).

The compiled part is the extension module frepfarm.frepfarm (python/frepfarm_module.cpp);
everything it defines is re-exported here. frepfarm.shapes builds models from Python calls
(primitives, set operations, transforms, offsets, Minkowski operations, sweeps, projections)
that compile to HyperFun text, hence to the same tape as the equivalent .hf file;
frepfarm.grids evaluates a model on a dense NumPy lattice.
"""
from . import frepfarm as _native
from .frepfarm import *  # noqa: F401,F403 (compile, load, Model, Volume, Mesh, the errors)

__version__ = _native.__version__
__all__ = [name for name in dir(_native) if not name.startswith("_")] + ["grids", "shapes"]
for _name in __all__[:-2]:  # tracebacks say frepfarm.ModelError, where users find it
    if isinstance(getattr(_native, _name), type):
        getattr(_native, _name).__module__ = __name__

from . import grids, shapes  # noqa: E402 (they use the names above)
