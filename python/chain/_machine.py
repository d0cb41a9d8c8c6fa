"""``chain.Machine``: a machine file, its exact error model, numpy in and out."""

from __future__ import annotations

import os
from typing import Any, Dict, List, Mapping, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _chain
from ._results import Derivation, ReliabilityResult, SobolResult

ArrayLike = Any
Params = Optional[Mapping[str, float]]


class Nominal(NamedTuple):
    """The nominal tool pose: ``rotation`` (``(3, 3)`` or ``(N, 3, 3)``) and ``position`` (``(3,)`` or ``(N, 3)``)."""

    rotation: np.ndarray
    position: np.ndarray


def _params(params: Params) -> List[Tuple[str, float]]:
    if params is None:
        return []
    if not isinstance(params, Mapping):
        raise TypeError(f"params must be a mapping of parameter name to value, not {type(params).__name__}")
    out = []
    for name, value in params.items():
        try:
            out.append((str(name), float(value)))
        except (TypeError, ValueError):
            raise ValueError(f"parameter `{name}`: {value!r} is not a number") from None
    return out


def _float_array(x: ArrayLike, name: str) -> np.ndarray:
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name} must be an array of numbers: {e}") from None
    return a


def _rows(x: ArrayLike, name: str, width: int, what: str) -> Tuple[np.ndarray, bool]:
    """``x`` as a C-contiguous ``(N, width)`` float64 array, and whether it was one row ``(width,)``."""
    a = _float_array(x, name)
    if a.ndim == 1:
        if a.shape[0] != width:
            raise ValueError(f"{name} of shape {a.shape}: expected ({width},) or (N, {width}), {width} = {what}")
        return np.ascontiguousarray(a.reshape(1, width)), True
    if a.ndim == 2:
        if a.shape[1] != width:
            raise ValueError(f"{name} of shape {a.shape}: expected ({width},) or (N, {width}), {width} = {what}")
        return np.ascontiguousarray(a), False
    raise ValueError(f"{name} of shape {a.shape}: expected ({width},) or (N, {width}), {width} = {what}")


