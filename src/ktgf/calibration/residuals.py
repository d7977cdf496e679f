"""Model predictions of the shared data, the weighted residuals and their exact Jacobians.

Parameters are any float option of a model (routed by :meth:`ktgf.closures.Model.with_options`,
e.g. φ_c, φ_f, β, a) and, for Couette data, the wall specularity φ' and wall restitution e_w
(both walls the same: the DEM walls are identical).

Residual of observation i: ``(prediction − data)/σ_i`` with the file's stated standard error
(``weights="sigma"``) or ``prediction/data − 1`` (``weights="relative"``).

Jacobians
---------
uniform shear
    ``jax.jacfwd`` through :meth:`Model.reduced` (``check=False``) and the closed form
    :func:`ktgf.shear.steady.steady_shear`: exact to round-off.
Couette
    implicit-function theorem at the converged solution X(p) of R(X, p) = 0:
    dX/dp = −(∂R/∂X)⁻¹ ∂R/∂p with ∂R/∂X the solver's own sparse Jacobian (central
    differences, O(h²)) factorised once, and ∂R/∂p, ∂y/∂(X, p) by central differences of the
    residual and of the observables y (the Couette residual is NumPy code, not JAX).  No re-solve
    per parameter; the error is O(h²) ≈ 1e-8 relative, checked against finite differences of
    re-solved cells in ``tests/calibration/test_calibration_gradients.py``.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..closures.models import Model
from ..errors import ConvergenceError, InputError
from ..data import CouetteData, UniformShearData

#: Parameters of the walls (Couette data only), with their range.
WALL_PARAMETERS = {"specularity": (1e-4, 1.0), "wall_restitution": (0.05, 1.0)}
WEIGHTS = ("sigma", "relative")
#: Couette observables: wall shear stress, wall normal stress, slip speed at the outermost occupied bins.
COUETTE_OBSERVABLES = ("tau_wall", "p_wall", "slip_speed")
#: Default wall of a Couette prediction when its parameters are neither fitted nor given.
DEFAULT_SPECULARITY = 0.1


def enable_x64() -> None:
    """Double precision in JAX (the coefficients lose ~1e-7 in float32; the 3D solver does the same)."""
    import jax

    jax.config.update("jax_enable_x64", True)


def model_at(model: Model, values: dict[str, Any]) -> Model:
    """``model`` with its options replaced by ``values`` (wall parameters are left out)."""
    opts = {k: v for k, v in values.items() if k not in WALL_PARAMETERS}
    return model.with_options(**opts) if opts else model


def shear_prediction(model: Model, data: UniformShearData, *, traced: bool = False) -> Any:
    """T = θ/(γ̇d)², η/η0 and p/(nT) at the data's (φ, e), concatenated in :data:`~.data.SHEAR_OBSERVABLES` order.

    NumPy; with ``traced=True`` (options that are JAX tracers, inside ``jax.jacfwd``) JAX, without
    range checks (a tracer has no value to check; the same values are checked concretely elsewhere).
    """
    from ..shear.steady import steady_temperature

    if traced:
        import jax.numpy as xp
    else:
        xp = np
    phi, e = xp.asarray(data.phi), xp.asarray(data.e)
    T = steady_temperature(model, phi, e, check=not traced)
    r = model.reduced(phi, e, check=False, chi_shear=1.0 / xp.sqrt(T))  # χ at the state's s = 1/√T if it has χ(φ, s)
    return xp.concatenate([T, r.eta, r.p])


def _scale(obs: np.ndarray, sigma: np.ndarray, weights: str) -> np.ndarray:
    return sigma if weights == "sigma" else np.abs(obs)


class ShearTerm:
    """Residuals of one uniform-shear file and their exact JAX Jacobian."""

    def __init__(self, data: UniformShearData, model: Model, names: Sequence[str], weights: str) -> None:
        self.data, self.model, self.names = data, model, list(names)
        self.obs, self.sigma = data.observed()
        self.scale = _scale(self.obs, self.sigma, weights)
        self.labels = data.labels
        self._jac = None
        self.method, self.method_note = "jax", ""

    def predict(self, values: dict[str, float]) -> np.ndarray:
        return np.asarray(shear_prediction(model_at(self.model, values), self.data), dtype=float)

    def residuals(self, values: dict[str, float]) -> np.ndarray:
        return (self.predict(values) - self.obs) / self.scale

    def jacobian(self, values: dict[str, float]) -> np.ndarray:
        """Exact (JAX) Jacobian; central differences only if the closure chain cannot be traced (``method`` says which)."""
        if self.method == "jax":
            try:
                return self._jax_jacobian(values)
            except Exception as exc:  # noqa: BLE001  (any part that is not JAX code: fall back, and say so)
                self.method = "finite differences"
                self.method_note = f"uniform-shear Jacobian by central differences: the model is not JAX-traceable ({type(exc).__name__})"
        J = np.empty((self.obs.size, len(self.names)))
        for j, n in enumerate(self.names):
            h = 1e-6 * max(abs(values[n]), 1e-2)
            J[:, j] = (self.residuals({**values, n: values[n] + h}) - self.residuals({**values, n: values[n] - h})) / (2 * h)
        return J

    def _jax_jacobian(self, values: dict[str, float]) -> np.ndarray:
        import jax
        import jax.numpy as jnp

        enable_x64()
        fitted = [n for n in self.names if n not in WALL_PARAMETERS]
        if self._jac is None:
            self._jac = _shear_jacobian_function(self.model, tuple(fitted), self.data)
        J = np.zeros((self.obs.size, len(self.names)))
        if fitted:
            Jm = np.asarray(self._jac(jnp.asarray([values[n] for n in fitted], dtype=jnp.float64)))
            for j, n in enumerate(fitted):
                J[:, self.names.index(n)] = Jm[:, j]
        return J / self.scale[:, None]


#: Compiled uniform-shear Jacobians by (model, fitted names, φ, e): tracing and XLA compilation cost
#: ~1.5 s CPU per fit, the Jacobian evaluations ~1 ms, so repeated fits of one model to one file
#: (sweeps of start values, ``docs/dense_fit.py``, a notebook) compile once per process.
_SHEAR_JACOBIANS: dict[tuple, Any] = {}
_SHEAR_JACOBIANS_MAX = 32


def _shear_jacobian_function(model: Model, fitted: tuple[str, ...], data: UniformShearData) -> Any:
    """``jax.jit(jax.jacfwd(...))`` of the uniform-shear predictions in the fitted options, cached."""
    import jax

    key = (model, fitted, np.asarray(data.phi).tobytes(), np.asarray(data.e).tobytes())
    try:
        fn = _SHEAR_JACOBIANS.get(key)
    except TypeError:  # a model with an unhashable option: no caching
        key, fn = None, None
    if fn is None:
        phi, e = np.array(data.phi), np.array(data.e)
        states = UniformShearData(data.path, phi, e, {}, {})

        def pred(x):
            return shear_prediction(traced_model(model, dict(zip(fitted, x))), states, traced=True)

        fn = jax.jit(jax.jacfwd(pred))
        if key is not None:
            if len(_SHEAR_JACOBIANS) >= _SHEAR_JACOBIANS_MAX:
                _SHEAR_JACOBIANS.pop(next(iter(_SHEAR_JACOBIANS)))
            _SHEAR_JACOBIANS[key] = fn
    return fn


def traced_model(model: Model, values: dict[str, Any]) -> Model:
    """``model`` with options set to JAX values (tracers), routed to every part that has them, as
    :meth:`Model.with_options` does.

    Option checks cannot look at abstract values (and may reject them), so the parts are copied and
    the values set directly; the same options are checked with concrete values by :func:`model_at`
    at every evaluation of the residuals, before any Jacobian.
    """
    import copy
    import dataclasses

    new = copy.copy(model)
    used: set[str] = set()
    for f in dataclasses.fields(model):
        part = getattr(model, f.name)
        if not dataclasses.is_dataclass(part) or isinstance(part, type):
            continue
        names = {g.name for g in dataclasses.fields(part)} & set(values)
        if names:
            part = copy.copy(part)
            for n in names:
                object.__setattr__(part, n, values[n])
            object.__setattr__(new, f.name, part)
            used |= names
    if set(values) - used:
        raise InputError(f"model {model.name!r} has no option(s) {sorted(set(values) - used)}")
    return new


class CouetteTerm:
    """Residuals of one DEM Couette file: the planar cell of its header solved with the model and JJ walls.

    The solution of the last point is the start of the next (warm start), and cached with its
    parameters so that the Jacobian at an accepted point costs no new solve.
    """

    def __init__(self, data: CouetteData, model: Model, names: Sequence[str], weights: str, *,
                 n_cells: int = 200, stretch: float = 1.5, fixed: dict[str, float] | None = None) -> None:
        self.data, self.model, self.names = data, model, list(names)
        self.n_cells, self.stretch = n_cells, stretch
        self.fixed = {"specularity": DEFAULT_SPECULARITY, "wall_restitution": data.case.e, **(fixed or {})}
        self.obs = np.array([data.tau_wall, data.p_wall, data.slip_speed()])
        self.sigma = np.array([data.case.tau_wall_sigma, data.case.p_wall_sigma, data.slip_sigma()])
        if weights == "sigma" and not np.all(np.isfinite(self.sigma) & (self.sigma > 0)):
            raise InputError(f"data file {data.path.name}: column ux_sem is needed for weights 'sigma' (slip uncertainty)")
        self.scale = _scale(self.obs, self.sigma, weights)
        self.labels = [f"{data.path.name} {k}" for k in COUETTE_OBSERVABLES]
        self._start: np.ndarray | None = None
        self._cache: tuple[tuple[float, ...], Any, np.ndarray] | None = None

    def problem(self, values: dict[str, float]):
        """The discrete Couette problem of the DEM case at parameter values ``values``."""
        from ..couette.geometry import PlanarCell
        from ..couette.run import Material, build_problem
        from ..couette.walls import Wall

        v = {**self.fixed, **values}
        c = self.data.case
        wall = Wall(specularity=v["specularity"], restitution=v["wall_restitution"])
        return build_problem(model_at(self.model, v), PlanarCell(c.gap, c.wall_speed), wall, wall, c.mean_phi,
                             Material(c.d, c.rho_s, c.e), n_cells=self.n_cells, stretch=self.stretch)

    def observables(self, problem, X: np.ndarray) -> np.ndarray:
        """Wall shear stress, wall normal stress (pressure at the walls) and slip speed, in DEM units."""
        t = problem.terms(X)
        V, rho = problem.v_scale, self.data.case.rho_s
        tau = np.mean(np.abs(t["F"][[0, -1]]) / problem.S_wall) * rho * V**2
        p = 0.5 * (t["p"][0] + t["p"][-1]) * rho * V**2
        y0 = self.data.slip_y
        u = 0.5 * (abs(np.interp(-y0, problem.x, t["u"])) + abs(np.interp(y0, problem.x, t["u"]))) * V
        return np.array([tau, p, u])

    def solve(self, values: dict[str, float]):
        """(problem, X) at ``values``; raises :class:`ConvergenceError` naming the parameters."""
        from ..couette.solver import solve

        key = tuple(values[n] for n in self.names)
        if self._cache is not None and self._cache[0] == key:
            return self._cache[1], self._cache[2]
        problem = self.problem(values)
        try:
            X, _ = solve(problem, self._start)
        except ConvergenceError:
            if self._start is None:
                raise _fail(values) from None
            try:
                X, _ = solve(problem, None)
            except ConvergenceError:
                raise _fail(values) from None
        self._start = X
        self._cache = (key, problem, X)
        return problem, X

    def predict(self, values: dict[str, float]) -> np.ndarray:
        problem, X = self.solve(values)
        return self.observables(problem, X)

    def residuals(self, values: dict[str, float]) -> np.ndarray:
        return (self.predict(values) - self.obs) / self.scale

    def jacobian(self, values: dict[str, float]) -> np.ndarray:
        """d(residuals)/d(parameters) by the implicit-function theorem (see the module notes)."""
        import scipy.sparse.linalg as spla

        problem, X = self.solve(values)
        lu = spla.splu(problem.jacobian(X, problem.residual(X)))
        J = np.zeros((self.obs.size, len(self.names)))
        for j, n in enumerate(self.names):
            h = 1e-5 * max(abs(values[n]), 1e-2)
            up, dn = {**values, n: values[n] + h}, {**values, n: values[n] - h}
            Pu, Pd = self.problem(up), self.problem(dn)
            dRdp = (Pu.residual(X) - Pd.residual(X)) / (2 * h)
            dX = -lu.solve(dRdp)
            J[:, j] = (self.observables(Pu, X + h * dX) - self.observables(Pd, X - h * dX)) / (2 * h)
        return J / self.scale[:, None]


def _fail(values: dict[str, float]) -> ConvergenceError:
    at = ", ".join(f"{k}={v:.6g}" for k, v in values.items())
    return ConvergenceError(f"the Couette solver did not converge at {at}")


def make_terms(model: Model, datasets: Sequence[Any], names: Sequence[str], weights: str, *,
               n_cells: int = 200, fixed: dict[str, float] | None = None) -> list[Any]:
    """One residual term per data file."""
    if weights not in WEIGHTS:
        raise InputError(f"weights {weights!r} is not valid; choose one of {', '.join(WEIGHTS)}")
    terms: list[Any] = []
    for d in datasets:
        if isinstance(d, CouetteData):
            terms.append(CouetteTerm(d, model, names, weights, n_cells=n_cells, fixed=fixed))
        else:
            terms.append(ShearTerm(d, model, names, weights))
    return terms


__all__ = ["COUETTE_OBSERVABLES", "CouetteTerm", "ShearTerm", "WALL_PARAMETERS", "WEIGHTS", "make_terms",
           "model_at", "shear_prediction"]
