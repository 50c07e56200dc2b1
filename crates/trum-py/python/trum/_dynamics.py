"""Nonlinear resonance of the Hertzian oscillator and β identification ([Hertz2022]), and
the stick-slip step response ([BarTransient]; keys of docs/REFERENCES.md):
``trum.resonance``, ``trum.identify_hertz``, ``trum.step`` (the CLI's ``trum resonance``,
``trum identify-hertz``, ``trum step``)."""
from __future__ import annotations

import numbers
import warnings
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _trum
from . import _axes, _plot
from ._api import _drive, _motor
from ._result import _require_pandas
from ._errors import InputError
from ._motor import Motor, _number

Values = Union[float, Sequence[float], np.ndarray]


def hertz_defaults() -> Dict[str, float]:
    """The Hertzian oscillator's default parameters (60 mm TRUM, docs/DYNAMICS.md)."""
    return dict(_trum.hertz_defaults())


def _params(oscillator: Optional[Mapping[str, Any]], motor: Any = None) -> List[tuple]:
    """The motor's oscillator parameters (if a motor is given), then ``oscillator``'s overrides."""
    base = [] if motor is None else list(_trum.hertz_motor_params(_motor(motor)))
    if oscillator is None:
        return base
    if not isinstance(oscillator, Mapping):
        raise InputError(f"oscillator: expected a dict of parameters, got {type(oscillator).__name__}")
    return base + [(str(k), _number("oscillator", str(k), v)) for k, v in oscillator.items()]


def _values(name: str, v: Values) -> List[float]:
    """A number, or explicit values (list, array, Series); a range is ``trum.linspace``."""
    return _axes.values(name, v).tolist()


@dataclass(frozen=True)
class ResonanceCurve:
    """The response at one (voltage, preload): every branch at every frequency (points of
    the same frequency share ``frequency_hz``), the backbone and the saddle nodes."""

    voltage_v: float
    preload_n: float
    status: str  # 'ok', 'no_static_equilibrium' or 'invalid_input'
    reason: str
    frequency_hz: np.ndarray
    amplitude_m: np.ndarray
    phase_lag_rad: np.ndarray
    stable: np.ndarray
    branch: np.ndarray  # 'single', 'lower', 'middle' (unstable) or 'upper'
    backbone_frequency_hz: np.ndarray
    backbone_amplitude_m: np.ndarray
    jump_up_hz: Optional[float]
    jump_up_amplitude_m: Optional[float]
    jump_down_hz: Optional[float]
    jump_down_amplitude_m: Optional[float]
    linear_resonance_hz: Optional[float]
    equivalent_beta_n_per_m3: Optional[float]

    @property
    def hysteresis_hz(self) -> Optional[float]:
        """Width of the bistable band, or ``None`` when the response is single valued."""
        if self.jump_up_hz is None or self.jump_down_hz is None:
            return None
        return abs(self.jump_up_hz - self.jump_down_hz)

    def __repr__(self) -> str:
        jumps = ("single valued" if self.hysteresis_hz is None else
                 f"jump up {self.jump_up_hz:.6g} Hz, jump down {self.jump_down_hz:.6g} Hz")
        return (f"<trum.ResonanceCurve {self.voltage_v:g} V, {self.preload_n:g} N: {self.status}; "
                f"{self.frequency_hz.size} response points ({int(np.count_nonzero(~self.stable.astype(bool)))} "
                f"unstable); {jumps}>")


