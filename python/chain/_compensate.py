"""``chain.compensate``: the swing-angle error of seed 003 from tool-tip heights measured at commanded angles."""

from __future__ import annotations

import os
from typing import Any, Mapping, Optional, Union

from . import _chain
from ._positioning import _runs_input
from ._results import CompensateResult


def compensate(
    data: Union[str, "os.PathLike[str]", Mapping[str, Any]],
    length: float,
    min_order: int = 2,
    max_order: int = 6,
    select: str = "loocv",
    order: Optional[int] = None,
    name: str = "<measurements>",
) -> CompensateResult:
    """Swing-angle error identification and compensation, ``chain compensate FILE --length L --format json``.

    ``data``: the measurement CSV's path, or its columns as a dict (a pandas
    DataFrame works too) named as the file's header: ``theta_deg``, ``z1``,
    ``z3`` and optionally ``z2``; ``name`` names them in messages.
    ``length``: the distance L from the swing axis to the tool tip (mm);
    ``min_order``/``max_order``: the polynomial orders fitted; ``select``:
    ``"loocv"``, ``"adjusted-r2"``, ``"aicc"`` or ``"bic"`` (``--select``);
    ``order``: the law's order instead of the rule's (``--order``). The file
    is read by the CLI's reader (``chain::compensate::records``); a refusal
    raises ``ValueError`` with the CLI's message.
    """
    path, text = _runs_input(data, "data")
    for label, v in (("min_order", min_order), ("max_order", max_order)):
        if not isinstance(v, int) or isinstance(v, bool) or v < 0:
            raise ValueError(f"{label} must be a non-negative integer, not {v!r}")
    if order is not None and (not isinstance(order, int) or isinstance(order, bool) or order < 0):
        raise ValueError(f"order must be a non-negative integer, not {order!r}")
    if isinstance(length, bool):
        raise ValueError(f"length must be a number, not {length!r}")
    text_json = _chain.compensate_json(
        path, text, name, float(length), min_order, max_order, str(select), order
    )
    return CompensateResult._from_json(text_json)
