"""Maps over a full-factorial grid and the preload criterion."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _axes, _plot, _trum
from ._axes import Values
from ._errors import InputError
from ._motor import Motor, _max_points
from ._registry import QUANTITY_NAMES, STATUS_NAMES, quantities, warning_words
from ._result import _require_pandas

AxisSpec = Values
_STATUS = np.array(STATUS_NAMES)
WEIGHT_NAMES = ("stall_torque", "efficiency", "temperature_rise", "speed_fluctuation")
#: Nesting of a map's points, slowest first (torque varies fastest).
_NESTING = ("preload_n", "voltage_v", "frequency_hz", "torque_nm")
_CORE_DEFAULT_DRIVE = (200.0, 43e3)


def _motor(m: Any) -> Any:
    if isinstance(m, Motor):
        return m._m
    if isinstance(m, str):
        return Motor(m)._m
    raise TypeError(f"expected a trum.Motor or a preset name, got {type(m).__name__}")


def _drive(m: Any) -> Tuple[float, float]:
    """The motor's ``[drive]`` (or its preset's), else the core's 200 V, 43 kHz."""
    return m.drive or _CORE_DEFAULT_DRIVE


def _check_axis(name: str, v: np.ndarray) -> None:
    """The CLI's rule for grid axes (trum_core::sweep::Grid::validate), word for word."""
    for x in v:
        if not np.isfinite(x):
            raise InputError(f"{name}: {x:g} is not a finite number")
        if (x < 0.0) if name == "torque_nm" else (x <= 0.0):
            raise InputError(f"{name}: {x:g} must be {'>= 0' if name == 'torque_nm' else '> 0'}")


class MapResult(dict):
    """The columns of :func:`map` (a dict of flat arrays, so ``pandas.DataFrame(res)`` works)
    with the grid they came from: ``axes`` (values per axis), ``shape`` (points per axis in
    nesting order preload, voltage, frequency, torque), ``motor`` and ``effects``.
    ``to_pandas()``, ``to_xarray()`` and ``plot()`` convert it."""

    axes: Dict[str, np.ndarray]
    motor: str
    effects: str

    @property
    def shape(self) -> Tuple[int, ...]:
        return tuple(self.axes[a].size for a in _NESTING)

    @property
    def swept(self) -> List[str]:
        """Axes with more than one value, in nesting order."""
        return [a for a in _NESTING if self.axes[a].size > 1]

    @property
    def fixed(self) -> Dict[str, float]:
        """Axes with one value: ``{name: value}``."""
        return {a: float(self.axes[a][0]) for a in _NESTING if self.axes[a].size == 1}

    def counts(self) -> Dict[str, int]:
        """Number of points per status word."""
        s = self.get("status", np.array([], dtype=object))
        return {n: int(np.count_nonzero(s == n)) for n in STATUS_NAMES}

    def to_pandas(self) -> Any:
        """A tidy DataFrame: one row per point, unit-suffixed columns, categorical ``status``."""
        pd = _require_pandas()
        cols = {k: v for k, v in self.items()}
        cols["status"] = pd.Categorical(self["status"], categories=list(STATUS_NAMES))
        return pd.DataFrame(cols)

    def to_xarray(self) -> Any:
        """An ``xarray.Dataset`` with one dimension per swept axis (coordinates in nesting
        order), the fixed axes as scalar coordinates, every quantity and ``status`` as data
        variables, and each variable's unit and meaning in its ``attrs``."""
        try:
            import xarray as xr
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("to_xarray() needs xarray: pip install xarray") from e
        shape = self.shape
        swept = self.swept
        keep = [i for i, a in enumerate(_NESTING) if a in swept]
        units = {q.name: (q.unit, q.doc) for q in quantities()}
        units["loaded_stall_torque_nm"] = (
            "N·m", "load torque at which the loaded motor stops (stall or clamp) at this preload and drive")
        axis_units = {"preload_n": "N", "voltage_v": "V", "frequency_hz": "Hz", "torque_nm": "N·m"}
        coords: Dict[str, Any] = {}
        for a in _NESTING:
            attrs = {"units": axis_units[a], "long_name": _plot.label(a).split(" [")[0]}
            coords[a] = ((a,), self.axes[a], attrs) if a in swept else ((), float(self.axes[a][0]), attrs)
        data: Dict[str, Any] = {}
        for k, v in self.items():
            if k in _NESTING:
                continue
            arr = np.asarray(v).reshape(shape)
            arr = arr.reshape([shape[i] for i in keep])
            attrs = {}
            if k in units:
                attrs = {"units": units[k][0], "description": units[k][1]}
            data[k] = (tuple(swept), arr, attrs)
        return xr.Dataset(data, coords=coords, attrs={"motor": self.motor, "effects": self.effects})

    def plot(self, kind: str = "speed_torque", *, ax: Any = None, y: str = "speed_rpm", by: Optional[str] = None) -> Any:
        """``kind='speed_torque'``: ``y`` (default speed) against load torque, one line per value
        of the other swept axis (or ``by``). ``kind='efficiency_map'``: efficiency contours in
        the speed-over-torque plane with the stall boundary; stalled points are left out, not
        drawn as efficiency 0. Returns the matplotlib Axes."""
        if kind == "speed_torque":
            return _plot_speed_torque(self, ax, y, by)
        if kind == "efficiency_map":
            return _plot_efficiency_map(self, ax)
        raise ValueError(f"kind: expected 'speed_torque' or 'efficiency_map', got {kind!r}")

    def __repr__(self) -> str:
        sw = ", ".join(f"{a}[{self.axes[a].size}] {self.axes[a][0]:g}..{self.axes[a][-1]:g}" for a in self.swept)
        fx = ", ".join(f"{a}={v:g}" for a, v in self.fixed.items())
        counts = ", ".join(f"{k}={v}" for k, v in self.counts().items() if v)
        n = len(self.get("status", ()))
        return (f"<trum.MapResult {n} points; swept: {sw or 'none'}; fixed: {fx or 'none'}; {counts or 'empty'}; "
                f"{len(self)} columns: {', '.join(list(self)[:6])}, ...>")

    __str__ = __repr__


