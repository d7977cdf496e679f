"""ktgf — continuum models of dense, inelastic granular flows.

Kinetic-theory closures (Enskog/Lun 1984, RET/Garzó–Dufty 1999, Visc.div./Bocquet 2001 and
the Proposed model), the homogeneous cooling state and its stability, the Couette shear cell
and a 3D JAX flow solver.  Start with :func:`get_model`.
"""

from ._startup import quit_on_interrupt_outside_the_run_loop

quit_on_interrupt_outside_the_run_loop()  # before the slow imports below

from ._version import __version__  # noqa: E402
from .closures import PAPER_MODELS, Model, get_model, list_models, register_model
from .errors import ConvergenceError, DivergenceError, InputError, KtgfError, UnknownModelError

__all__ = [
    "__version__", "PAPER_MODELS", "Model", "get_model", "list_models", "register_model",
    "ConvergenceError", "DivergenceError", "InputError", "KtgfError", "UnknownModelError",
]
