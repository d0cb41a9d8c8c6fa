"""``chain.circular``: an ISO 230-4 circular test (ballbar) evaluated per run and direction."""

from __future__ import annotations

import os
from typing import Any, Mapping, Optional, Union

from . import _chain
from ._machine import _csv_input, _optional_float
from ._results import CircularResult


def circular(
    runs: Union[None, str, "os.PathLike[str]", Mapping[str, Any]] = None,
    text: Optional[str] = None,
    name: str = "<runs>",
    radius: Optional[float] = None,
    feed: Optional[float] = None,
    plane: Optional[str] = None,
    arc: Optional[float] = None,
    pitch: Optional[Mapping[str, float]] = None,
    window: Optional[float] = None,
) -> CircularResult:
    """An ISO 230-4 circular test, ``chain circular RUNS --format json``.

    ``runs``: the run file's path, or its columns as a dict (a pandas
    DataFrame works too) named as the file's header: ``angle`` (degrees,
    from the plane's first axis towards its second), ``direction`` (``ccw``
    or ``cw``), ``deviation`` (mm; ``deviation(um)`` for µm), and optionally
    ``run``, ``radius`` (mm), ``feed`` (mm/min), ``plane`` (``xy``, ``yz``,
    ``zx``); or ``text``: the file's CSV text, named ``name`` in messages.
    ``radius``, ``feed``, ``plane``: for runs whose file gives none
    (``--radius``, ``--feed``, ``--plane``); ``arc``: the arc in degrees
    every direction covers (``--arc``, default 360); ``pitch``: ``{axis:
    mm}``, the pitch of each axis's cyclic error to diagnose (``--pitch
    x=10``); ``window``: the spike window after each reversal in degrees
    (``--window``, default 4). A refused file raises
    ``MachineError`` with the CLI's message, located; a refused option
    ``ValueError`` with the CLI's words.

    The result's ``to_dict()`` is the CLI's JSON: per run its ``plane``,
    ``radius``, ``feed``, ``directions`` (``ccw``, ``cw``: ``G``, ``F_max``,
    ``F_min``, ``centre``, in mm), ``G_b`` and ``H``; ``diagnosis`` (per
    error ``error``, ``plane``, ``axes``, ``run``, ``value``, ``unit``,
    ``uncertainty``, ``sign``, ``share``, ``shares``) and ``fit`` (per plane
    what was not fitted and why, what the runs separate only weakly, each
    run's centres, radius offset and residual); ``diagnosis_frame()`` the
    diagnosis as a DataFrame.
    """
    if (runs is None) == (text is None):
        raise ValueError("give the circular test as runs (a path or columns) or as text, one of them")
    if text is not None:
        if not isinstance(text, str):
            raise ValueError(f"text must be a str, not {type(text).__name__}")
        path = None
    else:
        path, text = _csv_input(runs, "runs", text_columns=("direction", "run", "plane"))
    if plane is not None and not isinstance(plane, str):
        raise ValueError(f"plane must be 'xy', 'yz' or 'zx', not {plane!r}")
    pitches = []
    if pitch is not None:
        if not isinstance(pitch, Mapping):
            raise ValueError(f"pitch must be a mapping {{axis: mm}}, not {type(pitch).__name__}")
        for axis, mm in pitch.items():
            if not isinstance(axis, str):
                raise ValueError(f"pitch: the axis {axis!r} must be 'x', 'y' or 'z'")
            pitches.append((axis, _optional_float(mm, f"pitch[{axis!r}]")))
    doc = _chain.circular_json(
        path,
        text,
        name,
        _optional_float(radius, "radius"),
        _optional_float(feed, "feed"),
        plane,
        _optional_float(arc, "arc"),
        pitches,
        _optional_float(window, "window"),
    )
    return CircularResult._from_json(doc)