def _other_swept(r: MapResult, x: str, by: Optional[str]) -> List[str]:
    if by is not None:
        return [by]
    return [a for a in r.swept if a != x]


def _plot_speed_torque(r: MapResult, ax: Any, y: str, by: Optional[str]) -> Any:
    if "torque_nm" not in r.swept:
        raise InputError("a speed-torque plot needs a map swept over torque_nm (e.g. torque_nm=trum.linspace(0, 0.6, 13))")
    ax = _plot.axes(ax)
    groups = list(_plot.group_masks(r, _other_swept(r, "torque_nm", by)))
    _plot.lines(ax, r["torque_nm"], np.where(r["status"] == "ok", r[y], np.nan), "torque_nm", y, groups)
    if len(groups) > 1:
        ax.legend(fontsize="small")
    ax.set_title(_plot.caption(r.fixed, r.motor, r.effects), fontsize="medium")
    return ax


def _plot_efficiency_map(r: MapResult, ax: Any) -> Any:
    if "torque_nm" not in r.swept or len(r.swept) != 2:
        raise InputError("an efficiency map needs a map swept over torque_nm and one other axis "
                         f"(this map sweeps: {', '.join(r.swept) or 'nothing'})")
    plt = _plot._require_matplotlib()
    ax = _plot.axes(ax)
    other = [a for a in r.swept if a != "torque_nm"][0]
    shape = (r.axes[other].size, r.axes["torque_nm"].size)  # torque varies fastest
    running = (r["status"] == "ok") & np.isfinite(r["efficiency"]) & np.isfinite(r["speed_rpm"])
    if np.count_nonzero(running) < 4:
        raise InputError("an efficiency map needs at least 4 running points")
    t = r["torque_nm"].reshape(shape)
    v = np.where(running, r["speed_rpm"], np.nan).reshape(shape)
    e = np.ma.masked_invalid(np.where(running, 100.0 * r["efficiency"], np.nan).reshape(shape))
    # the (torque, speed) grid is curvilinear: each row is one value of the other axis
    tt = np.ma.masked_where(np.ma.getmaskarray(e), t)
    vv = np.ma.masked_invalid(v)
    cs = ax.contourf(tt, vv, e, levels=12, cmap="viridis")
    lines = ax.contour(tt, vv, e, levels=cs.levels[1::2], colors="white", linewidths=0.7)
    ax.clabel(lines, fmt="%.0f %%", fontsize="x-small")
    plt.colorbar(cs, ax=ax, label=_plot.label("efficiency"))
    # each row's curve, thin, so the swept axis can be read off
    for i in range(shape[0]):
        ax.plot(t[i], v[i], color="white", lw=0.3, alpha=0.6)
    # stall boundary: per row, the last running torque before the motor stalls
    bt, bv = [], []
    stalled = (r["status"] == "stall").reshape(shape)
    for i in range(shape[0]):
        ok_i = np.flatnonzero(running.reshape(shape)[i])
        if ok_i.size and stalled[i, ok_i[-1] + 1:].any():
            bt.append(t[i, ok_i[-1]])
            bv.append(v[i, ok_i[-1]])
    if bt:
        ax.plot(bt, bv, "k--", lw=1.2, label="stall boundary")
        ax.legend(fontsize="small", loc="upper right")
    ax.set_xlabel(_plot.label("torque_nm"))
    ax.set_ylabel(_plot.label("speed_rpm"))
    a0, a1 = r.axes[other][0], r.axes[other][-1]
    ax.set_title(_plot.caption(r.fixed, r.motor, r.effects)
                 + f"\none curve per {_plot.value_text(other, a0)} ... {_plot.value_text(other, a1).split(' ', 1)[1]}",
                 fontsize="medium")
    return ax


