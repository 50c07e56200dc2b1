"""Maps over a full-factorial grid and the preload criterion."""
from __future__ import annotations

import numbers
from dataclasses import dataclass, field
from typing import Any, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _trum
from ._errors import InputError
from ._motor import Motor
from ._registry import QUANTITY_NAMES, STATUS_NAMES, warning_words
from ._result import _require_pandas

AxisSpec = Union[float, Tuple[float, float, int]]
_STATUS = np.array(STATUS_NAMES)
WEIGHT_NAMES = ("stall_torque", "efficiency", "temperature_rise", "speed_fluctuation")


def _axis(name: str, spec: Any) -> Tuple[float, float, int]:
    if isinstance(spec, numbers.Real) and not isinstance(spec, bool):
        return (float(spec), float(spec), 1)
    if isinstance(spec, Sequence) and len(spec) == 3 and not isinstance(spec, str):
        a, b, n = spec
        if not (isinstance(n, numbers.Integral) or (isinstance(n, float) and n.is_integer())):
            raise InputError(f"{name}: the point count {n!r} must be a positive whole number")
        return (float(a), float(b), int(n))
    raise InputError(f"{name}: expected a value or (start, stop, n), got {spec!r}")


def _motor(m: Any) -> Any:
    if isinstance(m, Motor):
        return m._m
    if isinstance(m, str):
        return Motor(m)._m
    raise TypeError(f"expected a trum.Motor or a preset name, got {type(m).__name__}")


def map(  # noqa: A001 - the CLI's name for it
    motor: Union[Motor, str],
    *,
    preload_n: AxisSpec,
    voltage_v: AxisSpec,
    frequency_hz: AxisSpec,
    torque_nm: AxisSpec = 0.0,
    max_points: int = 20_000_000,
    parallel: Optional[bool] = None,
) -> Dict[str, np.ndarray]:
    """A full-factorial map over preload × torque × voltage × frequency, as ``trum map``
    computes it. Each axis is a value or ``(start, stop, n)``; every point must be a valid
    operating point (preload, voltage, frequency > 0, torque >= 0), else ``InputError``
    names the axis. Returns flat columns ``{preload_n, torque_nm, voltage_v, frequency_hz,
    status, warnings, <quantities>}`` (``warnings``: the motor's ``[limits]`` keys a point
    exceeds, ``;``-joined, "" when none, as ``trum map`` writes them) ready for
    ``pandas.DataFrame``; points run torque fastest, then frequency, voltage, preload.
    Points are warm-started from their predecessors in the same fixed chunks as
    ``trum map``, so the numbers are the CLI's, equal to ``Motor.solve`` within the solver
    tolerance, and do not depend on threads.
    """
    d = _trum.map_grid(
        _motor(motor),
        preload_n=_axis("preload_n", preload_n),
        torque_nm=_axis("torque_nm", torque_nm),
        voltage_v=_axis("voltage_v", voltage_v),
        frequency_hz=_axis("frequency_hz", frequency_hz),
        max_points=int(max_points),
        parallel=parallel,
    )
    out: Dict[str, np.ndarray] = {k: d[k] for k in _trum.AXES}
    out["status"] = _STATUS[d["status_code"]]
    out["warnings"] = warning_words(d["warning_code"])
    out.update({q: d[q] for q in QUANTITY_NAMES})
    return out


@dataclass
class Optimum:
    """The preload criterion: one row per candidate preload, the optimum and its region."""

    table: Dict[str, np.ndarray]
    optimum_preload_n: float
    region_n: Tuple[float, float]
    config: Dict[str, Any] = field(default_factory=dict)
    #: True when the optimum was chosen among the candidates within the motor's
    #: ``[limits]`` (the ``warnings`` column); False when none is within them.
    within_limits: bool = True

    def to_pandas(self) -> Any:
        """The table as a DataFrame."""
        return _require_pandas().DataFrame(self.table)


def optimize(
    motor: Union[Motor, str],
    *,
    voltage_v: Optional[float] = None,
    frequency_hz: Optional[float] = None,
    preload_n: Optional[Tuple[float, float, int]] = None,
    weights: Union[None, Sequence[float], Mapping[str, float]] = None,
    run_time_s: Optional[float] = None,
    run_torque_nm: Optional[float] = None,
    runout_m: Optional[float] = None,
    region_tolerance: Optional[float] = None,
    torque_samples: Optional[int] = None,
) -> Optimum:
    """The preload optimisation criterion of Chen et al. 2020, section 5 (as ``trum optimize``).

    For each candidate preload: stall torque, maximum efficiency over load torque,
    temperature rise after ``run_time_s`` and the speed fluctuation from ``runout_m``;
    each scaled to [0, 1] and combined with ``weights`` (stall_torque, efficiency,
    temperature_rise, speed_fluctuation — a 4-sequence or a dict with those names).
    Unset settings take the core defaults (200 V, 43 kHz, 150-500 N in 36 steps,
    weights 1, 1, 2, 2). Candidates beyond the motor's ``[limits]`` (``warnings`` column)
    are scored but kept out of the optimum and its region, as in ``trum optimize``.
    """
    w: Optional[list] = None
    if isinstance(weights, Mapping):
        unknown = set(weights) - set(WEIGHT_NAMES)
        if unknown:
            raise InputError(f"unknown weight {sorted(unknown)[0]!r}; weights are: {', '.join(WEIGHT_NAMES)}")
        default = dict(zip(WEIGHT_NAMES, (1.0, 1.0, 2.0, 2.0)))
        default.update({k: float(v) for k, v in weights.items()})
        w = [default[k] for k in WEIGHT_NAMES]
    elif weights is not None:
        w = [float(x) for x in weights]
        if len(w) != 4:
            raise InputError(f"weights: expected 4 values ({', '.join(WEIGHT_NAMES)}), got {len(w)}")
    d = _trum.criterion(
        _motor(motor),
        voltage_v=voltage_v,
        frequency_hz=frequency_hz,
        preload_n=None if preload_n is None else _axis("preload_n", preload_n),
        weights=w,
        run_time_s=run_time_s,
        run_torque_nm=run_torque_nm,
        runout_m=runout_m,
        region_tolerance=region_tolerance,
        torque_samples=torque_samples,
    )
    table = dict(d["table"])
    table["status"] = np.array(table["status"])
    table["warnings"] = np.array(table["warnings"], dtype=object)
    cfg = dict(d["config"])
    cfg["weights"] = dict(zip(WEIGHT_NAMES, cfg["weights"]))
    return Optimum(table, d["optimum_preload_n"], tuple(d["region_n"]), cfg, bool(d["within_limits"]))