@dataclass(frozen=True)
class Resonance:
    """Result of :func:`resonance`: one curve per (voltage, preload), voltage slowest."""

    frequency_hz: np.ndarray
    curves: List[ResonanceCurve]
    #: The response table as the core lays it out, column by column (see ``to_dict``).
    table: Dict[str, Any] = field(default_factory=dict, repr=False)
    #: Its column order.
    columns: Tuple[str, ...] = ()

    def to_dict(self) -> Dict[str, np.ndarray]:
        """Flat columns laid out like the CLI's CSV (``trum resonance -o``, one table for
        both): ``voltage_v, preload_n, frequency_hz, branch, status, amplitude_m,
        phase_lag_rad, stable``; branch rows, then the ``backbone`` rows, then
        ``jump_up``/``jump_down``; a curve without a response is one row with its status.
        Numbers a row does not have are NaN; ``stable`` is ``None`` where stability does
        not apply."""
        t = self.table
        out = {k: np.asarray(t[k], dtype=np.float64)
               for k in ("voltage_v", "preload_n", "frequency_hz", "amplitude_m", "phase_lag_rad")}
        out["branch"] = np.array(t["branch"], dtype=object)
        out["status"] = np.array(t["status"], dtype=object)
        out["stable"] = np.array(t["stable"], dtype=object)
        return {k: out[k] for k in self.columns}

    def to_pandas(self) -> Any:
        """:meth:`to_dict` as a tidy DataFrame (``branch`` and ``status`` categorical,
        ``stable`` a nullable boolean)."""
        pd = _require_pandas()
        df = pd.DataFrame(self.to_dict())
        for c in ("branch", "status"):
            if c in df:
                df[c] = df[c].astype("category")
        if "stable" in df:
            df["stable"] = df["stable"].astype("boolean")
        return df

    def plot(self, *, ax: Any = None) -> Any:
        """Amplitude [µm] against frequency per curve: stable branches solid, the unstable
        branch dashed, the backbone dotted, each jump inside the band marked at its saddle
        node with an arrow to where the amplitude lands. Returns the Axes."""
        ax = _plot.axes(ax)
        fa, aa = _plot.factor("frequency_hz"), _plot.factor("amplitude_m")
        f_lo, f_hi = (float(self.frequency_hz.min()), float(self.frequency_hz.max())) if self.frequency_hz.size else (0, 0)
        for i, c in enumerate(self.curves):
            if c.status != "ok" or c.frequency_hz.size == 0:
                continue
            color = f"C{i % 10}"
            stable = c.stable.astype(bool)
            first = True
            for br in ("single", "lower", "middle", "upper"):
                m = c.branch == br
                if not m.any():
                    continue
                # one point per grid frequency and branch: NaN where the branch does not
                # exist, so that a branch of two separate pieces is not joined across the gap
                grid = np.unique(c.frequency_hz)
                y = np.full(grid.size, np.nan)
                y[np.searchsorted(grid, c.frequency_hz[m])] = c.amplitude_m[m]
                ax.plot(grid * fa, y * aa, color=color,
                        ls="--" if br == "middle" else "-", lw=0.9 if br == "middle" else 1.4,
                        label=f"{c.voltage_v:g} V, {c.preload_n:g} N" if first and br != "middle" else None)
                first = first and br == "middle"
            inside = (c.backbone_frequency_hz >= f_lo) & (c.backbone_frequency_hz <= f_hi)
            ax.plot(c.backbone_frequency_hz[inside] * fa, c.backbone_amplitude_m[inside] * aa, ":", lw=0.8, color=color)
            for f, a_jump, tag in ((c.jump_up_hz, c.jump_up_amplitude_m, "up"), (c.jump_down_hz, c.jump_down_amplitude_m, "down")):
                if f is None or a_jump is None or not (f_lo <= f <= f_hi):
                    continue
                # the jump lands on the stable branch nearest in frequency, on the other side
                on = stable & (np.abs(c.frequency_hz - f) <= np.min(np.abs(c.frequency_hz[stable] - f)) + 1e-9 * f)
                land = c.amplitude_m[on]
                target = land.max() if tag == "up" else land.min()
                if abs(target - a_jump) > 1e-3 * max(target, a_jump):
                    ax.annotate("", xy=(f * fa, target * aa), xytext=(f * fa, a_jump * aa),
                                arrowprops=dict(arrowstyle="->", color=color, lw=0.9))
                ax.plot([f * fa], [a_jump * aa], "o", mfc="none", color=color, ms=5)
        ax.plot([], [], "k--", lw=0.9, label="unstable branch")
        ax.plot([], [], "k:", lw=0.8, label="backbone")
        ax.plot([], [], "ko", mfc="none", ms=5, label="jump (saddle node), arrow: where it lands")
        ax.set_xlabel(_plot.label("frequency_hz"))
        ax.set_ylabel(_plot.label("amplitude_m"))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
        ax.set_title("Hertzian oscillator: response by drive voltage and preload", fontsize="medium")
        return ax

    def __repr__(self) -> str:
        st = [c.status for c in self.curves]
        counts = ", ".join(f"{k}={st.count(k)}" for k in sorted(set(st)))
        n = len(self.table.get("frequency_hz", ())) if self.table else 0
        f = self.frequency_hz
        band = f"{f[0]:.6g}..{f[-1]:.6g} Hz ({f.size})" if f.size else "no frequencies"
        return (f"<trum.Resonance {len(self.curves)} curves ({counts}); frequency {band}; table {n} rows x "
                f"{len(self.columns)} columns: {', '.join(self.columns)}>")


