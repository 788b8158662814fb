"""dynid: identification of robot dynamic parameters (link inertias, actuator inertias, joint
friction, payload). The functions are those of the compiled extension dynid._core (C++, pybind11);
pure-Python submodules of this package build on them."""
from ._core import *  # noqa: F401,F403  (the extension's public functions and classes)
from ._core import __doc__, __version__  # noqa: F401
from . import fleet  # noqa: F401,E402  (dynid.fleet.identify: many logs on a Dask cluster)
