"""Result objects: a CLI JSON document with attributes, ``to_dict()`` and ``to_dataframe()``.

Every result wraps the document the CLI prints with ``--format json`` for the
same input (``to_dict()`` returns it, a fresh copy each call). Its top-level
keys are attributes (``result.summary``, ``result.method``). A new result type
is a subclass naming its command and, where it has rows, the rows of its
data frame: see ``ReliabilityResult``.
"""

from __future__ import annotations

import copy
import json
from typing import Any, Dict, Iterator, List, Optional


def _frame(rows: List[Dict[str, Any]]) -> Any:
    """``rows`` as a pandas DataFrame (pandas must be installed)."""
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("to_dataframe() needs pandas: pip install pandas") from e
    return pandas.DataFrame(rows)


class Result:
    """A result document of one ``chain`` command (``command`` names it)."""

    command: str = ""

    def __init__(self, document: Dict[str, Any]) -> None:
        self._document = document

    @classmethod
    def _from_json(cls, text: str) -> "Result":
        return cls(json.loads(text))

    def to_dict(self) -> Dict[str, Any]:
        """The document as the CLI's JSON gives it (``json.loads`` of ``--format json``)."""
        return copy.deepcopy(self._document)

    def keys(self) -> List[str]:
        """The document's top-level keys (each is also an attribute)."""
        return list(self._document)

    def __getattr__(self, name: str) -> Any:
        document = self.__dict__.get("_document")
        if document is not None and name in document:
            return document[name]
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r} (keys: {', '.join(document or [])})")

    def __getitem__(self, key: str) -> Any:
        return self._document[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._document)

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self._document))

    def __repr__(self) -> str:
        return f"<{type(self).__name__} of `chain {self.command}`: {', '.join(self._document)}>"

    def _rows(self) -> List[Dict[str, Any]]:
        raise TypeError(f"{type(self).__name__} has no tabular form")

    def to_dataframe(self) -> Any:
        """The result's rows as a pandas DataFrame (pandas must be installed)."""
        return _frame(self._rows())


class Derivation(Result):
    """``chain derive --format json``: the exact first-order model.

    Rows of ``to_dataframe()``: one per non-zero coefficient (component,
    error, expression).
    """

    command = "derive"

    def _rows(self) -> List[Dict[str, Any]]:
        rows = []
        for component, entries in self._document["components"].items():
            for error, expression in entries.items():
                rows.append({"component": component, "error": error, "coefficient": expression})
        return rows


class ReliabilityResult(Result):
    """``chain reliability --format json``: reliability of each target over the grid.

    Attributes: ``machine``, ``method``, ``sided``, ``results`` (one dict per
    case), ``summary`` (per target: mean, min, max, met), ``requirement``
    when the file sets one. Rows of ``to_dataframe()``: one per case, the
    grid coordinates as columns.
    """

    command = "reliability"

    def _rows(self) -> List[Dict[str, Any]]:
        rows = []
        for case in self._document["results"]:
            row = {"component": case["component"]}
            row.update(case["point"])
            for key, value in case.items():
                if key in ("component", "point"):
                    continue
                if isinstance(value, dict):
                    for k, v in value.items():
                        row[f"{key}_{k}"] = v
                else:
                    row[key] = value
            rows.append(row)
        return rows


# -- group B: the measured machine (map, identify, plan, compensate) ---------


class MapResult(Result):
    """``chain map --format json``: the volumetric error of a built machine at every point.

    Attributes: ``machine``, ``frame``, ``points`` (one dict per point:
    ``point``, ``error`` px..oz, ``volumetric``), ``summary`` (the ISO
    230-1-style summary), and with bidirectional tables ``reversals`` (per
    table the reversal the chosen approach leaves out). Rows of ``to_dataframe()``: one per point, the
    axis variables, px..oz and ``volumetric`` as columns.
    """

    command = "map"

    def _rows(self) -> List[Dict[str, Any]]:
        rows = []
        for p in self._document["points"]:
            row = dict(p["point"])
            row.update(p["error"])
            row["volumetric"] = p["volumetric"]
            rows.append(row)
        return rows


