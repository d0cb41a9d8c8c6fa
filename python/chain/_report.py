"""``chain.report``: the calibration report a lab hands over, one self-contained HTML page."""

from __future__ import annotations

import os
from typing import Optional, Union

from . import _chain
from ._results import ReportResult


def report(
    calibration: Union[str, "os.PathLike[str]"],
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> ReportResult:
    """The calibration report, ``chain report CALIBRATION.yaml --out FILE``.

    ``calibration``: the calibration file's path (YAML, docs/report.md: the
    machine file, positioning runs per axis with tolerances, the values
    file, the identification's measurements, the controller exported to, a
    circular test, the cover's free text; paths relative to it). ``out``:
    also write the page there. The result's ``html`` is the page (also
    ``str(result)``), its ``to_dict()`` the CLI's ``--format json``. A
    refused calibration file, or a file it names, raises ``MachineError``
    with the CLI's message, located; another refusal ``ValueError``.
    """
    path = os.fspath(calibration)
    if not isinstance(path, str):
        raise ValueError(f"calibration must be a path, not {type(calibration).__name__}")
    html, doc = _chain.report_html(path)
    if out is not None:
        with open(os.fspath(out), "w", encoding="utf-8") as f:
            f.write(html)
    return ReportResult._from_json(doc, html)
