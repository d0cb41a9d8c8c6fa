"""``chain.positioning``: the ISO 230-2 evaluation of an axis's positioning runs."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any, Mapping, Optional, Tuple, Union

import numpy as np

from . import _chain
from ._machine import _table_source
from ._results import PositioningResult

if TYPE_CHECKING:
    from ._machine import Machine


def _cell(v: Any) -> str:
    """One CSV cell: strings as written, whole numbers as integers, other numbers in full precision."""
    if isinstance(v, (str, np.str_)):
        return str(v)
    if isinstance(v, (bool, np.bool_)):
        raise ValueError(f"{v!r} is not a number or a direction")
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    return repr(float(v))


def _runs_input(runs: Any, what: str = "runs") -> Tuple[Optional[str], Optional[str]]:
    """A CSV file's path, or its columns (a dict of 1-D sequences or a DataFrame) as the CSV's text."""
    path, runs = _table_source(runs, what)
    if runs is None:
        return path, None
    names = [str(n) for n in runs]
    columns = [list(np.asarray(v).ravel()) if np.ndim(v) == 1 else None for v in runs.values()]
    for name, column in zip(names, columns):
        if column is None:
            raise ValueError(f"{what}[{name!r}]: expected a 1-D column")
        if len(column) != len(columns[0]):
            raise ValueError(f"{what}[{name!r}] has {len(column)} values, {names[0]!r} has {len(columns[0])}")
    lines = [",".join(names)]
    for i in range(len(columns[0])):
        lines.append(",".join(_cell(c[i]) for c in columns))
    return None, "\n".join(lines) + "\n"


def positioning(
    runs: Union[str, "os.PathLike[str]", Mapping[str, Any]],
    k: float = 2,
    rotary: bool = False,
    name: str = "<runs>",
    machine: Optional["Machine"] = None,
    slot: Optional[str] = None,
    values_out: Optional[Union[str, "os.PathLike[str]"]] = None,
    temperatures: Optional[Mapping[str, float]] = None,
) -> PositioningResult:
    """The ISO 230-2 evaluation of positioning runs, ``chain positioning RUNS --format json``.

    ``runs``: the run file's path, or its columns as a dict (a pandas
    DataFrame works too) named as the file's header: ``target``,
    ``direction`` (``"up"``/``"down"``, ``"+"``/``"-"``), ``run`` (1..n), and
    ``measured`` or ``deviation`` (mm; degrees with ``rotary``); ``name``
    names them in messages. ``k``: the coverage factor (``--k``; 2, or 3 for
    the 1988 edition); ``rotary``: statistics in arcseconds (``--rotary``).
    A refused file raises ``MachineError`` with the CLI's message, located.

    ``machine`` and ``slot`` (``--machine``, ``--slot``): the run as the
    axis's positioning error in a values file (means and standard
    deviations per approach direction, docs/positioning.md), kept as the
    result's ``values_text`` and written to ``values_out`` when given
    (``--values-out``).

    ``temperatures``: correct a linear axis's runs to 20 °C (``--axis-temperature``
    ...): a mapping with ``axis`` (°C) and ``axis_expansion`` (µm/(m·K)), optionally
    ``instrument``, ``instrument_expansion``, ``temperature_uncertainty`` (K),
    ``expansion_uncertainty`` (relative); the result's ``temperature`` states the
    correction and its uncertainty.
    """
    path, text = _runs_input(runs)
    if isinstance(k, bool):
        raise ValueError(f"k must be a number, not {k!r}")
    if values_out is not None and (machine is None or slot is None):
        raise ValueError("values_out needs machine and slot")
    model = machine._model if machine is not None else None
    temps = None
    if temperatures is not None:
        keys = ("axis", "axis_expansion", "instrument", "instrument_expansion",
                "temperature_uncertainty", "expansion_uncertainty")
        if not isinstance(temperatures, Mapping):
            raise ValueError(f"temperatures must be a mapping, not {type(temperatures).__name__}")
        unknown = [key for key in temperatures if key not in keys]
        if unknown:
            raise ValueError(f"temperatures: unknown key {unknown[0]!r} (keys: {', '.join(keys)})")
        for key in keys[:2]:
            if key not in temperatures:
                raise ValueError(f"temperatures needs {key!r}")
        values = [temperatures.get(key) for key in keys]
        for key, v in zip(keys, values):
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
                raise ValueError(f"temperatures[{key!r}] must be a number, not {v!r}")
        temps = tuple(None if v is None else float(v) for v in values)
    doc, values_text = _chain.positioning_json(path, text, name, float(k), bool(rotary), model, slot, temps)
    result = PositioningResult._from_json(doc)
    result.values_text = values_text
    if values_out is not None:
        with open(os.fspath(values_out), "w", encoding="utf-8") as f:
            f.write(values_text)
    return result