class IdentifyResult(Result):
    """``chain identify --format json``: the error parameters estimated from measurements.

    Attributes: ``machine``, ``measurements``, ``parameters``, ``rank``,
    ``condition``, ``estimates`` (per error: value, std; the minimum-norm
    solution), ``unidentifiable``, ``residual``, ``groups``,
    ``largest_residuals``, ``noise`` (how the rank was decided), ``subset``
    (the estimated errors, their least-squares values, the fixed errors and
    their relations; absent with ``prior``), ``validation`` (with
    ``validate=``: the held-out error before and after), ... ``values_text`` is
    the values file ``--values-out`` writes (also written to ``values_out``
    when given). Rows of ``to_dataframe()``: one per error (error, value, std;
    with a subset also subset_value, subset_std and status: ``estimated`` or
    why the error is fixed).
    """

    command = "identify"

    def __init__(self, document: Dict[str, Any], values_text: str = "") -> None:
        super().__init__(document)
        self.__dict__["values_text"] = values_text

    def _rows(self) -> List[Dict[str, Any]]:
        d = self._document
        rows = [{"error": name, "value": e["value"], "std": e["std"]} for name, e in d["estimates"].items()]
        sub = d.get("subset")
        if sub is not None:
            status = {f["error"]: f["status"] for f in sub["fixed"]}
            for row in rows:
                s = sub["estimates"][row["error"]]
                row.update(subset_value=s["value"], subset_std=s["std"], status=status.get(row["error"], "estimated"))
        return rows


class PlanResult(Result):
    """``chain plan --format json``: where to measure (D-optimal choice of candidates).

    Attributes: ``machine``, ``candidates_file``, ``kind``, ``variables``,
    ``rank``, ``errors``, ``aliased``, ``optimal`` and ``even`` (candidates,
    log_det, std), ``swaps``, ``sweeps``, ... Rows of ``to_dataframe()``: one
    per error parameter (aliased, expected std D-optimal and even).
    """

    command = "plan"

    def _rows(self) -> List[Dict[str, Any]]:
        d = self._document
        return [
            {"error": e, "aliased": d["aliased"][j], "optimal_std": d["optimal"]["std"][j], "even_std": d["even"]["std"][j]}
            for j, e in enumerate(d["errors"])
        ]
class SobolResult(Result):
    """``chain sobol --format json``: first-order and total Sobol indices.

    Attributes: ``machine``, ``method`` (``saltelli-jansen``), ``at`` (the
    point, or ``None`` when pooled over the grid), ``grid`` (when pooled),
    ``points``, ``samples``, ``seed``, ``bootstrap``, ``confidence``,
    ``blocks``, ``evaluations_per_point``, ``outputs`` (per output: variance,
    sum_first, sum_total, errors). Rows of ``to_dataframe()``: one per
    output and error, as the CLI's CSV (first, first_low, first_high, total,
    total_low, total_high, exact).
    """

    command = "sobol"

    def _rows(self) -> List[Dict[str, Any]]:
        rows = []
        for output, doc in self._document["outputs"].items():
            for e in doc["errors"]:
                rows.append({
                    "output": output,
                    "error": e["error"],
                    "first": e["first"]["value"],
                    "first_low": e["first"]["low"],
                    "first_high": e["first"]["high"],
                    "total": e["total"]["value"],
                    "total_low": e["total"]["low"],
                    "total_high": e["total"]["high"],
                    "exact": e["first"].get("exact"),
                })
        return rows