class Machine:
    """A machine file loaded and validated, with its compiled exact first-order error model.

    ``Machine.load(path)`` or ``Machine.from_yaml(text)``; a problem in the
    file raises :class:`chain.MachineError` (file, line, column, key).
    """

    def __init__(self, model: "_chain.Model") -> None:
        self._model = model

    @classmethod
    def load(cls, path: Union[str, "os.PathLike[str]"]) -> "Machine":
        """Loads a machine file (YAML)."""
        return cls(_chain.Model.load(os.fspath(path)))

    @classmethod
    def from_yaml(cls, text: str, file: str = "<yaml>") -> "Machine":
        """Loads a machine from YAML text; ``file`` names it in error messages."""
        if not isinstance(text, str):
            raise TypeError(f"text must be a str, not {type(text).__name__}")
        return cls(_chain.Model.from_yaml(text, file))

    # -- names ---------------------------------------------------------------

    @property
    def name(self) -> str:
        """The machine's name."""
        return self._model.name

    @property
    def file(self) -> str:
        """The file name error messages use."""
        return self._model.file

    @property
    def variables(self) -> List[str]:
        """The axis variables, in the order of ``q``'s columns (rotary ones in radians)."""
        return self._model.variables

    @property
    def parameters(self) -> Dict[str, Optional[float]]:
        """The parameters and their values in the file (``None``: symbolic, must be given as ``params``)."""
        return dict(self._model.parameters)

    @property
    def errors(self) -> List[str]:
        """The error parameters, in the order of the sensitivity's columns and of ``e``."""
        return self._model.errors

    def __repr__(self) -> str:
        return (
            f"<chain.Machine {self.name!r}: {len(self.variables)} variables, "
            f"{len(self.parameters)} parameters, {len(self.errors)} errors>"
        )

    # -- the model -----------------------------------------------------------

    def derive(self, frame: Optional[str] = None) -> Derivation:
        """The exact first-order model, ``chain derive --format json`` (``frame``: ``"tool"``, ``"workpiece"`` or the file's)."""
        return Derivation._from_json(self._model.derive_json(frame))

    def to_sympy(self, frame: Optional[str] = None) -> Any:
        """The sensitivity matrix ``∂E/∂e`` as a SymPy ``Matrix`` (6 × N_err; rows px..oz, columns ``errors``).

        Its symbols are the variables and parameters by name; ``E = M * e``.
        """
        try:
            import sympy
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("to_sympy() needs sympy: pip install sympy") from e
        doc = self.derive(frame).to_dict()
        names = doc["variables"] + doc["parameters"] + doc["errors"]
        local = {n: sympy.Symbol(n) for n in names}
        errors = doc["errors"]
        m = sympy.zeros(6, len(errors))
        for c, component in enumerate(("px", "py", "pz", "ox", "oy", "oz")):
            for error, expression in doc["components"][component].items():
                m[c, errors.index(error)] = sympy.sympify(expression, locals=local)
        return m

    def sensitivity(self, q: ArrayLike, params: Params = None) -> np.ndarray:
        """The exact sensitivity ``∂E_c/∂e_j`` at axis values ``q``.

        ``q`` of shape ``(V,)`` gives ``(6, N_err)``; ``(N, V)`` gives
        ``(N, 6, N_err)`` (float64, C-contiguous). Rows px, py, pz, ox, oy,
        oz; columns ``errors``. Computed on all cores, the GIL released.
        """
        rows, single = _rows(q, "q", len(self.variables), "the variables " + ", ".join(self.variables))
        ne = len(self.errors)
        out = self._model.sensitivity(rows, _params(params)).reshape(rows.shape[0], 6, ne)
        return out[0] if single else out

    def error(self, q: ArrayLike, e: ArrayLike, params: Params = None) -> np.ndarray:
        """The first-order error ``E = S(q)·e`` (px, py, pz, ox, oy, oz).

        ``q``: ``(V,)`` or ``(N, V)``; ``e``: ``(N_err,)`` or ``(N, N_err)``;
        they broadcast over ``N``. One point and one ``e`` give ``(6,)``,
        otherwise ``(N, 6)``.
        """
        qr, q_single = _rows(q, "q", len(self.variables), "the variables " + ", ".join(self.variables))
        er, e_single = _rows(e, "e", len(self.errors), f"the {len(self.errors)} errors of the model")
        if q_single and not e_single:
            qr = np.ascontiguousarray(np.broadcast_to(qr, (er.shape[0], qr.shape[1])))
        elif not q_single and not e_single and er.shape[0] != qr.shape[0]:
            raise ValueError(f"q has {qr.shape[0]} points and e {er.shape[0]} rows: give one e, or one per point")
        out = self._model.error(qr, er, _params(params)).reshape(qr.shape[0], 6)
        return out[0] if (q_single and e_single) else out

    def nominal(self, q: ArrayLike, params: Params = None) -> Nominal:
        """The nominal tool pose at ``q``: rotation ``(3, 3)`` and position ``(3,)``, or ``(N, 3, 3)`` and ``(N, 3)``."""
        rows, single = _rows(q, "q", len(self.variables), "the variables " + ", ".join(self.variables))
        flat = self._model.nominal(rows, _params(params)).reshape(rows.shape[0], 12)
        rotation = np.ascontiguousarray(flat[:, :9].reshape(-1, 3, 3))
        position = np.ascontiguousarray(flat[:, 9:])
        if single:
            return Nominal(rotation[0], position[0])
        return Nominal(rotation, position)

    # -- reliability ---------------------------------------------------------

    def reliability(
        self,
        method: str = "form",
        samples: Optional[int] = None,
        seed: int = 0,
        grid: Optional[Mapping[str, Sequence[float]]] = None,
        params: Params = None,
        sided: Optional[str] = None,
        cov: Optional[float] = None,
        system: Optional[str] = None,
        system_tolerance: Optional[float] = None,
        values: Optional[Union[str, "os.PathLike[str]"]] = None,
        acceptance: bool = False,
        acceptance_tolerance: float = 1e-3,
    ) -> ReliabilityResult:
        """Machining-accuracy reliability over the file's grid, ``chain reliability --format json``.

        Every option of the command line, by the same name:

        - ``method``: ``"form"``, ``"is"`` (importance sampling, 10,000
          samples per case by default), ``"mc"`` (Monte Carlo, 100,000),
          ``"subset"`` (subset simulation, 1,000 per level),
          ``"directional"`` (10,000) or ``"sorm"``;
        - ``samples`` per case, ``seed`` of the random streams;
        - ``cov``: a target coefficient of variation in (0, 1] of each
          case's p_f (sampling methods only): ``samples`` is then the budget
          (mc 10^7, is and directional 10^6 by default);
        - ``grid``: axes replacing (or adding to) the file's,
          ``{"x": [0, 500, 1000]}``; ``params``; ``sided``: ``"upper"`` or
          ``"two"`` to override the file's;
        - ``system``: ``"series"`` or ``"volumetric"`` (``system_tolerance``:
          the allowable volumetric error, default the smallest position
          tolerance);
        - ``values``: a values file with a calibration's posterior (means,
          ``std``, ``correlation``), as ``--values``;
        - ``acceptance=True``: also the whole-machine acceptance probability
          (the document's ``acceptance``; also computed when the file sets
          ``reliability.acceptance: true``), to ``acceptance_tolerance``.
        """
        if samples is not None and (not isinstance(samples, int) or isinstance(samples, bool) or samples < 1):
            raise ValueError(f"samples must be a positive integer, not {samples!r}")
        if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
            raise ValueError(f"seed must be a non-negative integer, not {seed!r}")
        if not isinstance(method, str):
            raise ValueError(f"method must be a str, not {type(method).__name__}")
        if not isinstance(acceptance, bool):
            raise ValueError(f"acceptance must be True or False, not {acceptance!r}")
        cov = _optional_float(cov, "cov")
        system_tolerance = _optional_float(system_tolerance, "system_tolerance")
        acceptance_tolerance = _optional_float(acceptance_tolerance, "acceptance_tolerance")
        axes = []
        for name, values_ in (grid or {}).items():
            a = _float_array(values_, f"grid[{name!r}]").ravel()
            axes.append((str(name), [float(v) for v in a]))
        path = None if values is None else os.fspath(values)
        text = _chain.reliability_json(
            self._model, method, samples, seed, cov, axes, _params(params), sided, system,
            system_tolerance, path, acceptance, acceptance_tolerance,
        )
        return ReliabilityResult._from_json(text)

    def sobol(
        self,
        at: Optional[Mapping[str, float]] = None,
        samples: int = 10_000,
        seed: int = 0,
        bootstrap: int = 1000,
        confidence: float = 0.95,
        grid: Optional[Mapping[str, Sequence[float]]] = None,
        params: Params = None,
    ) -> SobolResult:
        """First-order and total Sobol indices, ``chain sobol --format json``.

        Saltelli et al. 2010's first-order and Jansen's total estimator of
        every toleranced component and of ``|p|`` with respect to every error
        parameter, with bootstrap percentile intervals (docs/sobol.md):
        at one point ``at`` (every axis variable, ``{"x": 0, "y": 1500, ...}``),
        otherwise pooled over the reliability grid (``grid`` replacing axes,
        not with ``at``). ``samples``: base samples N (N·(k+2) evaluations
        per point); ``bootstrap`` replicates at ``confidence``.
        """
        for name, v in (("samples", samples), ("seed", seed), ("bootstrap", bootstrap)):
            if not isinstance(v, int) or isinstance(v, bool) or v < 0:
                raise ValueError(f"{name} must be a non-negative integer, not {v!r}")
        confidence = _optional_float(confidence, "confidence")
        point = None
        if at is not None:
            if not isinstance(at, Mapping):
                raise ValueError(f"at must be a mapping of axis variable to value, not {type(at).__name__}")
            point = []
            for name, value in at.items():
                try:
                    point.append((str(name), float(value)))
                except (TypeError, ValueError):
                    raise ValueError(f"at: `{name}` = {value!r} is not a number") from None
        axes = []
        for name, values_ in (grid or {}).items():
            a = _float_array(values_, f"grid[{name!r}]").ravel()
            axes.append((str(name), [float(v) for v in a]))
        text = _chain.sobol_json(self._model, point, samples, seed, bootstrap, confidence, axes, _params(params))
        return SobolResult._from_json(text)


def _optional_float(x: Any, name: str) -> Optional[float]:
    """``x`` as a float (``None`` stays ``None``); a non-number raises ValueError naming ``name``."""
    if x is None:
        return None
    if isinstance(x, bool):
        raise ValueError(f"{name} must be a number, not {x!r}")
    try:
        return float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, not {x!r}") from None