def resonance(
    *,
    voltage_v: Optional[Values] = None,
    preload_n: Values = 400.0,
    frequency_hz: Optional[Values] = None,
    method: str = "multiple_scales",
    oscillator: Optional[Mapping[str, float]] = None,
    motor: Union[Motor, str, None] = None,
) -> Resonance:
    """Amplitude–frequency response of the Hertzian oscillator ([Hertz2022] eq. 10-12) for
    every voltage × preload: all branches incl. the unstable one, backbone, jump-up and
    jump-down frequencies. Each of ``voltage_v``, ``preload_n``, ``frequency_hz`` is a
    number or explicit values (a list, a 1-D array); a range is ``trum.linspace(start,
    stop, n)``; ``voltage_v=None`` is 100, 200 and 300 V; ``frequency_hz=None`` picks 401 points
    over a band holding every peak and jump. ``method``: ``'multiple_scales'`` or
    ``'harmonic_balance'``. ``motor``: a :class:`trum.Motor` or preset name whose modal
    mass, damping, free resonance, force factor and ``hertz_softening`` the oscillator takes
    (as ``trum resonance --motor``); without it, :func:`hertz_defaults`. ``oscillator``:
    parameters overriding either. A point the softening spring cannot carry has status
    ``'no_static_equilibrium'``."""
    if voltage_v is None:
        voltage_v = [100.0, 200.0, 300.0]
    freqs = None if frequency_hz is None else np.ascontiguousarray(_values("frequency_hz", frequency_hz))
    d = _trum.hertz_response(
        _params(oscillator, motor), _values("voltage_v", voltage_v), _values("preload_n", preload_n), freqs, method
    )
    curves = []
    for c in d["curves"]:
        c = dict(c)
        c["branch"] = np.array(c["branch"], dtype=object)
        curves.append(ResonanceCurve(**c))
    return Resonance(d["frequency_hz"], curves, dict(d["table"]), tuple(d["columns"]))


@dataclass(frozen=True)
class HertzIdentification:
    """β identified by harmonic balance, with the fit quality (see docs/DYNAMICS.md)."""

    beta_n_per_m3: float
    one_term_beta_n_per_m3: float
    harmonic_fit_r_squared: float
    waveform_residual_rms: float  # in the unit of the signal (V or m)
    balance_residual_rms_m: float
    balance_relative_residual: float
    displacement_amplitude_m: float
    periods_spanned: float
    drive_force_n: float