def map(  # noqa: A001 - the CLI's name for it
    motor: Union[Motor, str],
    *,
    preload_n: AxisSpec,
    voltage_v: Optional[AxisSpec] = None,
    frequency_hz: Optional[AxisSpec] = None,
    torque_nm: AxisSpec = 0.0,
    max_points: int = 20_000_000,
    parallel: Optional[bool] = None,
    loaded_stall: bool = True,
) -> MapResult:
    """A full-factorial map over preload × voltage × frequency × torque, as ``trum map``
    computes it. Each axis is a number or explicit values (a list, a NumPy array, a
    pandas Series); a range is ``trum.linspace(start, stop, n)`` or ``np.linspace``.
    Without ``voltage_v``/``frequency_hz`` the motor's drive is used (its ``[drive]``, else
    200 V, 43 kHz), as the CLI does. Every point must be a valid operating point (preload,
    voltage, frequency > 0, torque >= 0), else ``InputError`` names the axis.

    Returns a :class:`MapResult`: flat columns ``{preload_n, torque_nm, voltage_v,
    frequency_hz, status, warnings, <quantities>}`` (``warnings``: the motor's ``[limits]``
    keys a point exceeds, ``;``-joined, "" when none, as ``trum map`` writes them), then
    ``loaded_stall_torque_nm``: the load torque at which the loaded motor stops (stall or
    clamp) on the point's torque line, as ``trum map`` and ``trum point`` report it. A point
    is ``ok`` below it and not above it; ``stall_torque_nm`` (the rotor-at-rest torque at
    the point's own amplitude) can be far above it near clamping. It is one bisection of
    about 30 solves per (preload, voltage, frequency), shared along the torque axis; NaN
    where the rotor does not run at no load; ``loaded_stall=False`` leaves it out (a map
    with few torque values per line then costs several times less). Points run torque
    fastest, then frequency, voltage, preload. When every axis is evenly spaced the grid is solved as ``trum map``
    solves it (warm-started in the same fixed chunks: the CLI's numbers bit for bit, not
    depending on threads); other values are solved point by point from a cold start, as
    ``Motor.solve`` does. Both agree within the solver tolerance.
    """
    m = _motor(motor)
    v0, f0 = _drive(m)
    ax = {
        "preload_n": _axes.values("preload_n", preload_n),
        "torque_nm": _axes.values("torque_nm", torque_nm),
        "voltage_v": _axes.values("voltage_v", v0 if voltage_v is None else voltage_v),
        "frequency_hz": _axes.values("frequency_hz", f0 if frequency_hz is None else frequency_hz),
    }
    for name in _trum.AXES:
        _check_axis(name, ax[name])
    max_points = _max_points(max_points)
    n = int(np.prod([a.size for a in ax.values()], dtype=np.int64))
    if n > max_points:
        raise InputError(f"the map has {n} points, more than max_points = {max_points}; split it or raise max_points")
    ranges = {k: _axes.as_range(v) for k, v in ax.items()}
    out = MapResult()
    if all(r is not None for r in ranges.values()):
        d = _trum.map_grid(m, max_points=int(max_points), parallel=parallel, **ranges)
        out.update({k: d[k] for k in _trum.AXES})
        codes = d["status_code"]
        q = {k: d[k] for k in QUANTITY_NAMES}
        ax = {k: _axes.linspace(*ranges[k]) for k in ax}
    else:
        p, v, f, t = np.meshgrid(*(ax[a] for a in _NESTING), indexing="ij")
        flat = {"preload_n": p.ravel(), "voltage_v": v.ravel(), "frequency_hz": f.ravel(), "torque_nm": t.ravel()}
        d = _trum.solve_arrays(m, flat["preload_n"], flat["torque_nm"], flat["voltage_v"], flat["frequency_hz"],
                               np.zeros(1), parallel=parallel)
        out.update({k: flat[k] for k in _trum.AXES})
        codes = d["status_code"]
        q = {k: d[k] for k in QUANTITY_NAMES}
    out["status"] = _STATUS[codes]
    out["warnings"] = warning_words(d["warning_code"])
    out.update(q)
    if loaded_stall:
        # one value per torque line, repeated along the torque axis (the fastest)
        p, v, f = np.meshgrid(ax["preload_n"], ax["voltage_v"], ax["frequency_hz"], indexing="ij")
        lines = _trum.loaded_stall_lines(m, p.ravel(), v.ravel(), f.ravel(), parallel=parallel)
        out["loaded_stall_torque_nm"] = np.repeat(lines, ax["torque_nm"].size)
    out.axes = ax
    out.motor = m.name
    out.effects = m.effects
    return out


