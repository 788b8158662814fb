"""dynid: identification of robot dynamic parameters (link inertias, actuator inertias, joint
friction, payload). The functions are those of the compiled extension dynid._core (C++, pybind11);
pure-Python submodules of this package build on them."""
import glob as _glob
import os as _os
import sys as _sys


def _interpreter_hint():
    """Which interpreter the compiled module was built for, from its file name (cpython-311)."""
    built = sorted(_os.path.basename(p) for p in
                   _glob.glob(_os.path.join(_os.path.dirname(__file__), "_core.*")))
    return (f"this interpreter is {_sys.executable} (Python {_sys.version.split()[0]}); "
            f"the compiled module is {', '.join(built) or 'missing (build the target dynid_python)'}"
            "; Debian's /usr/bin/python3 has NumPy from `apt install python3-numpy` "
            "(scripts/setup installs it)")


# The arrays in and out are NumPy's: without it every call would fail at its first array, so the
# import says at once which interpreter to use (a pyenv or virtualenv python3 first on PATH often
# lacks it).
try:
    import numpy as _numpy  # noqa: F401
except ImportError as _error:
    raise ImportError("dynid needs NumPy, which this interpreter cannot import: run it with "
                      "/usr/bin/python3, or install NumPy for this interpreter "
                      f"(python3 -m pip install numpy); {_interpreter_hint()}") from _error

try:
    from ._core import *  # noqa: F401,F403  (the extension's public functions and classes)
    from ._core import __doc__, __version__  # noqa: F401
except ImportError as _error:
    raise ImportError("dynid's compiled module dynid._core does not load here (built for "
                      f"another Python version?): {_interpreter_hint()}") from _error
from . import fleet  # noqa: F401,E402  (dynid.fleet.identify: many logs on a Dask cluster)
