"""The result of a vectorised solve: one float64 array per quantity, status and reasons."""
from __future__ import annotations

from typing import Any, Dict, Iterator, List, Tuple

import numpy as np

from ._registry import QUANTITY_NAMES, STATUS_NAMES, warning_words

_STATUS = np.array(STATUS_NAMES)
_VALID_MAX_CODE = 2  # ok, stall, clamped are physical steady states


def _require_pandas() -> Any:
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("to_pandas() needs pandas: pip install pandas") from e
    return pandas


class Result:
    """Outputs of ``Motor.solve`` with the broadcast shape of its inputs.

    Every quantity of ``trum.quantities()`` is a float64 array attribute (``res.speed_rpm``),
    NaN where the point has no valid steady state. ``status`` (str array) is the source of
    truth: ``ok``, ``stall``, ``clamped`` are valid; ``no_convergence`` and
    ``invalid_input`` are not, and ``reason`` says why. ``warnings`` names the motor's
    ``[limits]`` each point exceeds (``trum.LIMIT_KEYS``; "" when none).
    """

    # Quantity attributes (for type checkers; values live in ``_q``).
    speed_rpm: np.ndarray
    speed_rad_s: np.ndarray
    efficiency: np.ndarray
    output_power_w: np.ndarray
    input_power_w: np.ndarray
    stall_torque_nm: np.ndarray
    amplitude_m: np.ndarray
    contact_angle_deg: np.ndarray
    driving_angle_deg: np.ndarray
    driving_ratio: np.ndarray
    contact_half_angle_rad: np.ndarray
    stick_half_angle_rad: np.ndarray
    contact_length_m: np.ndarray
    crest_speed_m_s: np.ndarray
    axial_force_n: np.ndarray
    dielectric_loss_w: np.ndarray
    damping_loss_w: np.ndarray
    friction_loss_w: np.ndarray
    radial_friction_loss_w: np.ndarray
    rotor_loss_w: np.ndarray
    current_a: np.ndarray
    feedback_v: np.ndarray
    electrode_voltage_v: np.ndarray
    phase_lag_rad: np.ndarray
    modal_stiffness_n_per_m: np.ndarray
    temperature_rise_k: np.ndarray
    temperature_rise_at_elapsed_k: np.ndarray
    speed_std_rpm: np.ndarray

    def __init__(self, data: Dict[str, Any], inputs: Dict[str, np.ndarray]) -> None:
        self.shape: Tuple[int, ...] = tuple(data.pop("shape"))
        #: uint8 codes into ``trum.STATUS_NAMES`` (``pandas.Categorical.from_codes`` friendly).
        self.status_code: np.ndarray = data.pop("status_code")
        #: uint8 bits into ``trum.LIMIT_KEYS`` (bit i: that limit exceeded).
        self.warning_code: np.ndarray = data.pop("warning_code")
        self._reasons: List[Tuple[int, str]] = data.pop("reasons")
        self._q: Dict[str, np.ndarray] = {n: data[n] for n in QUANTITY_NAMES}
        #: The inputs, broadcast to ``shape`` (read-only views).
        self.inputs: Dict[str, np.ndarray] = {k: np.broadcast_to(v, self.shape) for k, v in inputs.items()}
        self._index: Any = None
        self.motor: str = ""
        self.effects: str = ""

    def __getattr__(self, name: str) -> np.ndarray:
        if not name.startswith("_"):
            q = self.__dict__.get("_q", {})
            if name in q:
                return q[name]
        raise AttributeError(f"'Result' has no attribute '{name}'; quantities are: {', '.join(QUANTITY_NAMES)}")

    def __getitem__(self, name: str) -> np.ndarray:
        if name in self._q:
            return self._q[name]
        if name == "status":
            return self.status
        if name == "warnings":
            return self.warnings
        if name in self.inputs:
            return self.inputs[name]
        raise KeyError(name)

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(QUANTITY_NAMES))

    def __len__(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64))

    def __iter__(self) -> Iterator[str]:
        return iter(self.keys())

    def keys(self) -> List[str]:
        """Column names of ``to_dict``: inputs, ``status``, ``warnings``, quantities."""
        return [*self.inputs, "status", "warnings", *QUANTITY_NAMES]

    @property
    def size(self) -> int:
        """Number of operating points."""
        return len(self)

    @property
    def status(self) -> np.ndarray:
        """Status word per point (``ok``, ``stall``, ``clamped``, ``no_convergence``, ``invalid_input``)."""
        return _STATUS[self.status_code]

    @property
    def warnings(self) -> np.ndarray:
        """The motor's ``[limits]`` each point exceeds, ``;``-joined keys (object array; "" when none)."""
        return warning_words(self.warning_code)

    @property
    def within_limits(self) -> np.ndarray:
        """True where the point exceeds none of the motor's ``[limits]``."""
        return self.warning_code == 0

    @property
    def valid(self) -> np.ndarray:
        """True where the numbers describe a physical steady state."""
        return self.status_code <= _VALID_MAX_CODE

    @property
    def reason(self) -> np.ndarray:
        """Why each point is not valid ("" where it is): e.g. ``preload_n = -1 must be > 0``."""
        out = np.full(self.shape, "", dtype=object)
        flat = out.reshape(-1)
        for i, r in self._reasons:
            flat[i] = r
        return out

    def counts(self) -> Dict[str, int]:
        """Number of points per status word."""
        c = np.bincount(self.status_code.reshape(-1), minlength=len(STATUS_NAMES))
        return {n: int(k) for n, k in zip(STATUS_NAMES, c)}

    def to_dict(self) -> Dict[str, np.ndarray]:
        """``{column: array}`` with the broadcast shape: inputs, ``status``, ``warnings``, quantities."""
        d: Dict[str, np.ndarray] = {k: np.array(v) for k, v in self.inputs.items()}
        d["status"] = self.status
        d["warnings"] = self.warnings
        d.update(self._q)
        return d

    def to_pandas(self) -> Any:
        """A DataFrame with one row per point (C order); ``status`` is categorical, ``warnings``
        a string column. The index is that of a pandas Series given to ``solve`` (1-D
        results), else 0..n-1."""
        pd = _require_pandas()
        cols: Dict[str, Any] = {k: np.ravel(v) for k, v in self.inputs.items()}
        cols["status"] = pd.Categorical.from_codes(self.status_code.reshape(-1), categories=list(STATUS_NAMES))
        cols["warnings"] = self.warnings.reshape(-1)
        cols.update({k: v.reshape(-1) for k, v in self._q.items()})
        return pd.DataFrame(cols, index=self._index)

    def plot(self, x: str = "torque_nm", y: str = "speed_rpm", *, ax: Any = None) -> Any:
        """``y`` against ``x`` for a 1-D result (e.g. a speed-torque curve); points without
        a running steady state (stall, no convergence) leave a gap. Returns the Axes."""
        from . import _plot

        if len(self.shape) != 1:
            raise ValueError(f"plot() draws a 1-D result; this one has shape {self.shape} (use trum.map for grids)")
        ax = _plot.axes(ax)
        xs = np.asarray(self[x], dtype=np.float64)
        ys = np.where(self.status == "ok", np.asarray(self[y], dtype=np.float64), np.nan)
        _plot.lines(ax, xs, ys, x, y, [("", np.ones(xs.size, dtype=bool))], marker=".")
        fixed = {k: float(np.ravel(v)[0]) for k, v in self.inputs.items()
                 if k != x and np.ravel(v).size and np.all(np.ravel(v) == np.ravel(v)[0]) and not (k == "elapsed_s" and np.ravel(v)[0] == 0)}
        ax.set_title(_plot.caption(fixed, self.motor or None, self.effects or None), fontsize="medium")
        return ax

    def __repr__(self) -> str:
        counts = ", ".join(f"{k}={v}" for k, v in self.counts().items() if v)
        return f"<trum.Result shape={self.shape} {counts or 'empty'}; {len(self.keys())} columns: {', '.join(self.keys()[:7])}, ...>"
