# Type stubs of the private native module trum._trum (crates/trum-py/src/lib.rs).
# The public API is in trum/__init__.py; these are its building blocks.
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str
STATUS_NAMES: List[str]
LIMIT_KEYS: List[str]
ESTIMATE_STATUS_NAMES: List[str]
ESTIMATE_COLUMNS: List[Tuple[str, str, str]]
INPUTS: List[str]
AXES: List[str]
PARALLEL_MIN_POINTS: int

_Axis = Tuple[float, float, int]

class Motor:
    def __init__(self, preset: str) -> None: ...
    @staticmethod
    def from_toml_str(text: str, source: str = "<string>") -> Motor: ...
    @staticmethod
    def from_parts(
        preset: Optional[str],
        name: Optional[str],
        params: Sequence[Tuple[str, float]],
        effects: Sequence[str],
        source: str = "dict",
    ) -> Motor: ...
    def with_params(self, params: Sequence[Tuple[str, float]], source: str = "with_params") -> Motor: ...
    def with_effects(self, specs: Sequence[str], source: str = "with_effects") -> Motor: ...
    def get(self, key: str) -> float: ...
    def params(self) -> List[Tuple[str, float]]: ...
    def overrides(self) -> List[Tuple[str, float, float]]: ...
    @property
    def name(self) -> str: ...
    @property
    def preset(self) -> Optional[str]: ...
    @property
    def active_effects(self) -> List[Tuple[str, List[Tuple[str, float]]]]: ...
    @property
    def effects(self) -> str: ...
    @property
    def drive(self) -> Optional[Tuple[float, float]]: ...
    def to_toml(self) -> str: ...
    def __eq__(self, other: object) -> bool: ...
    def __reduce__(self) -> Tuple[Any, Tuple[str]]: ...

def _motor_from_toml(text: str) -> Motor: ...
def solve_arrays(
    motor: Motor,
    preload_n: npt.NDArray[np.float64],
    torque_nm: npt.NDArray[np.float64],
    voltage_v: npt.NDArray[np.float64],
    frequency_hz: npt.NDArray[np.float64],
    elapsed_s: npt.NDArray[np.float64],
    parallel: Optional[bool] = None,
) -> Dict[str, Any]: ...
def map_grid(
    motor: Motor,
    preload_n: _Axis,
    torque_nm: _Axis,
    voltage_v: _Axis,
    frequency_hz: _Axis,
    max_points: int = 20_000_000,
    parallel: Optional[bool] = None,
) -> Dict[str, Any]: ...
def loaded_stall_lines(
    motor: Motor,
    preload_n: npt.NDArray[np.float64],
    voltage_v: npt.NDArray[np.float64],
    frequency_hz: npt.NDArray[np.float64],
    parallel: Optional[bool] = None,
) -> npt.NDArray[np.float64]: ...
def criterion(
    motor: Motor,
    voltage_v: Optional[float] = None,
    frequency_hz: Optional[float] = None,
    preload_n: Optional[_Axis] = None,
    weights: Optional[Sequence[float]] = None,
    run_time_s: Optional[float] = None,
    run_torque_nm: Optional[float] = None,
    runout_m: Optional[float] = None,
    region_tolerance: Optional[float] = None,
    torque_samples: Optional[int] = None,
) -> Dict[str, Any]: ...
def presets_list() -> List[Tuple[str, str, str]]: ...
def preset_toml(name: str) -> str: ...
def effects_list() -> List[Tuple[str, str, str, List[Tuple[str, str, float, float, float, bool]]]]: ...
def quantities_list() -> List[Tuple[str, str, str]]: ...
def parameter_keys() -> List[Tuple[str, str]]: ...
def hertz_defaults() -> List[Tuple[str, float]]: ...
def hertz_motor_params(motor: Motor) -> List[Tuple[str, float]]: ...
def hertz_response(
    params: Sequence[Tuple[str, float]],
    voltage_v: Sequence[float],
    preload_n: Sequence[float],
    frequency_hz: Optional[npt.NDArray[np.float64]] = None,
    method_name: str = "multiple_scales",
) -> Dict[str, Any]: ...
def hertz_identify(
    time_s: npt.NDArray[np.float64],
    signal: npt.NDArray[np.float64],
    frequency_hz: float,
    params: Sequence[Tuple[str, float]],
    voltage_v: Optional[float] = None,
    preload_n: Optional[float] = None,
    drive_force_n: Optional[float] = None,
    feedback_gain_v_per_m: Optional[float] = None,
    harmonics: int = 3,
) -> Dict[str, float]: ...
def step(
    motor: Motor,
    voltage_v: float,
    frequency_hz: float,
    phase_difference_deg: float,
    preload_n: float,
    torque_nm: float,
    duration_s: float,
    steps_per_period: int,
    nodes_per_wavelength: int,
    tangential_stiffness_ratio: float,
    record_every: int,
    snapshot_at_s: Sequence[float],
    auto_steps: bool = False,
) -> Dict[str, Any]: ...
def bar_step(
    spec: str,
    moment_nm: float,
    frequency_hz: float,
    phase_difference_deg: float,
    preload_n: float,
    torque_nm: float,
    duration_s: float,
    steps_per_period: int,
    nodes_per_wavelength: int,
    record_every: int,
    snapshot_at_s: Sequence[float],
) -> Dict[str, Any]: ...
def is_bar_motor(spec: str) -> bool: ...
def bar_defaults(spec: str) -> List[Tuple[str, float]]: ...
def diagnose_csv(
    motor: Motor,
    data: bytes,
    source: str,
    motor_source: str,
    exact_cv: bool = False,
    plausible: List[str] = ...,
    plausible_toml: Optional[Tuple[str, str]] = None,
    tolerances: List[Tuple[str, float]] = ...,
    tolerances_toml: Optional[Tuple[str, str]] = None,
    sensor_noise: List[str] = ...,
) -> Tuple[str, List[str]]: ...
def calibrate_csv(
    motor: Motor,
    data: bytes,
    source: str,
    plausible: List[str] = ...,
    plausible_toml: Optional[Tuple[str, str]] = None,
    tolerances: List[Tuple[str, float]] = ...,
    tolerances_toml: Optional[Tuple[str, str]] = None,
) -> Dict[str, Any]: ...

def estimate_rows(
    motor: Motor,
    preload_n: Sequence[float],
    voltage_v: Sequence[float],
    frequency_hz: Sequence[float],
    torque_nm: Sequence[float],
    feedback_v: Sequence[float],
    speed_rpm: Optional[Sequence[float]] = None,
) -> Dict[str, Any]: ...
