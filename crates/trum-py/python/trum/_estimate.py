"""The measured-input estimator of Sun et al. 2021 (``trum estimate``): per measurement row,
the amplitude implied by the feedback voltage, contact and driving zones, every loss,
output power and efficiency."""
from __future__ import annotations

from typing import Any, Dict, Mapping, Union

import numpy as np

from . import _trum
from ._api import _motor
from ._errors import InputError
from ._motor import Motor
from ._registry import warning_words

#: Status words of an estimate, in ``status_code`` order.
ESTIMATE_STATUS_NAMES = tuple(_trum.ESTIMATE_STATUS_NAMES)
#: ``(name, unit, meaning)`` of every numeric column of an estimate.
ESTIMATE_COLUMNS = tuple(tuple(c) for c in _trum.ESTIMATE_COLUMNS)

_REQUIRED = ("preload_n", "voltage_v", "frequency_hz", "torque_nm", "feedback_v")


def _column(data: Any, name: str, n: int | None) -> np.ndarray:
    try:
        col = np.asarray(data[name], dtype=np.float64).reshape(-1)
    except (TypeError, ValueError) as e:
        raise InputError(f"estimate: column '{name}' is not numeric ({e})") from e
    if n is not None and col.size != n:
        raise InputError(f"estimate: column '{name}' has {col.size} rows, expected {n}")
    return col


def estimate(motor: Union[Motor, str], data: Union[Mapping[str, Any], Any]) -> Any:
    """The measured-input estimate of every row of ``data`` (docs/ESTIMATE.md), as
    ``trum estimate`` computes it.

    ``data``: a pandas DataFrame or a mapping of 1-D columns in the measurement layout
    (docs/MEASUREMENTS.md): ``preload_n``, ``voltage_v``, ``frequency_hz``, ``torque_nm``,
    ``feedback_v`` (NaN where not measured), and ``speed_rpm`` if measured (then
    ``speed_residual_rpm`` compares it). The motor's ``electrical.feedback_gain_v_per_m``
    turns the feedback voltage into the amplitude.

    Returns the same type (a DataFrame for a DataFrame, else a dict of arrays): the input
    columns, ``status`` (``ok``, ``stall``, ``no_contact_state``, ``no_feedback``,
    ``invalid_input``), ``warnings`` (the motor's ``[limits]`` exceeded), ``full_contact``
    and the numeric columns of ``trum.ESTIMATE_COLUMNS`` (NaN where the status has no
    contact state)."""
    m = _motor(motor)
    missing = [c for c in _REQUIRED if c not in data]
    if missing:
        raise InputError(
            f"estimate: no column {', '.join(repr(c) for c in missing)}; the estimator needs "
            f"{', '.join(_REQUIRED)} (docs/MEASUREMENTS.md)"
        )
    cols: Dict[str, np.ndarray] = {}
    n = None
    for c in _REQUIRED:
        cols[c] = _column(data, c, n)
        n = cols[c].size
    speed = _column(data, "speed_rpm", n) if "speed_rpm" in data else None
    d = _trum.estimate_rows(
        m, cols["preload_n"], cols["voltage_v"], cols["frequency_hz"], cols["torque_nm"], cols["feedback_v"], speed
    )
    out: Dict[str, Any] = dict(cols)
    if speed is not None:
        out["measured_speed_rpm"] = speed
    out["status"] = np.array(ESTIMATE_STATUS_NAMES, dtype=object)[d["status_code"]]
    out["warnings"] = warning_words(d["warning_code"])
    out["full_contact"] = d["full_contact"]
    out.update({name: d[name] for name, _, _ in ESTIMATE_COLUMNS})
    try:
        import pandas as pd
    except ImportError:  # pragma: no cover - depends on the environment
        return out
    if isinstance(data, pd.DataFrame):
        return pd.DataFrame(out, index=data.index)
    return out