def identify_hertz(
    time_s: Any,
    signal: Any,
    *,
    frequency_hz: float,
    voltage_v: Optional[float] = None,
    preload_n: Optional[float] = None,
    drive_force_n: Optional[float] = None,
    feedback_gain_v_per_m: Optional[float] = None,
    oscillator: Optional[Mapping[str, float]] = None,
    harmonics: int = 3,
    motor: Union[Motor, str, None] = None,
) -> HertzIdentification:
    """The cubic coefficient β from a sampled waveform ([Hertz2022] eq. 5-9), given m, c and
    k: the ``motor``'s (as in :func:`resonance`) or the defaults, overridden by
    ``oscillator`` (e.g. ``{"modal_mass_kg": ..., "damping_ns_per_m": ...}``).

    ``signal`` is the feedback-electrode voltage [V] when ``feedback_gain_v_per_m`` is
    given, else the modal displacement [m]. The drive force is ``drive_force_n``, or
    A·V + k_c·N from ``voltage_v`` (and ``preload_n``); ``preload_n`` also adds the DC
    balance. Bad records raise :class:`trum.InputError` with the reason."""
    t = np.ascontiguousarray(np.asarray(time_s, dtype=np.float64))
    s = np.ascontiguousarray(np.asarray(signal, dtype=np.float64))
    if t.ndim != 1 or s.ndim != 1:
        raise InputError(f"time_s and signal must be 1-D arrays, got shapes {t.shape} and {s.shape}")
    if isinstance(harmonics, bool) or not isinstance(harmonics, numbers.Integral) or harmonics < 0:
        raise InputError(f"harmonics: expected a whole number >= 1, got {harmonics!r}")
    d = _trum.hertz_identify(
        t, s, float(frequency_hz), _params(oscillator, motor), voltage_v=voltage_v, preload_n=preload_n,
        drive_force_n=drive_force_n, feedback_gain_v_per_m=feedback_gain_v_per_m, harmonics=int(harmonics),
    )
    return HertzIdentification(**d)


@dataclass(frozen=True)
class Snapshot:
    """Contact state over one wavelength at one instant ([BarTransient] Fig. 10)."""

    requested_time_s: float
    time_s: float
    speed_rpm: float
    position_m: np.ndarray
    pressure_n_per_m: np.ndarray
    tangential_force_n_per_m: np.ndarray
    friction_limit_n_per_m: np.ndarray
    slip_speed_m_s: np.ndarray
    state: np.ndarray  # 'no_contact', 'stick' or 'slip' per node

    def to_pandas(self) -> Any:
        """One row per node: position and the contact state there."""
        pd = _require_pandas()
        df = pd.DataFrame({k: getattr(self, k) for k in ("position_m", "pressure_n_per_m", "tangential_force_n_per_m",
                                                          "friction_limit_n_per_m", "slip_speed_m_s", "state")})
        df["state"] = df["state"].astype("category")
        return df

    def __repr__(self) -> str:
        st = self.state
        counts = ", ".join(f"{k}={int(np.count_nonzero(st == k))}" for k in ("stick", "slip", "no_contact"))
        return f"<trum.Snapshot t={self.time_s:.6g} s, {self.speed_rpm:.5g} rpm; {st.size} nodes ({counts})>"


