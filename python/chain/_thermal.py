"""``chain.thermal``: an ISO 230-3 thermal drift test and the thermal model of each displacement channel."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any, Mapping, Optional, Sequence, Tuple, Union

from . import _chain
from ._machine import _csv_input, _optional_float
from ._results import ThermalResult

if TYPE_CHECKING:
    from ._machine import Machine

Pair = Union[str, Tuple[str, str, float]]


def _names(x: Optional[Sequence[str]], what: str) -> list:
    """Column names (a str is one name)."""
    if x is None:
        return []
    if isinstance(x, str):
        return [x]
    names = list(x)
    for n in names:
        if not isinstance(n, str):
            raise ValueError(f"{what} must be column names, not {n!r}")
    return names


def _pair(p: Pair) -> str:
    """A pair as the CLI's ``X1:X2=L`` text (one parser reads both)."""
    if isinstance(p, str):
        return p
    if isinstance(p, tuple) and len(p) == 3 and all(isinstance(n, str) for n in p[:2]):
        distance = _optional_float(p[2], "a pair's distance")
        return f"{p[0]}:{p[1]}={distance!r}"
    raise ValueError(f"a pair is 'X1:X2=L' or (X1, X2, L), not {p!r}")


def thermal(
    run: Union[None, str, "os.PathLike[str]", Mapping[str, Any]] = None,
    text: Optional[str] = None,
    name: str = "<run>",
    displacements: Optional[Sequence[str]] = None,
    temperatures: Optional[Sequence[str]] = None,
    loads: Optional[Sequence[str]] = None,
    pairs: Optional[Sequence[Pair]] = None,
    fit: bool = False,
    sensors: Optional[int] = None,
    lag: bool = False,
    holdout: Optional[float] = None,
    fit_until: Optional[float] = None,
    machine: Optional["Machine"] = None,
    slots: Optional[Mapping[str, str]] = None,
    values_out: Union[None, str, "os.PathLike[str]"] = None,
) -> ThermalResult:
    """An ISO 230-3 drift test, ``chain thermal RUN --format json``.

    ``run``: the drift-test file's path, or its columns as a dict (a pandas
    DataFrame works too) named as the file's header: ``time`` (s),
    displacement channels (a header ending in ``(um)`` or ``(mm)``),
    temperatures (``(°C)``, ``(degC)``, ``(C)``) and loads; or ``text``: the
    file's CSV text, named ``name`` in messages. ``displacements``,
    ``temperatures``, ``loads``: columns whose headers carry no unit
    (``--displacements`` ...). ``pairs``: ``"X1:X2=L"`` or ``(X1, X2, L)``,
    two displacement sensors ``L`` mm apart, the first nearer the spindle
    nose (``--pair``). ``fit``: a thermal model per channel (``--fit``) with
    at most ``sensors`` temperature sensors (``--sensors``, default 4),
    ``lag`` responses to the loads (``--lag``), fitted on the first
    ``1 - holdout`` of the duration (``--holdout``) or before ``fit_until``
    seconds (``--fit-until``). ``machine`` and ``slots`` (``--machine``,
    ``--slot``; ``{"EZS": "Z(um)"}``): the fitted models as the thermal
    coefficients of the machine's thermal terms ``{name, per}``, the values
    file's text in the result's ``values_text`` (and the document's
    ``values``), written to ``values_out`` too (``--values-out``;
    docs/thermal.md). A refused file raises ``MachineError`` with
    the CLI's message, located; a refused option ``ValueError`` with the
    CLI's words.

    The result's ``to_dict()`` is the CLI's JSON; ``time``, ``measured`` and
    ``predicted`` hold the samples' times and, per channel, its drift and
    the model's prediction as arrays (``--format csv``).
    """
    if (run is None) == (text is None):
        raise ValueError("give the drift test as run (a path or columns) or as text, one of them")
    if text is not None:
        if not isinstance(text, str):
            raise ValueError(f"text must be a str, not {type(text).__name__}")
        path = None
    else:
        path, text = _csv_input(run, "run")
    for flag, what in ((fit, "fit"), (lag, "lag")):
        if not isinstance(flag, bool):
            raise ValueError(f"{what} must be True or False, not {flag!r}")
    if sensors is not None and (isinstance(sensors, bool) or not isinstance(sensors, int) or sensors < 0):
        raise ValueError(f"sensors must be a non-negative integer, not {sensors!r}")
    if (machine is None) != (slots is None):
        raise ValueError("machine and slots go together: the machine whose thermal terms take the channels' models")
    if slots is not None and not isinstance(slots, Mapping):
        raise TypeError(f"slots must be a mapping of thermal term to channel, not {type(slots).__name__}")
    if values_out is not None and machine is None:
        raise ValueError("values_out writes the fitted models into a machine's values: give machine and slots")
    doc, time, predictions, values_text = _chain.thermal_json(
        path, text, name,
        _names(displacements, "displacements"), _names(temperatures, "temperatures"), _names(loads, "loads"),
        [_pair(p) for p in (pairs or [])],
        fit, sensors, lag, _optional_float(holdout, "holdout"), _optional_float(fit_until, "fit_until"),
        None if machine is None else machine._model,
        [(str(k), str(v)) for k, v in (slots or {}).items()],
    )
    if values_out is not None and values_text is not None:
        with open(os.fspath(values_out), "w", encoding="utf-8") as f:
            f.write(values_text)
    result = ThermalResult._from_json(doc)
    result.values_text = values_text
    result.time = time
    result.measured = {c: m for c, m, _ in predictions}
    result.predicted = {c: p for c, _, p in predictions}
    return result