class SensitivityResult(Result):
    """``chain sensitivity --kind reliability --format json``.

    Attributes: ``machine``, ``at`` (the point, or ``None`` for the grid
    mean), ``methods`` (per target: ``exact`` or ``form``), ``components``
    (per target: the errors sorted by ``|dr_dstd|``, each with ``dr_dstd``,
    ``dr_dmean``, ``importance`` and, for the grid mean,
    ``mean_abs_dr_dstd``, ``mean_abs_dr_dmean``), ``posterior`` (when
    ``values`` was given). Rows of ``to_dataframe()``: one per target and
    error.
    """

    command = "sensitivity"

    def _rows(self) -> List[Dict[str, Any]]:
        return [
            {"target": target, "method": self._document["methods"][target], **e}
            for target, errors in self._document["components"].items()
            for e in errors
        ]


class GeometricSensitivityResult(Result):
    """``chain sensitivity --kind geometric --format json``.

    Attributes: ``machine``, ``kind`` (``geometric``), ``at`` (the point, or
    ``None`` for the grid mean), ``grid`` and ``points`` (grid mean),
    ``normalisation``, ``values`` (the nominal sizes), ``totals`` (``sum(S*e)``
    per direction), ``components`` (per direction: every error ranked by
    ``c``, with ``s``, ``c``, ``e`` and, for the grid mean, ``c_min``,
    ``c_max``). Rows of ``to_dataframe()``: one per direction and error.
    """

    command = "sensitivity --kind geometric"

    def _rows(self) -> List[Dict[str, Any]]:
        return [
            {"component": component, **e}
            for component, errors in self._document["components"].items()
            for e in errors
        ]


class AllocationResult(Result):
    """``chain allocate --format json`` (docs/allocation.md).

    Attributes: ``machine``, ``strategy`` (``optimal`` or ``paper``),
    ``requirement``, ``initial`` (``std`` per error, ``summary`` per
    component), ``steps`` (the paper's rounds), ``final`` (``std``, ``cost``,
    ``met``, ``summary``), ``kkt`` (optimal), ``acceptance`` (target
    acceptance). Rows of ``to_dataframe()``: one per error, its initial and
    allocated standard deviation.
    """

    command = "allocate"

    def _rows(self) -> List[Dict[str, Any]]:
        d = self._document
        return [
            {"error": e, "std0": s0, "std": d["final"]["std"][e], "ratio": s0 / d["final"]["std"][e]}
            for e, s0 in d["initial"]["std"].items()
        ]


class PositioningResult(Result):
    """``chain positioning --format json``: the ISO 230-2 evaluation of positioning runs.

    Attributes: ``k``, ``runs``, ``unit``, ``targets`` (per target: means,
    reversal, s, repeatabilities), ``axis`` (``A``, ``E``, ``M``, ``R``,
    ``B``, ``B_mean`` and the per-direction values), ``axis_kind``,
    ``target_unit``, ``file``, ``points``; ``values_text``: the values file
    of ``machine`` and ``slot`` (``--values-out``), or None. Rows of
    ``to_dataframe()``: one per target.
    """

    command = "positioning"
    values_text: Optional[str] = None

    def _rows(self) -> List[Dict[str, Any]]:
        return [dict(t) for t in self._document["targets"]]


class ThermalResult(Result):
    """``chain thermal --format json``: an ISO 230-3 drift test and, with a fit, its thermal models.

    Attributes: ``file``, ``samples``, ``duration``, ``channels`` (per
    displacement channel: ``name``, ``unit``, ``range``, ``max_drift``,
    ``max_drift_at``; with a fit ``model``, ``fit``, ``holdout``),
    ``temperatures``, ``pairs``, ``fit`` (the fit period). ``time``: the
    samples' times (s); ``measured`` and ``predicted``: per channel name,
    the drift and the model's prediction at every sample (with a fit), as
    arrays. Rows of ``to_dataframe()``: one per displacement channel.
    """

    command = "thermal"
    time: Any = None
    measured: Dict[str, Any] = {}
    predicted: Dict[str, Any] = {}

    def _rows(self) -> List[Dict[str, Any]]:
        return [{k: v for k, v in c.items() if not isinstance(v, dict)} for c in self._document["channels"]]


