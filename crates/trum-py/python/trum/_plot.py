"""Plotting helpers on matplotlib (an optional dependency): axis labels in words with units,
amplitudes in µm, efficiencies in %, and a title stating the fixed conditions and the
effects switched on."""
from __future__ import annotations

from typing import Any, Dict, Iterable, Mapping, Optional, Sequence, Tuple

import numpy as np

#: column -> (words, unit shown, factor from the column's SI unit to the unit shown)
_LABELS: Dict[str, Tuple[str, str, float]] = {
    "preload_n": ("Preload", "N", 1.0),
    "torque_nm": ("Load torque", "N·m", 1.0),
    "voltage_v": ("Drive voltage", "V", 1.0),
    "moment_nm": ("Drive moment", "N·m", 1.0),
    "frequency_hz": ("Drive frequency", "kHz", 1e-3),
    "elapsed_s": ("Time since switch-on", "s", 1.0),
    "speed_rpm": ("Speed", "rpm", 1.0),
    "speed_rad_s": ("Angular speed", "rad/s", 1.0),
    "efficiency": ("Efficiency", "%", 100.0),
    "output_power_w": ("Output power", "W", 1.0),
    "input_power_w": ("Input power", "W", 1.0),
    "stall_torque_nm": ("Stall torque", "N·m", 1.0),
    "amplitude_m": ("Vibration amplitude", "µm", 1e6),
    "contact_angle_deg": ("Contact angle", "°", 1.0),
    "driving_angle_deg": ("Driving angle", "°", 1.0),
    "crest_speed_m_s": ("Crest speed", "m/s", 1.0),
    "axial_force_n": ("Axial force", "N", 1.0),
    "current_a": ("Current", "A", 1.0),
    "feedback_v": ("Feedback voltage", "V", 1.0),
    "temperature_rise_k": ("Temperature rise", "K", 1.0),
    "speed_std_rpm": ("Speed fluctuation (std)", "rpm", 1.0),
    "time_s": ("Time", "ms", 1e3),
    "phase_lag_rad": ("Phase lag", "rad", 1.0),
    "max_efficiency": ("Maximum efficiency", "%", 100.0),
    "temperature_rise_after_run_k": ("Temperature rise after the run", "K", 1.0),
    "score": ("Criterion score", "", 1.0),
}


def _require_matplotlib() -> Any:
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("plot() needs matplotlib: pip install matplotlib") from e
    return plt


def label(col: str) -> str:
    """``"Speed [rpm]"`` for ``speed_rpm``; unknown columns fall back to their unit suffix."""
    if col in _LABELS:
        words, unit, _ = _LABELS[col]
        return f"{words} [{unit}]" if unit else words
    words = col.replace("_", " ")
    return words[:1].upper() + words[1:]


def factor(col: str) -> float:
    """Factor from the column's SI unit to the unit of :func:`label`."""
    return _LABELS.get(col, ("", "", 1.0))[2]


def value_text(col: str, v: float) -> str:
    """``"preload 260 N"``: a fixed condition in words."""
    words, unit, f = _LABELS.get(col, (col, "", 1.0))
    return f"{words.lower()} {v * f:.4g} {unit}".rstrip()


def caption(fixed: Mapping[str, float], motor: Optional[str] = None, effects: Optional[str] = None) -> str:
    """Title text: the motor, the fixed conditions and the effects switched on."""
    parts = [value_text(k, v) for k, v in fixed.items()]
    head = f"{motor}: " if motor else ""
    fx = "" if effects in (None, "") else ("\nnominal model (no effects)" if effects == "none" else f"\neffects: {effects}")
    if fx and len(fx) > 70:
        # one effect per line keeps the title inside the figure
        fx = "\neffects: " + effects.replace("), ", "),\n")
    # wrap between conditions, never inside one
    lines_, cur = [], head
    for i, p in enumerate(parts):
        piece = p + ("," if i < len(parts) - 1 else "")
        if cur and len(cur) + len(piece) > 66 and cur != head:
            lines_.append(cur.rstrip())
            cur = ""
        cur += piece + " "
    lines_.append(cur.rstrip())
    return "\n".join(lines_) + fx


def axes(ax: Any = None) -> Any:
    plt = _require_matplotlib()
    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 4.4), constrained_layout=True)
    return ax


def lines(ax: Any, x: np.ndarray, y: np.ndarray, xcol: str, ycol: str, groups: Iterable[Tuple[str, np.ndarray]],
          **kw: Any) -> Any:
    """One line per group mask; NaN (no steady state) leaves a gap."""
    for name, mask in groups:
        ax.plot(x[mask] * factor(xcol), y[mask] * factor(ycol), label=name, **kw)
    ax.set_xlabel(label(xcol))
    ax.set_ylabel(label(ycol))
    ax.grid(True, alpha=0.3)
    return ax


def group_masks(cols: Mapping[str, np.ndarray], by: Sequence[str]) -> Iterable[Tuple[str, np.ndarray]]:
    """``(legend text, mask)`` per distinct combination of the ``by`` columns."""
    if not by:
        n = len(next(iter(cols.values())))
        yield "", np.ones(n, dtype=bool)
        return
    keys = np.stack([np.asarray(cols[b], dtype=np.float64) for b in by], axis=1)
    uniq = np.unique(keys, axis=0)
    for u in uniq:
        mask = np.all(keys == u, axis=1)
        yield ", ".join(value_text(b, float(v)) for b, v in zip(by, u)), mask
