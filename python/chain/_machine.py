"""``chain.Machine``: a machine file, its exact error model, numpy in and out."""

from __future__ import annotations

import os
from typing import Any, Dict, List, Mapping, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _chain
from ._results import AllocationResult, Derivation, GeometricSensitivityResult, ReliabilityResult, SensitivityResult, SobolResult

ArrayLike = Any
Params = Optional[Mapping[str, float]]


class Nominal(NamedTuple):
    """The nominal tool pose: ``rotation`` (``(3, 3)`` or ``(N, 3, 3)``) and ``position`` (``(3,)`` or ``(N, 3)``)."""

    rotation: np.ndarray
    position: np.ndarray


def _approach(approach: Union[None, str, Mapping[str, str]]) -> Optional[str]:
    """``--approach``'s text: ``"up"`` as given, ``{"x": "up"}`` as ``"x=up"``."""
    if approach is None or isinstance(approach, str):
        return approach
    if isinstance(approach, Mapping):
        return ",".join(f"{k}={v}" for k, v in approach.items())
    raise ValueError(f"approach must be a str or a mapping, not {type(approach).__name__}")


def _named_numbers(given: Optional[Mapping[str, float]], what: str, of: str, entry: str) -> List[Tuple[str, float]]:
    if given is None:
        return []
    if not isinstance(given, Mapping):
        raise TypeError(f"{what} must be a mapping of {of}, not {type(given).__name__}")
    out = []
    for name, value in given.items():
        try:
            out.append((str(name), float(value)))
        except (TypeError, ValueError):
            raise ValueError(f"{entry} `{name}`: {value!r} is not a number") from None
    return out


def _params(params: Params) -> List[Tuple[str, float]]:
    return _named_numbers(params, "params", "parameter name to value", "parameter")