class CircularResult(Result):
    """``chain circular --format json``: an ISO 230-4 circular test evaluated per run and direction.

    Attributes: ``file``, ``unit`` (``mm``), ``centre`` (``least_squares``),
    ``arc``, ``runs`` (per run: ``run``, ``plane``, ``radius``, ``feed``,
    ``directions`` with ``ccw`` and ``cw`` each ``G``, ``F_max``, ``F_min``,
    ``centre``, ``radius_offset``, ``samples``; ``G_b``, ``H``,
    ``centre_both``), ``diagnosis`` (per error ``error``, ``plane``,
    ``axes``, ``run``, ``value``, ``unit``, ``uncertainty``, ``sign``,
    ``share``, ``shares``), ``fit`` (per plane). Rows of ``to_dataframe()``:
    one per run and direction; of ``diagnosis_frame()``: one per error.
    """

    command = "circular"

    def diagnosis_frame(self) -> Any:
        """The diagnosis as a pandas DataFrame: one row per error (its axes
        joined by ``-``)."""
        rows = []
        for e in self._document["diagnosis"]:
            rows.append(
                {
                    "error": e["error"],
                    "plane": e["plane"],
                    "axes": "-".join(e["axes"]),
                    "run": e["run"],
                    "value": e["value"],
                    "unit": e["unit"],
                    "uncertainty": e["uncertainty"],
                    "share": e["share"],
                }
            )
        return _frame(rows)

    def _rows(self) -> List[Dict[str, Any]]:
        rows = []
        for r in self._document["runs"]:
            for direction, d in r["directions"].items():
                rows.append(
                    {
                        "run": r["run"],
                        "plane": r["plane"],
                        "radius": r["radius"],
                        "feed": r["feed"],
                        "direction": direction,
                        "G": d["G"],
                        "F_max": d["F_max"],
                        "F_min": d["F_min"],
                        "centre_1": d["centre"][0],
                        "centre_2": d["centre"][1],
                        "G_b": r["G_b"],
                        "H": r["H"],
                    }
                )
        return rows


class InverseResult(Result):
    """``chain inverse --format json``: the axis values that reach each tool pose.

    Attributes: ``machine``, ``method``, ``variables``, ``rows`` (per pose:
    ``row`` (1-based), ``status``, ``solutions`` as ``{variable: value}``).
    Rows of ``to_dataframe()``: one per solution (``row``, ``status``,
    ``solution`` and the variables), as ``--format csv``; an unreachable pose
    has one row without values.
    """

    command = "inverse"

    def _rows(self) -> List[Dict[str, Any]]:
        out: List[Dict[str, Any]] = []
        for r in self._document["rows"]:
            if not r["solutions"]:
                out.append({"row": r["row"], "status": r["status"], "solution": None})
            for j, q in enumerate(r["solutions"]):
                row = {"row": r["row"], "status": r["status"], "solution": j + 1}
                row.update(q)
                out.append(row)
        return out


class PathResult(Result):
    """``chain path --format json``: error and reliability at every instant of a path.

    Attributes: ``machine``, ``method``, ``input`` (``axes`` or ``pose``),
    ``frame``, ``sided``, ``tolerances``, ``variables``, ``instants`` (per
    instant: ``row``, ``t``, ``axes``, ``status``, ``nominal``, ``mean``,
    ``std``, ``reliability``, ...), ``summary``. Rows of ``to_dataframe()``:
    one per instant (``row``, ``t``, ``status``, the axis values, then
    ``mean_<q>``, ``std_<q>`` and ``reliability_<target>``).
    """

    command = "path"

    def _rows(self) -> List[Dict[str, Any]]:
        out: List[Dict[str, Any]] = []
        for i in self._document["instants"]:
            row: Dict[str, Any] = {"row": i["row"], "t": i["t"], "status": i["status"]}
            row.update(i["axes"] or {v: None for v in self._document["variables"]})
            for key in ("mean", "std", "reliability"):
                for name, value in (i[key] or {}).items():
                    row[f"{key}_{name}"] = value
            out.append(row)
        return out