@dataclass
class Optimum:
    """The preload criterion: one row per candidate preload, the optimum and its region."""

    table: Dict[str, np.ndarray]
    optimum_preload_n: float
    region_n: Tuple[float, float]
    config: Dict[str, Any] = field(default_factory=dict)
    motor: str = ""
    effects: str = ""
    #: True when the optimum was chosen among the candidates within the motor's
    #: ``[limits]`` (the ``warnings`` column); False when none is within them.
    within_limits: bool = True

    def to_pandas(self) -> Any:
        """The table as a tidy DataFrame (one row per candidate preload, unit-suffixed
        columns, categorical ``status``)."""
        pd = _require_pandas()
        df = pd.DataFrame(self.table)
        df["status"] = df["status"].astype("category")
        return df

    def plot(self, y: Sequence[str] = ("stall_torque_nm", "max_efficiency", "score"), *, ax: Any = None) -> Any:
        """The criterion's terms against preload, one panel per column of ``y``, the optimum
        and its region marked. Returns the Axes (an array when ``y`` has several)."""
        plt = _plot._require_matplotlib()
        y = [y] if isinstance(y, str) else list(y)
        if ax is None:
            _, ax = plt.subplots(len(y), 1, sharex=True, figsize=(6.4, 1.6 + 1.6 * len(y)), constrained_layout=True)
        axs = np.atleast_1d(ax)
        p = self.table["preload_n"]
        for a, col in zip(axs, y):
            a.plot(p, np.asarray(self.table[col]) * _plot.factor(col), "o-", ms=3)
            a.axvspan(*self.region_n, color="tab:green", alpha=0.15, label="optimal region")
            a.axvline(self.optimum_preload_n, color="tab:green", lw=1, label=f"optimum {self.optimum_preload_n:.4g} N")
            a.set_ylabel(_plot.label(col))
            a.grid(True, alpha=0.3)
        axs[0].legend(fontsize="small")
        axs[-1].set_xlabel(_plot.label("preload_n"))
        fixed = {"voltage_v": self.config.get("voltage_v", np.nan), "frequency_hz": self.config.get("frequency_hz", np.nan)}
        axs[0].set_title(_plot.caption(fixed, self.motor or None, self.effects or None), fontsize="medium")
        return ax

    def __repr__(self) -> str:
        n = len(self.table.get("preload_n", ()))
        st = np.asarray(self.table.get("status", []))
        counts = ", ".join(f"{k}={int(np.count_nonzero(st == k))}" for k in np.unique(st))
        return (f"<trum.Optimum optimum_preload_n={self.optimum_preload_n:.6g} region_n=({self.region_n[0]:.6g}, "
                f"{self.region_n[1]:.6g}); {n} candidate preloads ({counts}); columns: {', '.join(self.table)}>")


def optimize(
    motor: Union[Motor, str],
    *,
    voltage_v: Optional[float] = None,
    frequency_hz: Optional[float] = None,
    preload_n: Optional[AxisSpec] = None,
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
    ``preload_n`` is evenly spaced values (``trum.linspace(150, 500, 36)``). Unset settings
    take the motor's drive (its ``[drive]``, as ``trum optimize``), else the core defaults
    (200 V, 43 kHz, 150-500 N in 36 steps, weights 1, 1, 2, 2).
    Candidates beyond the motor's ``[limits]`` (``warnings`` column) are scored but kept
    out of the optimum and its region, as in ``trum optimize``.
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
    m = _motor(motor)
    d = _trum.criterion(
        m,
        voltage_v=voltage_v if voltage_v is not None else (m.drive[0] if m.drive else None),
        frequency_hz=frequency_hz if frequency_hz is not None else (m.drive[1] if m.drive else None),
        preload_n=None if preload_n is None else _criterion_preloads(preload_n),
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
    return Optimum(table, d["optimum_preload_n"], tuple(d["region_n"]), cfg, m.name, m.effects, bool(d["within_limits"]))


def _criterion_preloads(spec: AxisSpec) -> Tuple[float, float, int]:
    v = _axes.values("preload_n", spec)
    r = _axes.as_range(v)
    if r is None:
        raise InputError("preload_n: the criterion needs evenly spaced candidate preloads; "
                         f"write e.g. preload_n=trum.linspace({v.min():g}, {v.max():g}, {v.size})")
    return r
