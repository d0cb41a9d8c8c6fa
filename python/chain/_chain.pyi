"""Type stubs of the compiled core ``chain._chain`` (python/src/lib.rs)."""

from typing import List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

class MachineError(ValueError):
    """A problem in a machine file: the CLI's message, located."""

    message: str
    file: str
    line: int
    column: int
    key: str
    errors: List[str]

class Model:
    @staticmethod
    def load(path: str) -> "Model": ...
    @staticmethod
    def from_yaml(text: str, file: str) -> "Model": ...
    @property
    def name(self) -> str: ...
    @property
    def file(self) -> str: ...
    @property
    def variables(self) -> List[str]: ...
    @property
    def parameters(self) -> List[Tuple[str, Optional[float]]]: ...
    @property
    def errors(self) -> List[str]: ...
    def derive_json(self, frame: Optional[str] = None) -> str: ...
    def sensitivity(
        self, q: npt.NDArray[np.float64], params: Sequence[Tuple[str, float]]
    ) -> npt.NDArray[np.float64]: ...
    def sensitivity_into(
        self,
        q: npt.NDArray[np.float64],
        params: Sequence[Tuple[str, float]],
        out: npt.NDArray[np.float64],
    ) -> None: ...
    def error(
        self,
        q: npt.NDArray[np.float64],
        e: npt.NDArray[np.float64],
        params: Sequence[Tuple[str, float]],
    ) -> npt.NDArray[np.float64]: ...
    def nominal(
        self, q: npt.NDArray[np.float64], params: Sequence[Tuple[str, float]]
    ) -> npt.NDArray[np.float64]: ...
    def tape_per_point(
        self, q: npt.NDArray[np.float64], params: Sequence[Tuple[str, float]]
    ) -> Tuple[float, float]: ...

def reliability_json(
    model: Model,
    method: str,
    samples: Optional[int],
    seed: int,
    cov: Optional[float],
    grid: Sequence[Tuple[str, Sequence[float]]],
    params: Sequence[Tuple[str, float]],
    sided: Optional[str],
    system: Optional[str],
    system_tolerance: Optional[float],
    values: Optional[str],
    acceptance: bool,
    acceptance_tolerance: float,
    approach: Optional[str],
    temperatures: Sequence[Tuple[str, float]],
) -> str: ...
def sobol_json(
    model: Model,
    at: Optional[Sequence[Tuple[str, float]]],
    samples: int,
    seed: int,
    bootstrap: int,
    confidence: float,
    grid: Sequence[Tuple[str, Sequence[float]]],
    params: Sequence[Tuple[str, float]],
) -> str: ...


# -- sensitivity (python/src/sensitivity.rs) ----------------------------------

def sensitivity_reliability_json(
    model: Model,
    at: Optional[Sequence[Tuple[str, float]]],
    grid: Sequence[Tuple[str, Sequence[float]]],
    params: Sequence[Tuple[str, float]],
    sided: Optional[str],
    values: Optional[str],
    approach: Optional[str],
    temperatures: Sequence[Tuple[str, float]],
) -> str: ...
def geometric_json(
    model: Model,
    at: Optional[Sequence[Tuple[str, float]]],
    grid: Sequence[Tuple[str, Sequence[float]]],
    params: Sequence[Tuple[str, float]],
    sizes: Optional[str],
) -> str: ...


# -- allocation (python/src/allocate.rs) --------------------------------------

def allocate_json(
    model: Model,
    strategy: str,
    step: float,
    threshold: float,
    rank: str,
    target: str,
    level: Optional[float],
    params: Sequence[Tuple[str, float]],
    sided: Optional[str],
) -> str: ...


# -- group B: the measured machine (python/src/measured.rs) --------------------

def identify_json(
    model: Model,
    measurements: Optional[Tuple[Optional[str], Optional[str], str]],
    spheres: Optional[Tuple[Optional[str], Optional[str], str]],
    setup: Optional[str],
    params: Sequence[Tuple[str, float]],
    prior: bool,
    validate: Optional[Tuple[Optional[str], Optional[str], str]] = None,
    rank_tol: Optional[float] = None,
    fix: Optional[Sequence[str]] = None,
    estimate: Optional[Sequence[str]] = None,
    iterate: bool = False,
    holdout: Optional[float] = None,
    seed: Optional[int] = None,
    temperatures: Sequence[Tuple[str, float]] = (),
    circular: Optional[Tuple[Optional[str], Optional[str], str]] = None,
    centre: Optional[Sequence[Tuple[str, float]]] = None,
    axes: bool = False,
    radius: Optional[float] = None,
    feed: Optional[float] = None,
    plane: Optional[str] = None,
    arc: Optional[float] = None,
) -> Tuple[str, str]: ...
def plan_json(
    model: Model,
    path: Optional[str],
    text: Optional[str],
    file: str,
    count: int,
    kind: Optional[str],
    params: Sequence[Tuple[str, float]],
    spheres: bool = False,
) -> str: ...
def map_json(
    model: Model,
    values_path: Optional[str],
    values_text: Optional[str],
    values_file: str,
    grid: Sequence[Tuple[str, Sequence[float]]],
    points: Optional[npt.NDArray[np.float64]],
    params: Sequence[Tuple[str, float]],
    approach: Optional[str],
    temperatures: Sequence[Tuple[str, float]],
) -> str: ...