def _temperatures(temperature: Optional[Mapping[str, float]]) -> List[Tuple[str, float]]:
    """``temperature={"T_x": 28.0}``: ``--temperature T_x=28`` (°C)."""
    return _named_numbers(temperature, "temperature", "sensor name to °C", "sensor")


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

    def sensitivity(self, q: ArrayLike, params: Params = None, out: Optional[np.ndarray] = None) -> np.ndarray:
        """The exact sensitivity ``∂E_c/∂e_j`` at axis values ``q``.

        ``q`` of shape ``(V,)`` gives ``(6, N_err)``; ``(N, V)`` gives
        ``(N, 6, N_err)`` (float64, C-contiguous). Rows px, py, pz, ox, oy,
        oz; columns ``errors``. Computed on all cores, the GIL released, each
        value written once into the result.

        ``out``: an array of that shape (float64, C-contiguous, writeable) to
        write into instead of a new one, e.g. reused over batches of points;
        it is returned.
        """
        rows, single = _rows(q, "q", len(self.variables), "the variables " + ", ".join(self.variables))
        ne = len(self.errors)
        shape = (6, ne) if single else (rows.shape[0], 6, ne)
        if out is None:
            result = self._model.sensitivity(rows, _params(params)).reshape(rows.shape[0], 6, ne)
            return result[0] if single else result
        if not isinstance(out, np.ndarray):
            raise TypeError(f"out must be a numpy array, not {type(out).__name__}")
        if out.dtype != np.float64:
            raise ValueError(f"out must be float64, not {out.dtype}")
        if out.shape != shape:
            raise ValueError(f"out has shape {out.shape}, expected {shape}")
        if not out.flags.c_contiguous:
            raise ValueError("out must be C-contiguous")
        if not out.flags.writeable:
            raise ValueError("out must be writeable")
        self._model.sensitivity_into(rows, _params(params), out.reshape(-1))
        return out

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
        approach: Union[None, str, Mapping[str, str]] = None,
        temperature: Optional[Mapping[str, float]] = None,
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
          ``std``, ``correlation``) or a built machine's measured tables (a
          positioning run's means and repeatability), as ``--values``;
          ``approach``: the direction of its bidirectional tables
          (``--approach``: ``"up"``, ``"down"``, ``"mean"``, ``"x=up"`` or
          ``{"x": "up"}``);
        - ``acceptance=True``: also the whole-machine acceptance probability
          (the document's ``acceptance``; also computed when the file sets
          ``reliability.acceptance: true``), to ``acceptance_tolerance``;
        - ``temperature``: the thermal state of a machine with ``sensors``,
          ``{sensor: °C}`` (``--temperature``; docs/thermal.md).
        """
        if samples is not None and (not isinstance(samples, int) or isinstance(samples, bool) or samples < 0):
            raise ValueError(f"samples must be a non-negative integer, not {samples!r}")
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
            system_tolerance, path, acceptance, acceptance_tolerance, _approach(approach),
            _temperatures(temperature),
        )
        return ReliabilityResult._from_json(text)

    def inverse(
        self,
        poses: ArrayLike,
        fix: Optional[Mapping[str, float]] = None,
        params: Params = None,
    ) -> "InverseResult":
        """Inverse kinematics of tool poses, ``chain inverse --pose POSES --format json``.

        ``poses``: an ``(N, 6)`` array of ``px, py, pz, i, j, k`` (tool point
        and tool axis in the workpiece frame) or ``(N, 12)`` of ``px, py, pz,
        r11 … r33`` (the whole tool frame, row-major); one pose may be a 1-D
        row; or the path of a pose CSV, read as ``--pose`` reads it. ``fix``: values of the variables the pose does not determine
        (``--fix``). Built and checked by ``chain::ops::inverse`` as the CLI's.
        """
        from ._results import InverseResult

        if isinstance(poses, (str, os.PathLike)):
            text = _chain.inverse_json(self._model, None, _params(fix), _params(params), _file(poses))
            return InverseResult._from_json(text)
        a = _float_array(poses, "poses")
        if a.ndim == 1:
            a = a.reshape(1, -1)
        if a.ndim != 2:
            raise ValueError(f"poses of shape {a.shape}: expected (N, 6) or (N, 12)")
        text = _chain.inverse_json(self._model, np.ascontiguousarray(a), _params(fix), _params(params))
        return InverseResult._from_json(text)

    def path(
        self,
        axes: Optional[Union[ArrayLike, Mapping[str, ArrayLike]]] = None,
        poses: Optional[ArrayLike] = None,
        t: Optional[ArrayLike] = None,
        fix: Optional[Mapping[str, float]] = None,
        params: Params = None,
        method: str = "form",
        samples: Optional[int] = None,
        seed: int = 0,
        cov: Optional[float] = None,
        sided: Optional[str] = None,
        system: Optional[str] = None,
        system_tolerance: Optional[float] = None,
        temperature: Optional[Mapping[str, float]] = None,
    ) -> "PathResult":
        """Error and reliability along a path, ``chain path --axes AXES | --pose POSES --format json``.

        Give exactly one of ``axes`` and ``poses``:

        - ``axes``: an ``(N, V)`` array whose columns are :attr:`variables`
          in order, or a mapping ``{name: column}`` (a pandas DataFrame
          works) naming axis variables in any order, as the columns of
          ``--axes`` (an optional first ``"t"`` is the instant);
        - ``poses``: an ``(N, 6)`` or ``(N, 12)`` array of tool poses as for
          :meth:`inverse`, solved by the inverse kinematics;
        - either as the path of a CSV file, read as ``--axes`` or ``--pose``
          reads it.

        ``t``: the instants (``N`` values; the row numbers when omitted).
        ``fix``: variables held at a value (``--fix``). ``method``,
        ``samples``, ``seed``, ``cov``, ``sided``, ``system`` and
        ``system_tolerance`` are :meth:`reliability`'s; ``temperature``: the
        thermal state along the path (``--temperature``). Built, checked and
        run by ``chain::ops::path`` as the CLI's.
        """
        from ._results import PathResult

        if (axes is None) == (poses is None):
            raise ValueError("give the path as axes=... or poses=... (one of them)")
        # A file is read by the CLI's reader (its column t gives the instants).
        axes_file = _file(axes) if isinstance(axes, (str, os.PathLike)) else None
        poses_file = _file(poses) if isinstance(poses, (str, os.PathLike)) else None
        if (axes_file or poses_file) and t is not None:
            raise ValueError("t=... is given with a file; give the instants as its column t")
        header: List[str] = []
        axes_array = poses_array = t_array = None
        if t is not None:
            t_array = np.ascontiguousarray(_float_array(t, "t"))
            if t_array.ndim != 1:
                raise ValueError(f"t of shape {t_array.shape}: expected (N,)")
        if axes_file or poses_file:
            pass  # no arrays: Rust reads the file
        elif axes is not None:
            if isinstance(axes, Mapping) or hasattr(axes, "columns"):
                names = [str(k) for k in (axes.columns if hasattr(axes, "columns") else axes.keys())]
                columns = [_float_array(axes[k], f"axes[{k!r}]") for k in (axes.columns if hasattr(axes, "columns") else axes.keys())]
                for name, c in zip(names, columns):
                    if c.ndim != 1:
                        raise ValueError(f"axes[{name!r}] of shape {c.shape}: expected (N,)")
                if len({c.shape[0] for c in columns}) > 1:
                    raise ValueError("the columns of axes have different lengths")
                n = columns[0].shape[0] if columns else 0
                a = np.column_stack(columns) if columns else np.zeros((n, 0))
                header = names
            else:
                a = _float_array(axes, "axes")
                if a.ndim == 1:
                    a = a.reshape(1, -1)
                if a.ndim != 2 or a.shape[1] != len(self.variables):
                    raise ValueError(
                        f"axes of shape {a.shape}: expected (N, {len(self.variables)}), the columns {', '.join(self.variables)}"
                        " (or a mapping naming them)"
                    )
                header = list(self.variables)
            if t_array is not None:
                if t_array.shape[0] != a.shape[0]:
                    raise ValueError(f"t has {t_array.shape[0]} values for {a.shape[0]} rows of axes")
                if header[:1] == ["t"]:
                    raise ValueError("axes has a column \"t\" and t=... is given; give one of them")
                a = np.column_stack([t_array, a])
                header = ["t"] + header
            axes_array = np.ascontiguousarray(a, dtype=np.float64)
            t_array = None
        else:
            p = _float_array(poses, "poses")
            if p.ndim == 1:
                p = p.reshape(1, -1)
            if p.ndim != 2:
                raise ValueError(f"poses of shape {p.shape}: expected (N, 6) or (N, 12)")
            poses_array = np.ascontiguousarray(p)
        if not isinstance(method, str):
            raise ValueError(f"method must be a str, not {type(method).__name__}")
        text = _chain.path_json(
            self._model, header, axes_array, poses_array, t_array, _params(fix), _params(params),
            method, samples, seed, cov, sided, system, system_tolerance, axes_file, poses_file,
            _temperatures(temperature),
        )
        return PathResult._from_json(text)

    # -- the measured machine (group B: map, identify, plan) -----------------

    def map(
        self,
        values: Union[str, "os.PathLike[str]", Mapping[str, Any]],
        grid: Optional[Mapping[str, Sequence[float]]] = None,
        points: Optional[ArrayLike] = None,
        params: Params = None,
        approach: Union[None, str, Mapping[str, str]] = None,
        temperature: Optional[Mapping[str, float]] = None,
    ) -> "MapResult":
        """The error map of the built machine, ``chain map --values VALUES --format json``.

        ``values``: a values file's path, a values document as a dict
        (``{"units": ..., "values": {...}}``), or a plain ``{error: value}``
        dict (mm and rad). ``grid``: axes replacing the file's
        ``reliability.grid`` (``--grid``); ``points``: an ``(N, V)`` array of
        axis values in ``variables`` order instead (``--axes``).
        ``approach``: which direction of the bidirectional tables to map
        (``--approach``): ``"up"``, ``"down"``, ``"mean"`` (the default),
        ``"x=up,y=down"`` or ``{"x": "up"}``. ``temperature``: the thermal
        state of a machine with ``sensors``, ``{sensor: °C}``
        (``--temperature``; docs/thermal.md).
        """
        from ._results import MapResult

        path, text, name = _values_input(self, values)
        q = None
        if points is not None:
            q, _ = _rows(points, "points", len(self.variables), "the variables " + ", ".join(self.variables))
        text_json = _chain.map_json(
            self._model,
            path,
            text,
            name,
            _grid_axes(grid),
            q,
            _params(params),
            _approach(approach),
            _temperatures(temperature),
        )
        return MapResult._from_json(text_json)

    def export(
        self,
        values: Union[str, "os.PathLike[str]", Mapping[str, Any]],
        controller: str = "grid",
        grid: Optional[Mapping[str, Sequence[float]]] = None,
        points: Optional[ArrayLike] = None,
        step: Optional[float] = None,
        cec_max_points: Optional[int] = None,
        beckhoff_max_records: Optional[int] = None,
        params: Params = None,
        out: Union[None, str, "os.PathLike[str]"] = None,
        angles: bool = False,
        temperature: Optional[Mapping[str, float]] = None,
    ) -> "ExportResult":
        """Compensation for a controller, ``chain export --values VALUES --controller NAME --format json``.

        ``values`` as for :meth:`map`. ``controller``: ``"grid"`` (the
        universal grid CSV), ``"beckhoff"``, ``"linuxcnc"``,
        ``"siemens-cec"``, ``"klipper"``, or a rotary format of a
        table-table machine: ``"linuxcnc-trt"``, ``"heidenhain"``,
        ``"siemens-carr"``, ``"fanuc-tcp"``. ``grid``: the grid's nodes
        (``grid``) or each axis's travel (the per-axis tables and rotary
        formats), ``--grid``; ``points``: the grid export's nodes as an
        ``(N, V)`` array (``--axes``); ``step``, ``cec_max_points``,
        ``beckhoff_max_records``: the per-axis tables' options; ``angles``:
        heidenhain's angle rows (``--angles``); ``temperature``: the
        thermal state the tables are for (``--temperature``, as for
        :meth:`map`). The result's ``files`` maps
        each file's name to its text; ``out``: also write them into that
        folder (created if missing), as ``--out DIR``.
        """
        from ._results import ExportResult

        path, text, name = _values_input(self, values)
        q = None
        if points is not None:
            q, _ = _rows(points, "points", len(self.variables), "the variables " + ", ".join(self.variables))
        if not isinstance(controller, str):
            raise ValueError(f"controller must be a str, not {type(controller).__name__}")
        doc, files = _chain.export_json(
            self._model, path, text, name, controller, _grid_axes(grid), q,
            _optional_float(step, "step"), cec_max_points, beckhoff_max_records,
            _bool(angles, "angles"), _params(params), _temperatures(temperature),
        )
        result = ExportResult._from_json(doc)
        result.__dict__["files"] = dict(files)
        if out is not None:
            os.makedirs(out, exist_ok=True)
            for file_name, content in files:
                with open(os.path.join(out, file_name), "w", encoding="utf-8", newline="") as f:
                    f.write(content)
        return result

    def motion(
        self,
        settings: Union[str, "os.PathLike[str]", Mapping[str, Any]],
        order: int = 8,
        max_order: int = 40,
        samples: int = 1000,
        tolerance: Optional[float] = None,
        angular_tolerance: Optional[float] = None,
        params: Params = None,
        fix: Optional[Mapping[str, float]] = None,
    ) -> "MotionResult":
        """Motion conversion onto this CNC machine, ``chain motion FILE --settings SETTINGS --format json``.

        ``settings``: a settings file's path, or its document as a dict
        (relative paths in it are then resolved against the working
        directory). ``order``, ``max_order``, ``samples``, ``tolerance``,
        ``angular_tolerance``, ``params`` (``--param``) and ``fix``
        (``--fix``) are the CLI's options. The result's ``times`` (``(K,)``)
        and ``exact`` (``(K, V)``, :attr:`variables` order) are the exact
        motion, the CLI's ``--format csv``.
        """
        import json

        from ._results import MotionResult

        if isinstance(settings, (str, os.PathLike)):
            path, text, name = os.fspath(settings), None, os.fspath(settings)
        elif isinstance(settings, Mapping):
            try:
                path, text, name = None, json.dumps(dict(settings), allow_nan=False), "<settings>"
            except (TypeError, ValueError) as e:
                raise ValueError(f"settings: {e}") from None
        else:
            raise ValueError(f"settings must be a settings file's path or a dict, not {type(settings).__name__}")
        for key, value in (("order", order), ("max_order", max_order), ("samples", samples)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise ValueError(f"{key} must be a non-negative integer, not {value!r}")
        doc, times, exact = _chain.motion_json(
            self._model, path, text, name, order, max_order, samples,
            _optional_float(tolerance, "tolerance"), _optional_float(angular_tolerance, "angular_tolerance"),
            _params(params), _params(fix),
        )
        result = MotionResult._from_json(doc)
        result.__dict__["times"] = np.asarray(times, dtype=np.float64)
        result.__dict__["exact"] = np.asarray(exact, dtype=np.float64).reshape(len(times), len(self.variables))
        return result

    def identify(
        self,
        measurements: Optional[Union[str, "os.PathLike[str]", Mapping[str, ArrayLike]]] = None,
        prior: bool = False,
        params: Params = None,
        values_out: Optional[Union[str, "os.PathLike[str]"]] = None,
        name: str = "<measurements>",
        validate: Optional[Union[str, "os.PathLike[str]", Mapping[str, ArrayLike]]] = None,
        validate_name: str = "<validation>",
        rank_tol: Optional[float] = None,
        fix: Optional[Sequence[str]] = None,
        estimate: Optional[Sequence[str]] = None,
        iterate: bool = False,
        holdout: Optional[float] = None,
        seed: Optional[int] = None,
        spheres: Optional[Union[str, "os.PathLike[str]", Mapping[str, Any]]] = None,
        setup: Optional[str] = None,
        temperature: Optional[Mapping[str, float]] = None,
        circular: Optional[Union[str, "os.PathLike[str]", Mapping[str, Any]]] = None,
        centre: Optional[Mapping[str, float]] = None,
        axes: bool = False,
        radius: Optional[float] = None,
        feed: Optional[float] = None,
        plane: Optional[str] = None,
        arc: Optional[float] = None,
    ) -> "IdentifyResult":
        """The error parameters from measurements, ``chain identify --measurements M --format json``.

        ``measurements``: the CSV's path, its text (a string holding a
        line break), or its columns as a dict of 1-D arrays (a pandas
        DataFrame works too) named as the CSV's header: the axis variables,
        any per-row parameters, ``dpx, dpy, dpz`` or ``ux, uy, uz, d``,
        optionally ``std``; ``name`` names them in messages and in the
        document's ``file``. ``spheres`` (``--spheres``), instead of
        ``measurements``: sphere probings as a path, CSV text or columns
        (every axis variable, rotary ones in degrees; optionally ``sphere``,
        whose values may be text, and ``std``); each sphere's position is
        estimated beside the errors (the document's ``setups``), never
        written into values. ``setup="ball"`` (``--setup ball``): the
        measurement records are an R-test's, whose ball set-up offsets are
        estimated likewise. ``prior``: the
        ``statistics`` as a Gaussian prior (``--prior``); ``values_out``:
        also write the estimates as a values file (``--values-out``);
        ``validate``: records held out of the fit, as ``measurements`` (or
        ``spheres``) (``--validate``; ``validate_name`` names text or
        columns): the document's ``validation`` gives the error they show
        before and after the estimates' correction. ``rank_tol``
        (``--rank-tol``): a fixed relative tolerance instead of the noise
        rule; ``fix`` / ``estimate`` (``--fix`` / ``--estimate``): the error
        parameters to fix at 0, or the only ones to estimate, instead of the
        elimination's choice (the document's ``subset``); ``iterate``
        (``--iterate``): fit the exact kinematics from the linear estimate
        (the document's ``iteration``); ``holdout`` / ``seed``
        (``--holdout`` / ``--seed``): hold that fraction of the records out
        of the fit and report the prediction at them (``validation``).
        A machine with ``sensors``: a column named after a sensor gives each
        record's temperature (°C), and the thermal coefficients are
        identified with the geometric ones; ``temperature``
        (``--temperature``, ``{sensor: °C}``) is the state of the records
        whose file has no column for a sensor (docs/thermal.md).
        ``circular`` (``--circular``), instead of ``measurements``: a
        circular-test file (a ballbar's runs, as ``chain.circular`` reads
        them: path, text or columns): each sample a measurement along the
        nominal ball-to-ball direction, each run's table-ball offset and bar
        length estimated beside the errors (``setups``); placed by
        ``centre`` (``--centre``, ``{variable: value}``, rotary in degrees:
        the circle's centre) or ``axes=True`` (``--axes``: each sample's pose
        in the file's columns named after the machine's variables);
        ``radius``, ``feed``, ``plane``, ``arc`` as ``chain.circular``'s.
        """
        from ._results import IdentifyResult

        def file_input(data: Any, what: str, label: str, text_columns: Sequence[str] = ()) -> Tuple[Optional[str], Optional[str], str]:
            if isinstance(data, str) and "\n" in data:
                return (None, data, label)
            path, text = _csv_input(data, what, text_columns)
            return (path, text, path if path is not None else label)

        text_columns = ("sphere",) if spheres is not None else ()
        records = None if measurements is None else file_input(measurements, "measurements", name)
        probings = None if spheres is None else file_input(spheres, "spheres", name if name != "<measurements>" else "<spheres>", ("sphere",))
        runs = None if circular is None else file_input(circular, "circular", name if name != "<measurements>" else "<runs>", ("direction", "run", "plane"))
        if circular is not None:
            text_columns = ("direction", "run", "plane")
        held_out = None if validate is None else file_input(validate, "validate", validate_name, text_columns)
        if centre is not None and not isinstance(centre, Mapping):
            raise ValueError(f"centre must be a mapping {{variable: value}}, not {type(centre).__name__}")
        if plane is not None and not isinstance(plane, str):
            raise ValueError(f"plane must be 'xy', 'yz' or 'zx', not {plane!r}")
        doc, values_text = _chain.identify_json(
            self._model,
            records,
            probings,
            None if setup is None else str(setup),
            _params(params),
            bool(prior),
            held_out,
            None if rank_tol is None else float(rank_tol),
            None if fix is None else [str(n) for n in fix],
            None if estimate is None else [str(n) for n in estimate],
            bool(iterate),
            None if holdout is None else float(holdout),
            None if seed is None else int(seed),
            _temperatures(temperature),
            runs,
            None if centre is None else [(str(k), _optional_float(v, f"centre[{k!r}]")) for k, v in centre.items()],
            bool(axes),
            _optional_float(radius, "radius"),
            _optional_float(feed, "feed"),
            plane,
            _optional_float(arc, "arc"),
        )
        if values_out is not None:
            with open(os.fspath(values_out), "w", encoding="utf-8") as f:
                f.write(values_text)
        import json

        return IdentifyResult(json.loads(doc), values_text)

    def plan(
        self,
        candidates: Union[str, "os.PathLike[str]", Mapping[str, ArrayLike]],
        k: int,
        kind: Optional[str] = None,
        params: Params = None,
        name: str = "<candidates>",
        spheres: bool = False,
    ) -> "PlanResult":
        """Where to measure, ``chain plan --candidates C --count K --format json``.

        ``candidates``: the candidate CSV's path or its columns as a dict of
        1-D arrays (the axis variables, any per-row parameters, ``ux, uy,
        uz`` for directions, optionally ``std``); ``k``: how many to choose
        (``--count``); ``kind``: ``"point"`` or ``"direction"`` (``--kind``).
        ``spheres=True`` (``--spheres-candidates``): the candidates are
        sphere probings (the sphere file's columns: rotary axes in degrees,
        optionally ``sphere``, whose values may be text, and ``std``), each
        sphere's position counted among the unknowns.
        """
        from ._results import PlanResult

        if not isinstance(k, int) or isinstance(k, bool) or k < 1:
            raise ValueError(f"k must be a positive integer (the count of candidates to choose), not {k!r}")
        path, text = _csv_input(candidates, "candidates", ("sphere",) if spheres else ())
        doc = _chain.plan_json(self._model, path, text, name, k, kind, _params(params), bool(spheres))
        return PlanResult._from_json(doc)


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

    def sensitivity_reliability(
        self,
        at: Optional[Mapping[str, float]] = None,
        grid: Optional[Mapping[str, Sequence[float]]] = None,
        params: Params = None,
        sided: Optional[str] = None,
        values: Optional[Union[str, "os.PathLike[str]"]] = None,
        approach: Union[None, str, Mapping[str, str]] = None,
        temperature: Optional[Mapping[str, float]] = None,
    ) -> SensitivityResult:
        """Reliability sensitivity, ``chain sensitivity --kind reliability --format json``.

        The sensitivity of each toleranced component's reliability to the
        mean and standard deviation of every error parameter (Wang & Yuan
        2021 Eq. 32-33) and its FORM importance factor, sorted by
        ``|dR/dstd|``: at one point ``at`` (every axis variable), otherwise
        the mean over the reliability grid (``grid`` replacing axes).
        ``values``: a values file with a calibration's posterior (``--values``);
        ``approach``: the direction of its bidirectional tables (``--approach``);
        ``temperature``: the thermal state (``--temperature``).
        """
        point = _at_point(at)
        path = None if values is None else os.fspath(values)
        text = _chain.sensitivity_reliability_json(
            self._model,
            point,
            _grid_axes(grid),
            _params(params),
            sided,
            path,
            _approach(approach),
            _temperatures(temperature),
        )
        return SensitivityResult._from_json(text)

    def geometric_sensitivity(
        self,
        at: Optional[Mapping[str, float]] = None,
        grid: Optional[Mapping[str, Sequence[float]]] = None,
        sizes: Optional[Union[str, Mapping[str, Union[float, str]]]] = None,
        params: Params = None,
    ) -> GeometricSensitivityResult:
        """Geometric error sensitivity, ``chain sensitivity --kind geometric --format json``.

        Fan et al. 2020's coefficients ``S = |dE/de|`` and ``C = S*e / sum(S*e)``
        per direction (Eq. 5-6): at one point ``at`` (every axis variable),
        otherwise the mean over the reliability grid (``grid`` replacing or
        adding axes; not with ``at``). ``sizes``: the nominal error sizes
        ``e``, as ``--values`` spells them (``"linear=0.001,angular=0.001deg"``)
        or a mapping ``{"linear": 0.001, "angular": "0.001deg"}`` (angles in
        radians, or strings with a ``deg`` suffix; ``squareness`` follows
        ``angular`` unless given); default 0.001 mm and 0.001 degrees.
        """
        point = _at_point(at)
        if sizes is None or isinstance(sizes, str):
            text_sizes = sizes
        elif isinstance(sizes, Mapping):
            text_sizes = ",".join(f"{k}={v if isinstance(v, str) else repr(float(v))}" for k, v in sizes.items())
        else:
            raise ValueError(f"sizes must be a str or a mapping of error kind to size, not {type(sizes).__name__}")
        text = _chain.geometric_json(self._model, point, _grid_axes(grid), _params(params), text_sizes)
        return GeometricSensitivityResult._from_json(text)

    def allocate(
        self,
        strategy: str = "optimal",
        step: float = 0.005,
        threshold: float = 0.1,
        rank: str = "component",
        target: str = "requirement",
        level: Optional[float] = None,
        params: Params = None,
        sided: Optional[str] = None,
    ) -> AllocationResult:
        """Precision allocation, ``chain allocate --format json`` (docs/allocation.md).

        ``strategy="optimal"``: the least-cost standard deviations meeting the
        requirement, with the KKT check; ``"paper"``: Wang & Yuan 2021's
        rounds (``step`` in Table 1's tolerance units, ``threshold`` a fraction
        of the largest sensitivity, ``rank`` ``"component"`` or ``"pooled"``).
        ``target="requirement"`` (the reliability section's) or
        ``"acceptance"`` with ``level`` in (0, 1): the whole-machine
        acceptance probability. An allocation that misses its target is
        returned with ``final["met"]`` false (the CLI exits non-zero).
        """
        step = _optional_float(step, "step")
        threshold = _optional_float(threshold, "threshold")
        level = _optional_float(level, "level")
        text = _chain.allocate_json(self._model, strategy, step, threshold, rank, target, level, _params(params), sided)
        return AllocationResult._from_json(text)


# -- group B helpers ----------------------------------------------------------


def _file(path: Union[str, "os.PathLike[str]"]) -> Tuple[Optional[str], Optional[str], str]:
    """A file argument of the compiled core, ``(path, text, name)``: here its path, named so."""
    return os.fspath(path), None, os.fspath(path)


def _grid_axes(grid: Optional[Mapping[str, Sequence[float]]]) -> List[Tuple[str, List[float]]]:
    if grid is None:
        return []
    if not isinstance(grid, Mapping):
        raise ValueError(f"grid must be a mapping of axis variable to values, not {type(grid).__name__}")
    axes = []
    for name, values in grid.items():
        a = _float_array(values, f"grid[{name!r}]").ravel()
        axes.append((str(name), [float(v) for v in a]))
    return axes


def _values_input(machine: "Machine", values: Any) -> Tuple[Optional[str], Optional[str], str]:
    """A values file's path, or a dict as the values file's text (JSON is YAML)."""
    import json

    if isinstance(values, (str, os.PathLike)):
        return os.fspath(values), None, os.fspath(values)
    if not isinstance(values, Mapping):
        raise ValueError(f"values must be a values file's path or a dict, not {type(values).__name__}")
    if "values" in values:
        doc = dict(values)
    else:
        doc = {"units": {"linear": "mm", "angular": "rad"}, "values": dict(values)}
    doc.setdefault("machine", machine.name)
    try:
        text = json.dumps(doc, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise ValueError(f"values: {e}") from None
    return None, text, "<values>"


def _table_source(data: Any, what: str) -> Tuple[Optional[str], Optional[Mapping[str, Any]]]:
    """A CSV given as its path (``(path, None)``) or as columns: a dict, or a DataFrame's (``(None, columns)``)."""
    if isinstance(data, (str, os.PathLike)):
        return os.fspath(data), None
    if hasattr(data, "columns") and hasattr(data, "__getitem__") and not isinstance(data, Mapping):
        data = {str(c): data[c].to_numpy() for c in data.columns}
    if not isinstance(data, Mapping):
        raise ValueError(f"{what} must be a CSV path or a dict of columns, not {type(data).__name__}")
    if not data:
        raise ValueError(f"{what} has no column")
    return None, data


def _csv_input(data: Any, what: str, text_columns: Sequence[str] = ()) -> Tuple[Optional[str], Optional[str]]:
    """A CSV path, or columns (a dict of 1-D arrays, or a DataFrame) as the CSV's text.

    Columns named in ``text_columns`` (a sphere's identifier) are written as
    their values' text; every other column must hold finite numbers.
    """
    path, data = _table_source(data, what)
    if data is None:
        return path, None
    names = [str(n) for n in data]
    columns: List[Any] = []
    n = None
    for name, values in zip(names, data.values()):
        if name in text_columns:
            cells = [str(v) for v in (values.tolist() if hasattr(values, "tolist") else list(values))]
            bad = [c for c in cells if "," in c or "\n" in c or '"' in c]
            if bad:
                raise ValueError(f"{what}[{name!r}] has an identifier {bad[0]!r} with a comma, quote or line break")
            if n is None:
                n = len(cells)
            elif len(cells) != n:
                raise ValueError(f"{what}[{name!r}] has {len(cells)} values, {names[0]!r} has {n}")
            columns.append(cells)
            continue
        a = _float_array(values, f"{what}[{name!r}]")
        if a.ndim != 1:
            raise ValueError(f"{what}[{name!r}] of shape {a.shape}: expected a 1-D column")
        if n is None:
            n = a.shape[0]
        elif a.shape[0] != n:
            raise ValueError(f"{what}[{name!r}] has {a.shape[0]} values, {names[0]!r} has {n}")
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise ValueError(f"{what}[{name!r}] has a non-finite value ({a[bad[0]]}) at row {bad[0]}")
        columns.append(a)
    lines = [",".join(names)]
    for i in range(n or 0):
        lines.append(",".join(c[i] if isinstance(c, list) else repr(float(c[i])) for c in columns))
    return None, "\n".join(lines) + "\n"


def _bool(x: Any, name: str) -> bool:
    """``x`` when it is a bool; anything else raises ValueError naming ``name``."""
    if not isinstance(x, bool):
        raise ValueError(f"{name} must be True or False, not {x!r}")
    return x


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


def _at_point(at: Optional[Mapping[str, float]]) -> Optional[List[Tuple[str, float]]]:
    """``at`` as ``(variable, value)`` pairs (``None`` stays ``None``)."""
    if at is None:
        return None
    if not isinstance(at, Mapping):
        raise ValueError(f"at must be a mapping of axis variable to value, not {type(at).__name__}")
    point = []
    for name, value in at.items():
        try:
            point.append((str(name), float(value)))
        except (TypeError, ValueError):
            raise ValueError(f"at: `{name}` = {value!r} is not a number") from None
    return point
