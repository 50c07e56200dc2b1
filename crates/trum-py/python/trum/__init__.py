"""trum: steady-state model of traveling-wave rotary ultrasonic motors (TRUMs).

>>> import trum
>>> m = trum.Motor("trum60a")
>>> res = m.solve(preload_n=260.0, torque_nm=[0.0, 0.2], voltage_v=200.0, frequency_hz=43e3)
>>> res.status.tolist()
['ok', 'ok']

SI units everywhere; every name carries its unit (``speed_rpm``, ``preload_n``).
"""
from ._errors import InputError, ParameterError, ParameterKeyError, TrumError
from ._registry import (
    LIMIT_KEYS,
    QUANTITY_NAMES,
    STATUS_NAMES,
    EffectInfo,
    EffectParam,
    ParameterInfo,
    PresetInfo,
    QuantityInfo,
    effects,
    parameters,
    preset_toml,
    presets,
    quantities,
)
from ._result import Result
from ._motor import Motor
from ._axes import linspace
from ._api import MapResult, Optimum, map, optimize
from ._diagnosis import Calibration, Diagnosis, calibrate, diagnose
from ._fleet import CALIBRATE_FLEET_COLUMNS, DIAGNOSE_FLEET_COLUMNS, calibrate_fleet, diagnose_fleet
from ._estimate import ESTIMATE_COLUMNS, ESTIMATE_STATUS_NAMES, estimate
from ._dynamics import (
    HertzIdentification,
    Resonance,
    ResonanceCurve,
    Snapshot,
    StepResult,
    hertz_defaults,
    identify_hertz,
    resonance,
    step,
)
from ._trum import __version__

__all__ = [
    "Motor",
    "Result",
    "Optimum",
    "MapResult",
    "Diagnosis",
    "linspace",
    # `map` is left out of __all__ so `from trum import *` does not shadow the builtin.
    "optimize",
    "resonance",
    "identify_hertz",
    "step",
    "diagnose",
    "calibrate",
    "Calibration",
    "diagnose_fleet",
    "calibrate_fleet",
    "DIAGNOSE_FLEET_COLUMNS",
    "CALIBRATE_FLEET_COLUMNS",
    "estimate",
    "ESTIMATE_COLUMNS",
    "ESTIMATE_STATUS_NAMES",
    "hertz_defaults",
    "Resonance",
    "ResonanceCurve",
    "HertzIdentification",
    "StepResult",
    "Snapshot",
    "presets",
    "preset_toml",
    "effects",
    "quantities",
    "parameters",
    "PresetInfo",
    "EffectInfo",
    "EffectParam",
    "QuantityInfo",
    "ParameterInfo",
    "STATUS_NAMES",
    "QUANTITY_NAMES",
    "LIMIT_KEYS",
    "TrumError",
    "ParameterError",
    "ParameterKeyError",
    "InputError",
    "__version__",
]