class ExportResult(Result):
    """``chain export --format json``: the compensation of a built machine for a controller.

    Attributes: the summary the CLI prints (grid: ``values_file``, ``files``,
    ``machine``, ``frame``, ``variables``, ``summary``; a per-axis format:
    ``values_file``, ``controller``, ``files``, ``axes``, ``expressed``,
    ``remaining``, ``residual``, ...), and ``files``: each file's name
    mapped to its text (what ``--out DIR`` writes). Rows of
    ``to_dataframe()``: the grid CSV's nodes (grid), or one per table axis.
    """

    command = "export"
    files: Dict[str, str] = {}

    def _rows(self) -> List[Dict[str, Any]]:
        import csv
        import io

        if "axes" in self._document:
            return [dict(a) for a in self._document["axes"]]
        (text,) = self.__dict__["files"].values()
        lines = [line for line in text.splitlines() if line and not line.startswith("#")]
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(io.StringIO("\n".join(lines)))]


class MotionResult(Result):
    """``chain motion --format json``: CNC axis motions reproducing a generator's roll, and their series.

    Attributes: ``machine``, ``generator``, ``settings``, ``match``,
    ``variables``, ``units``, ``parameters``, ``fixed``, ``generator_laws``,
    ``interval``, ``samples``, ``equivalence``, ``order``, ``at_zero``,
    ``coefficients``, ``derivatives``, ``truncation_error``,
    ``errors_by_order``, ``required_order``; and ``times`` (``(K,)``) and
    ``exact`` (``(K, V)``), the exact motion. Rows of ``to_dataframe()``: one
    per instant (``t`` and the axes), as ``--format csv``.
    """

    command = "motion"

    def _rows(self) -> List[Dict[str, Any]]:
        names = self._document["variables"]
        return [
            dict({"t": float(t)}, **{v: float(x) for v, x in zip(names, q)})
            for t, q in zip(self.__dict__["times"], self.__dict__["exact"])
        ]


class CompensateResult(Result):
    """``chain compensate --format json``: a swing-angle error identified from tool-tip heights.

    Attributes: ``file``, ``length``, ``points`` (per measured angle: the
    heights, ΔZ, Δθ, the fit and its residual), ``fits`` (per order: R²,
    adjusted R², RMSE, LOOCV, AICc, BIC, F-test p, coefficients),
    ``selected_order``, ``selection``, ``law``, ... as the CLI's document.
    Rows of ``to_dataframe()``: one per measured point.
    """

    command = "compensate"

    def _rows(self) -> List[Dict[str, Any]]:
        return [dict(p) for p in self._document["points"]]


class ReportResult(Result):
    """``chain report``: the calibration report's page and its documents.

    ``html``: the page (``str(result)`` too). Attributes (``to_dict()``, the
    CLI's ``--format json``): ``file``, ``cover``, ``chain_version``,
    ``machine``, ``inputs`` (each ``role``, ``path``, ``bytes``,
    ``sha256``), ``positioning`` (per axis ``axis``, ``document``,
    ``verdicts``), ``map``, ``identify``, ``export``, ``circular``,
    ``thermal`` (each a command's document, or ``None``). Rows of ``to_dataframe()``: one per
    ISO 230-2 verdict.
    """

    command = "report"

    def __init__(self, document: Dict[str, Any], html: str = "") -> None:
        super().__init__(document)
        self.__dict__["html"] = html

    @classmethod
    def _from_json(cls, text: str, html: str = "") -> "ReportResult":  # type: ignore[override]
        return cls(json.loads(text), html)

    def __str__(self) -> str:
        return self.__dict__["html"]

    def _rows(self) -> List[Dict[str, Any]]:
        rows = []
        for a in self._document["positioning"]:
            for v in a["verdicts"]:
                rows.append({"axis": a["axis"], **v})
        return rows

