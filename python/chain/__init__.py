"""chain: exact geometric-error models of machine tools and their machining-accuracy reliability.

The engine is Rust (the ``chain`` crates); arrays go in and out as numpy::

    import chain
    m = chain.Machine.load("examples/machines/ac_trunnion.yaml")
    S = m.sensitivity(q)          # q: (N, V) -> (N, 6, N_err), float64
    r = m.reliability(method="form")
    r.summary, r.to_dict(), r.to_dataframe()

Every result's ``to_dict()`` is the document the ``chain`` CLI prints with
``--format json`` for the same input. See docs/python.md.
"""

from ._chain import MachineError
from ._machine import Machine, Nominal
from ._results import Derivation, ReliabilityResult, Result
from ._results import IdentifyResult, MapResult, PlanResult
from ._results import Derivation, ReliabilityResult, Result, SobolResult
from ._results import AllocationResult, GeometricSensitivityResult, SensitivityResult
from ._results import CompensateResult, ExportResult, InverseResult, MotionResult, PathResult, PositioningResult
from ._results import CircularResult, ReportResult, ThermalResult
from ._positioning import positioning
from ._circular import circular
from ._thermal import thermal
from ._compensate import compensate
from ._report import report

__all__ = [
    "AllocationResult",
    "CircularResult",
    "CompensateResult",
    "Derivation",
    "ExportResult",
    "GeometricSensitivityResult",
    "IdentifyResult",
    "InverseResult",
    "PathResult",
    "MapResult",
    "MotionResult",
    "PlanResult",
    "PositioningResult",
    "Machine",
    "MachineError",
    "Nominal",
    "ReliabilityResult",
    "ReportResult",
    "Result",
    "SensitivityResult",
    "SobolResult",
    "ThermalResult",
    "compensate",
    "positioning",
    "thermal",
    "circular",
    "report",
]

__version__ = "0.1.0"
