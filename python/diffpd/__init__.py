"""DiffPD: differentiable projective dynamics for soft bodies.

The classes and functions of the C++ library (lib/include/diffpd/*.h) under
Python names: Mesh, Scene, SolverOptions, Simulator, State, Rollout, ...
Arrays are NumPy float64 (positions and velocities flattened to 3n, node i
axis d at 3 i + d); Eigen members of the library's structs are returned as
views of their memory. The library's exceptions are InvalidInputError
(a ValueError) and SolverError (a RuntimeError with a `status`), both
subclasses of diffpd.Error, with the library's messages.

diffpd.torch holds torch.autograd Functions over rollouts; diffpd.problems
the project's registered problems (when the package was built with them).
"""

from ._diffpd import *  # noqa: F401,F403
from ._diffpd import __doc__ as _native_doc  # noqa: F401

try:
    from ._diffpd import problems  # noqa: F401
except ImportError:  # built without the problems library
    pass
