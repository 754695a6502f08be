"""frepfarm: F-rep solids in the HyperFun language (inside is f >= 0), evaluated, sampled,
meshed and measured by the frepfarm core (docs/python.md).

The compiled part is the extension module frepfarm.frepfarm (python/frepfarm_module.cpp);
everything it defines is re-exported here. frepfarm.shapes builds models from Python calls
(primitives, set operations, transforms, offsets, Minkowski operations, sweeps, projections)
that compile to HyperFun text, hence to the same tape as the equivalent .hf file.
"""
from . import frepfarm as _native
from .frepfarm import *  # noqa: F401,F403 (compile, load, Model, Volume, Mesh, the errors)

__version__ = _native.__version__
__all__ = [name for name in dir(_native) if not name.startswith("_")] + ["shapes"]

from . import shapes  # noqa: E402 (needs the names above)