@dataclass(frozen=True)
class StepResult:
    """Result of :func:`step`. ``steady`` is ``None`` for a bar-type motor (no steady solver);
    at a phase difference other than ±90° (partly a standing wave) its numbers are NaN, its
    ``status`` is ``'not_comparable'`` and its ``note`` says why (``note`` is ``None``
    otherwise). At −90° it is the +90° solution mirrored, with or without load."""

    series: Dict[str, np.ndarray]
    metrics: Dict[str, Optional[float]]
    status: str  # 'ok' (moving, either way: a negative speed turns backwards), 'not_moving' or 'not_settled'
    averages: Dict[str, float]
    steady: Optional[Dict[str, Any]]
    snapshots: List[Snapshot] = field(default_factory=list)
    time_step_s: float = 0.0
    steps: int = 0
    #: the fixed drive and load, for titles: voltage_v, frequency_hz, preload_n, torque_nm
    conditions: Dict[str, float] = field(default_factory=dict)
    motor: str = ""

    def speed_difference(self) -> float:
        """(settled transient speed − steady-solver speed) / steady-solver speed (NaN
        without a steady solver or where it does not describe the point)."""
        if self.steady is None:
            return float("nan")
        return (self.averages["speed_rpm"] - self.steady["speed_rpm"]) / self.steady["speed_rpm"]

    def to_pandas(self) -> Any:
        """The time series as a tidy DataFrame, one row per recorded step (``time_s`` first)."""
        pd = _require_pandas()
        return pd.DataFrame(self.series)

    def plot(self, y: str = "speed_rpm", *, ax: Any = None) -> Any:
        """``y`` (default the rotor speed) against time [ms], with the period mean, the
        steady solver's speed and the metrics (delay, rise, settling) marked."""
        ax = _plot.axes(ax)
        t = np.asarray(self.series["time_s"])
        ft = _plot.factor("time_s")
        ax.plot(t * ft, self.series[y], lw=0.6, color="0.6", label="rotor speed")
        if y == "speed_rpm" and "speed_period_mean_rpm" in self.series:
            ax.plot(t * ft, self.series["speed_period_mean_rpm"], lw=1.4, color="C0", label="mean over a drive period")
        steady_speed = None if self.steady is None else self.steady.get("speed_rpm")
        if y == "speed_rpm" and steady_speed is not None and np.isfinite(steady_speed):
            ax.axhline(self.steady["speed_rpm"], color="C3", ls="--", lw=1, label="steady-state solver")
        for key, words in (("delay_s", "delay"), ("settling_time_s", "settled")):
            v = self.metrics.get(key)
            if v is not None:
                ax.axvline(v * ft, color="k", lw=0.6, ls=":")
                ax.annotate(words, (v * ft, 1.0), xycoords=("data", "axes fraction"), va="top", fontsize="x-small")
        ax.set_xlabel(_plot.label("time_s"))
        ax.set_ylabel(_plot.label(y))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small", loc="lower right")
        if self.conditions:
            ax.set_title(_plot.caption(self.conditions, self.motor or None, "none"), fontsize="medium")
        return ax

    def __repr__(self) -> str:
        n = len(next(iter(self.series.values()))) if self.series else 0
        m = ", ".join(f"{k}={v:.4g}" for k, v in self.metrics.items() if v is not None)
        return (f"<trum.StepResult {self.status}; {n} samples x {len(self.series)} series "
                f"({', '.join(self.series)}); metrics: {m or 'none'}; {len(self.snapshots)} snapshots>")


def _require_name(motor: Any) -> str:
    if isinstance(motor, str):
        return motor
    raise TypeError(f"expected a trum.Motor or a preset name, got {type(motor).__name__}")