# -- positioning runs (python/src/positioning.rs) ------------------------------

def positioning_json(
    path: Optional[str],
    text: Optional[str],
    file: str,
    k: float,
    rotary: bool,
    model: Optional[Model],
    slot: Optional[str],
    temperatures: Optional[Tuple[float, float, Optional[float], Optional[float], Optional[float], Optional[float]]] = None,
) -> Tuple[str, Optional[str]]: ...


# -- circular tests (python/src/circular.rs) -------------------------------------

def circular_json(
    path: Optional[str],
    text: Optional[str],
    file: str,
    radius: Optional[float] = None,
    feed: Optional[float] = None,
    plane: Optional[str] = None,
    arc: Optional[float] = None,
    pitch: Sequence[Tuple[str, float]] = (),
    window: Optional[float] = None,
) -> str: ...


# -- the calibration report (python/src/report.rs) -------------------------------

def report_html(path: str) -> Tuple[str, str]: ...


# -- thermal drift tests (python/src/thermal.rs) ---------------------------------

def thermal_json(
    path: Optional[str],
    text: Optional[str],
    file: str,
    displacements: Sequence[str],
    temperatures: Sequence[str],
    loads: Sequence[str],
    pairs: Sequence[str],
    fit: bool,
    sensors: Optional[int],
    lag: bool,
    holdout: Optional[float],
    fit_until: Optional[float],
    model: Optional[Model] = None,
    slots: Sequence[Tuple[str, str]] = (),
) -> Tuple[
    str,
    npt.NDArray[np.float64],
    List[Tuple[str, npt.NDArray[np.float64], npt.NDArray[np.float64]]],
    Optional[str],
]: ...


# -- inverse kinematics (python/src/inverse.rs) ----------------------------------

def inverse_json(
    model: Model,
    poses: Optional[npt.NDArray[np.float64]],
    fix: Sequence[Tuple[str, float]],
    params: Sequence[Tuple[str, float]],
    poses_file: Optional[Tuple[Optional[str], Optional[str], str]] = None,
) -> str: ...


# -- error and reliability along a path (python/src/path.rs) ---------------------

def path_json(
    model: Model,
    header: Sequence[str],
    axes: Optional[npt.NDArray[np.float64]],
    poses: Optional[npt.NDArray[np.float64]],
    t: Optional[npt.NDArray[np.float64]],
    fix: Sequence[Tuple[str, float]],
    params: Sequence[Tuple[str, float]],
    method: str,
    samples: Optional[int],
    seed: int,
    cov: Optional[float],
    sided: Optional[str],
    system: Optional[str],
    system_tolerance: Optional[float],
    axes_file: Optional[Tuple[Optional[str], Optional[str], str]] = None,
    poses_file: Optional[Tuple[Optional[str], Optional[str], str]] = None,
    temperatures: Sequence[Tuple[str, float]] = (),
) -> str: ...


# -- compensation for a controller (python/src/export.rs) ------------------------

def export_json(
    model: Model,
    values_path: Optional[str],
    values_text: Optional[str],
    values_file: str,
    controller: str,
    grid: Sequence[Tuple[str, Sequence[float]]],
    points: Optional[npt.NDArray[np.float64]],
    step: Optional[float],
    cec_max_points: Optional[int],
    beckhoff_max_records: Optional[int],
    angles: bool,
    params: Sequence[Tuple[str, float]],
    temperatures: Sequence[Tuple[str, float]],
) -> Tuple[str, List[Tuple[str, str]]]: ...


# -- motion conversion (python/src/motion.rs) ------------------------------------

def motion_json(
    model: Model,
    path: Optional[str],
    text: Optional[str],
    file: str,
    order: int,
    max_order: int,
    samples: int,
    tolerance: Optional[float],
    angular_tolerance: Optional[float],
    params: Sequence[Tuple[str, float]],
    fix: Sequence[Tuple[str, float]],
) -> Tuple[str, List[float], List[float]]: ...


# -- swing-angle compensation (python/src/compensate.rs) -------------------------

def compensate_json(
    path: Optional[str],
    text: Optional[str],
    name: str,
    length: float,
    min_order: int,
    max_order: int,
    select: str,
    order: Optional[int],
) -> str: ...
