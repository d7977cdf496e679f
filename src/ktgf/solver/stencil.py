"""The names of the finite-volume discretisation shared by the JAX path and the C++ kernel: ghost cells,
slope limiters and Riemann solvers (indices of the tuples are the kernel's compile-time codes)."""

#: Ghost cells per side: the MUSCL stencil of a face reaches two cells away.
GHOST = 2
#: Slope limiters of the MUSCL reconstruction (``none`` = central slopes).
LIMITERS = ("minmod", "vanleer", "mc", "none")
#: Approximate Riemann solvers of the face fluxes.
RIEMANN_SOLVERS = ("hll", "rusanov")