def step(
    motor: Union[Motor, str],
    *,
    voltage_v: Optional[float] = None,
    moment_nm: Optional[float] = None,
    frequency_hz: Optional[float] = None,
    phase_difference_deg: Optional[float] = None,
    preload_n: Optional[float] = None,
    torque_nm: float = 0.0,
    duration_s: Optional[float] = None,
    steps_per_period: Optional[int] = None,
    nodes_per_wavelength: int = 256,
    tangential_stiffness_ratio: Optional[float] = None,
    record_every: int = 16,
    snapshot_at_s: Sequence[float] = (),
) -> StepResult:
    """Step response of the rotor speed with the stick-slip contact ([BarTransient]): the drive
    switches on at t = 0. Returns the time series, the metrics (delay, rise times,
    peak time, overshoot, settling time; ``None`` where undefined, e.g. a standing wave at
    0°), the settled averages, the steady-state solver at the same point (mirrored for a
    reversed wave at −90°: negative speed and torque; NaN with a ``UserWarning`` where it
    does not describe the point, see :class:`StepResult`) and the contact
    snapshots at ``snapshot_at_s``. A negative final speed (e.g. at −90°) is rotation the
    other way, status ``ok``. The GIL is released while it runs.

    ``motor``: a ring motor (``trum.Motor`` or preset name; driven by ``voltage_v``,
    by default at the motor's ``[drive]`` (``Motor.drive``; else 200 V at 43 kHz), 260 N,
    10 ms) or a bar-type motor (preset name such as
    ``"bar36"`` or a bar-type motor file path; driven by ``moment_nm``, every default from
    the motor's ``[drive]``: 0.25 N·m at 36.7 kHz, 40 N, 15 ms for ``bar36``).

    ``torque_nm``: load torque T_load [N·m], ≥ 0, a Coulomb brake ([BarTransient] eq. 4 with
    T_load·sign Ω): it opposes the rotation either way and holds the rotor at rest while
    the contact torque stays within it.

    ``steps_per_period``: time steps per drive period; by default 64, raised in steps of 16
    on a ring motor where the explicit scheme would be unstable (``time_step_s`` of the
    result says which step ran); given, it is used as is."""
    auto_steps = steps_per_period is None
    steps_per_period = 64 if steps_per_period is None else steps_per_period
    for name, v in (("steps_per_period", steps_per_period), ("nodes_per_wavelength", nodes_per_wavelength),
                    ("record_every", record_every)):
        if isinstance(v, bool) or not isinstance(v, numbers.Integral) or v < 0:
            raise InputError(f"{name}: expected a whole number, got {v!r}")
    snaps_at = [float(t) for t in snapshot_at_s]
    if isinstance(motor, str) and _trum.is_bar_motor(motor):
        if voltage_v is not None:
            raise InputError("voltage_v: a bar-type motor is driven by a moment; give moment_nm")
        if tangential_stiffness_ratio is not None:
            raise InputError(
                "tangential_stiffness_ratio: a bar-type motor file sets contact.tangential_stiffness_n_per_m2"
            )
        dflt = dict(_trum.bar_defaults(motor))
        pick = lambda v, k: float(dflt[k] if v is None else v)  # noqa: E731
        d = _trum.bar_step(
            motor, pick(moment_nm, "moment_nm"), pick(frequency_hz, "frequency_hz"),
            pick(phase_difference_deg, "phase_difference_deg"), pick(preload_n, "preload_n"), float(torque_nm),
            pick(duration_s, "duration_s"), int(steps_per_period), int(nodes_per_wavelength), int(record_every),
            snaps_at,
        )
        cond = {"moment_nm": pick(moment_nm, "moment_nm"), "frequency_hz": pick(frequency_hz, "frequency_hz"),
                "preload_n": pick(preload_n, "preload_n"), "torque_nm": float(torque_nm)}
        name = motor
    else:
        if moment_nm is not None:
            raise InputError("moment_nm drives a bar-type motor; a ring motor is driven by voltage_v")
        m = motor if isinstance(motor, Motor) else Motor(_require_name(motor))
        # A paper preset may carry effects its paper's model includes (docs/PRESETS.md); the
        # transient model has none of them, so it runs on the preset's baseline and says so,
        # as `trum step` does. Effects a user switched on are still refused.
        if m.preset_name is not None and m.active_effects and m.active_effects == Motor(m.preset_name).active_effects:
            warnings.warn(
                f"the transient model has no unmodelled effects: {m.preset_name} runs without its "
                f"{', '.join(m.active_effects)}",
                stacklevel=2,
            )
            m = m.with_effects("none")
        opt = lambda v, default: float(default if v is None else v)  # noqa: E731
        # the drive of the motor's figures, as trum.solve and trum step use it
        drive_v, drive_hz = _drive(_motor(m))
        d = _trum.step(
            _motor(m), opt(voltage_v, drive_v), opt(frequency_hz, drive_hz), opt(phase_difference_deg, 90.0),
            opt(preload_n, 260.0), float(torque_nm), opt(duration_s, 10e-3), int(steps_per_period),
            int(nodes_per_wavelength), opt(tangential_stiffness_ratio, 300.0), int(record_every), snaps_at,
            auto_steps,
        )
        cond = {"voltage_v": opt(voltage_v, drive_v), "frequency_hz": opt(frequency_hz, drive_hz),
                "preload_n": opt(preload_n, 260.0), "torque_nm": float(torque_nm)}
        name = m.name
    snaps = []
    for s in d["snapshots"]:
        s = dict(s)
        s["state"] = np.array(s["state"], dtype=object)
        snaps.append(Snapshot(**s))
    steady = None if d["steady"] is None else dict(d["steady"])
    if steady is not None and steady.get("note"):
        warnings.warn(f"no steady comparison (steady numbers NaN): {steady['note']}", stacklevel=2)
    return StepResult(dict(d["series"]), dict(d["metrics"]), d["status"], dict(d["averages"]), steady,
                      snaps, d["time_step_s"], d["steps"], cond, name)
