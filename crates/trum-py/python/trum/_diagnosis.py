"""The sim-to-real diagnosis from Python (the document: docs/DIAGNOSIS_JSON.md)."""
from __future__ import annotations

import json
import os
import warnings
from typing import Any, Dict, List, Mapping, Optional, Tuple, Union

import numpy as np

from . import _trum
from ._api import _motor
from ._errors import InputError, decode_utf8
from ._motor import Motor
from ._result import _require_pandas


DataLike = Union[str, "os.PathLike[str]", bytes, Any]


def _read_data(data: DataLike) -> Tuple[bytes, str]:
    """The bytes of a measurement CSV and the name messages give it: a path, the file's
    bytes, its text, an open file (text or binary) or a pandas DataFrame (its columns as the
    CSV's)."""
    if isinstance(data, (bytes, bytearray)):
        return bytes(data), "<bytes>"
    if isinstance(data, str) and ("\n" in data or "\r" in data):
        # CSV text rather than a path (no file name has a line break)
        return data.encode("utf-8"), "<text>"
    if isinstance(data, (str, os.PathLike)):
        source = os.fspath(data)
        if os.path.isdir(source):
            raise InputError(f"measurement file '{source}' is a directory")
        try:
            with open(source, "rb") as f:
                return f.read(), source
        except FileNotFoundError:
            raise InputError(f"measurement file '{source}' does not exist") from None
        except OSError as e:
            raise InputError(f"cannot read measurement file '{source}': {e.strerror}") from None
    if hasattr(data, "to_csv") and hasattr(data, "columns"):
        # a DataFrame: the index is not a measurement column; numbers at full precision
        text = data.to_csv(index=False, float_format="%.17g", na_rep="")
        return text.encode("utf-8"), "<DataFrame>"
    if hasattr(data, "read"):
        raw = data.read()
        name = getattr(data, "name", None)
        source = name if isinstance(name, str) else "<file>"
        return (raw.encode("utf-8") if isinstance(raw, str) else bytes(raw)), source
    raise TypeError(
        f"data: expected a measurement file's path, bytes or text, an open file or a pandas DataFrame, "
        f"got {type(data).__name__}"
    )


def _plausible_specs(plausible: Optional[Mapping[str, Any]]) -> List[str]:
    """``{"speed_rpm": (0, 2e4), "preload_n": None}`` as the CLI's ``--plausible`` specs
    (an infinite end is no bound there, as ``None`` is)."""
    specs = []
    for col, rng in (plausible or {}).items():
        if rng is None:
            specs.append(f"{col}=any")
        else:
            lo, hi = rng
            end = lambda x: "" if x is None or np.isinf(float(x)) else repr(float(x))  # noqa: E731
            specs.append(f"{col}={end(lo)}:{end(hi)}")
    return specs


Plausible = Union[None, Mapping[str, Any], str, "os.PathLike[str]"]


class _TomlText:
    """A TOML file already read: its text and name (what travels to a Dask worker, which
    may not see the client's files)."""

    __slots__ = ("text", "source")

    def __init__(self, text: str, source: str) -> None:
        self.text, self.source = text, source

    def __reduce__(self) -> Any:
        return (_TomlText, (self.text, self.source))


def _read_toml(path: Union[str, "os.PathLike[str]"], what: str) -> Tuple[str, str]:
    """The text and name of the TOML file ``path`` given as ``what=``; a missing file or
    bytes that are not UTF-8 raise ``trum.InputError`` naming the file (and line, byte)."""
    source = os.fspath(path)
    try:
        with open(source, "rb") as f:
            raw = f.read()
    except FileNotFoundError:
        raise InputError(f"{what}: TOML file '{source}' does not exist") from None
    except OSError as e:
        raise InputError(f"{what}: cannot read TOML file '{source}': {e.strerror}") from None
    return decode_utf8(raw, source, InputError), source


def _plausible_args(plausible: Plausible) -> Tuple[List[str], Optional[Tuple[str, str]]]:
    """``plausible=`` as the extension takes it: the specs of a mapping, or the text and
    name of a TOML file whose ``[plausible]`` table sets the ranges (a motor file)."""
    if plausible is None:
        return [], None
    if isinstance(plausible, _TomlText):
        return [], (plausible.text, plausible.source)
    if isinstance(plausible, (str, os.PathLike)):
        return [], _read_toml(plausible, "plausible")
    if isinstance(plausible, Mapping):
        return _plausible_specs(plausible), None
    raise TypeError(
        "plausible: expected a mapping {column: (low, high) or None} or the path of a TOML file with a "
        f"[plausible] table, got {type(plausible).__name__}"
    )


Tolerances = Union[None, Mapping[str, float], str, "os.PathLike[str]"]
SensorNoise = Optional[Mapping[str, Union[float, Tuple[float, float]]]]


def _sensor_noise_args(sensor_noise: SensorNoise) -> List[str]:
    """``sensor_noise=`` as the extension takes it: ``COLUMN=SD`` or ``COLUMN=SD,REL`` texts."""
    if sensor_noise is None:
        return []
    if not isinstance(sensor_noise, Mapping):
        raise TypeError("sensor_noise must be a mapping of column names to sd or (sd, rel)")
    out = []
    for col, level in sensor_noise.items():
        if isinstance(level, (tuple, list)):
            if len(level) != 2:
                raise TypeError(f"sensor_noise[{col!r}]: expected sd or (sd, rel), got {level!r}")
            out.append(f"{col}={float(level[0])!r},{float(level[1])!r}")
        else:
            out.append(f"{col}={float(level)!r}")
    return out


def _tolerances_args(tolerances: Tolerances) -> Tuple[List[Tuple[str, float]], Optional[Tuple[str, str]]]:
    """``tolerances=`` as the extension takes it: the (key, value) pairs of a mapping, or the
    text and name of a TOML file whose ``[tolerances]`` table sets the priors (a motor
    file). The keys and values are checked by the extension, which names the bad one."""
    if tolerances is None:
        return [], None
    if isinstance(tolerances, _TomlText):
        return [], (tolerances.text, tolerances.source)
    if isinstance(tolerances, (str, os.PathLike)):
        return [], _read_toml(tolerances, "tolerances")
    if isinstance(tolerances, Mapping):
        pairs = []
        for k, v in tolerances.items():
            try:
                pairs.append((str(k), float(v)))
            except (TypeError, ValueError):
                raise InputError(
                    f"tolerances, key 'tolerances.{k}': expected a number (relative standard deviation, 0 or inf), "
                    f"got {v!r}"
                ) from None
        return pairs, None
    raise TypeError(
        "tolerances: expected a mapping {parameter key: relative standard deviation} or the path of a TOML file "
        f"with a [tolerances] table, got {type(tolerances).__name__}"
    )


def _portable(arg: Any, read: Any) -> Any:
    """``plausible=`` or ``tolerances=`` in a form that travels to a Dask worker: a TOML
    file as its text (read once here by ``read``, the argument's parser), a mapping as a
    plain dict."""
    _, toml = read(arg)
    if toml is not None:
        return _TomlText(*toml)
    return None if arg is None else dict(arg)


class Diagnosis(dict):
    """The diagnosis document (docs/DIAGNOSIS_JSON.md) as a dict, with tables and a plot:
    ``to_pandas()`` (the held-out readings with their predictions), ``to_pandas("ranking")``
    (every candidate effect), ``to_pandas("where")`` (where the baseline misses), and
    ``plot()`` (the held-out residuals per quantity, before and after the verdict)."""

    def to_pandas(self, table: str = "heldout") -> Any:
        """``'heldout'``: one row per held-out reading (``row``, ``line``, ``quantity``,
        ``measured``, ``baseline``, ``after``, and the residuals ``residual_baseline`` and
        ``residual_after`` = measured − predicted, in the quantity's unit); ``'ranking'``:
        one row per candidate (``effect``, ``evidence``, ``heldout_nrmse_after``, ``shrink``,
        ...); ``'where'``: the regions of ``gap.where``."""
        pd = _require_pandas()
        if table == "heldout":
            df = pd.DataFrame(self.get("heldout", []), columns=["row", "line", "quantity", "measured", "baseline", "after"])
            df = df.astype({"measured": float, "baseline": float, "after": float})
            df["residual_baseline"] = df["measured"] - df["baseline"]
            df["residual_after"] = df["measured"] - df["after"]
            df["quantity"] = df["quantity"].astype("category")
            return df
        if table == "ranking":
            rows = [{k: v for k, v in r.items() if k not in ("params", "shrink_interval")} for r in self.get("ranking", [])]
            return pd.DataFrame(rows)
        if table == "where":
            return pd.DataFrame(self.get("gap", {}).get("where", []))
        raise ValueError(f"table: expected 'heldout', 'ranking' or 'where', got {table!r}")

    def plot(self, *, ax: Any = None) -> Any:
        """Held-out residual (measured − predicted) per reading, one panel per measured
        quantity: the calibrated baseline's and, with the verdict's effect(s) added, what is
        left. Returns the Axes (one per quantity)."""
        from . import _plot

        plt = _plot._require_matplotlib()
        held = self.get("heldout", [])
        qs = list(dict.fromkeys(h["quantity"] for h in held))
        if not qs:
            raise InputError("this diagnosis has no held-out readings to plot")
        if ax is None:
            _, ax = plt.subplots(len(qs), 1, figsize=(6.4, 1.2 + 2.0 * len(qs)), constrained_layout=True, squeeze=False)
            ax = ax[:, 0]
        axs = np.atleast_1d(ax)
        after_name = self.get("verdict", "")
        for a, q in zip(axs, qs):
            h = [x for x in held if x["quantity"] == q]
            i = np.arange(len(h))
            meas = np.array([np.nan if x["measured"] is None else x["measured"] for x in h], dtype=float)
            base = np.array([np.nan if x["baseline"] is None else x["baseline"] for x in h], dtype=float)
            aft = np.array([np.nan if x["after"] is None else x["after"] for x in h], dtype=float)
            f = _plot.factor(q)
            a.axhline(0, color="k", lw=0.6)
            a.plot(i, (meas - base) * f, "o", ms=3, color="C3", label="calibrated baseline")
            if after_name not in ("none", "unexplained"):
                a.plot(i, (meas - aft) * f, "s", ms=3, mfc="none", color="C0", label=f"with {after_name}")
            words = _plot.label(q)
            a.set_ylabel("Residual of\n" + words[:1].lower() + words[1:], fontsize="small")
            a.grid(True, alpha=0.3)
        axs[0].legend(fontsize="small")
        axs[-1].set_xlabel("Held-out reading (in file order)")
        axs[0].set_title(f"Diagnosis of {self.get('motor', {}).get('name', 'the motor')}: verdict {after_name}",
                         fontsize="medium")
        return ax

    def __repr__(self) -> str:
        g = self.get("gap", {})
        return (f"<trum.Diagnosis verdict={self.get('verdict')!r} complete={self.get('complete')} "
                f"confounded_with={self.get('confounded_with')}; held-out NRMSE {g.get('baseline_heldout_nrmse', float('nan')):.3g} "
                f"-> {g.get('remaining_heldout_nrmse', float('nan')) or float('nan'):.3g} (noise {g.get('noise_nrmse', float('nan')):.3g}); "
                f"{len(self.get('ranking', []))} candidates; {self.get('n_rows')} rows>")

    __str__ = __repr__


def diagnose(
    motor: Union[Motor, str],
    data: DataLike,
    *,
    exact_cv: bool = False,
    plausible: Plausible = None,
    tolerances: Tolerances = None,
    sensor_noise: SensorNoise = None,
) -> Diagnosis:
    """Where the calibrated baseline misses the measurements, which unmodelled effect
    causes it, and how far the held-out gap shrinks once it is added.

    ``motor`` is the nominal motor (a ``trum.Motor`` or a preset name); ``data`` a
    measurement table in the layout of docs/MEASUREMENTS.md: a path, the file's bytes or
    text, an open file or a pandas DataFrame with those columns. Returns the JSON document of
    ``trum diagnose --json`` as a :class:`Diagnosis` (a dict: ``verdict``,
    ``confounded_with``, ``partial``, ``gap``, ``ranking``, ``notes``, ...; every field in
    docs/DIAGNOSIS_JSON.md, the method in docs/DIAGNOSIS.md), with ``to_pandas()`` and
    ``plot()``. Columns the reader ignores are reported with ``warnings.warn``. A bad file,
    or data that cannot support a held-out test, raises ``trum.InputError`` naming the
    file, line and column. The GIL is released while it runs.

    A value outside its column's plausible range (docs/MEASUREMENTS.md) is such an error;
    ``plausible={"speed_rpm": (0, 2e4), "preload_n": None}`` replaces ranges when the
    values are real (``None`` for no bound at all; ``None`` at either end of a pair for
    no bound there); ``plausible="motor.toml"`` reads them from the ``[plausible]`` table
    of a TOML file, such as the motor file (docs/MOTOR_FILE.md).

    ``tolerances`` sets the priors of the calibration, as a motor file's ``[tolerances]``
    table does for ``trum diagnose`` (docs/MOTOR_FILE.md): the path of a TOML file whose
    table is read (``tolerances="motor.toml"``, the motor file itself), or a mapping of
    dotted keys to the relative standard deviation, ``{"geometry.neutral_plane_distance_m":
    0.02, "stator.resonance_frequency_hz": 0, "bench.speed_std_floor_rpm": 0}`` (0 holds a
    parameter, ``float("inf")`` fits it without a prior; the bench keys state the sensors'
    specs). Without it the default tolerances apply. An unknown key raises
    ``trum.InputError`` listing the valid ones.

    ``sensor_noise`` states the noise levels of the bench's sensors, in place of the
    default levels and of their estimate from the data (as ``trum diagnose
    --sensor-noise``; docs/DIAGNOSIS.md, "Noise levels from the data"): a mapping of
    measured columns to the standard deviation in the column's unit, or to a pair
    (standard deviation, relative part), a reading's σ being ``sd + rel * |reading|``:
    ``{"speed_rpm": (0.3, 0.005), "current_a": 0.002}``. An unknown column or a level out
    of range raises ``trum.InputError``.
    """
    m = _motor(motor)
    raw, source = _read_data(data)
    motor_source = motor if isinstance(motor, str) else (m.preset or m.name)
    specs, toml = _plausible_args(plausible)
    tol, tol_toml = _tolerances_args(tolerances)
    noise = _sensor_noise_args(sensor_noise)
    text, notes = _trum.diagnose_csv(
        m, raw, source, motor_source, bool(exact_cv), specs, toml, tol, tol_toml, noise
    )
    for w in notes:
        warnings.warn(w, stacklevel=2)
    return Diagnosis(json.loads(text))


class Calibration:
    """Result of :func:`calibrate`: the calibrated motor and the fit, parameter by parameter.

    ``motor`` (a ``trum.Motor``), ``params`` (list of dicts: ``name``, ``nominal``,
    ``value``, ``std_error``, ``at_bound``, ``identifiable``), ``chi2``,
    ``chi2_per_reading`` (1 = fits to within the assumed noise), ``n_rows``,
    ``n_readings``, ``evaluations``, ``warnings``."""

    def __init__(self, d: Dict[str, Any]) -> None:
        self.motor: Motor = Motor._wrap(d["motor"])
        keys = ("name", "nominal", "value", "std_error", "at_bound", "identifiable")
        self.params = [dict(zip(keys, row)) for row in d["params"]]
        self.chi2: float = d["chi2"]
        self.chi2_per_reading: float = d["chi2_per_reading"]
        self.n_rows: int = d["n_rows"]
        self.n_readings: int = d["n_readings"]
        self.evaluations: int = d["evaluations"]
        self.warnings: List[str] = list(d["warnings"])

    def to_pandas(self) -> Any:
        """One row per fitted parameter: ``name``, ``nominal``, ``value``, ``std_error``,
        ``change`` (value / nominal − 1), ``at_bound``, ``identifiable``."""
        pd = _require_pandas()
        df = pd.DataFrame(self.params, columns=["name", "nominal", "value", "std_error", "at_bound", "identifiable"])
        df.insert(4, "change", df["value"] / df["nominal"] - 1.0)
        return df

    def __repr__(self) -> str:
        ident = sum(1 for p in self.params if p["identifiable"])
        return (f"<trum.Calibration {len(self.params)} parameters ({ident} identifiable), chi2/reading "
                f"{self.chi2_per_reading:.3g} over {self.n_readings} readings; {len(self.warnings)} warnings>")


def calibrate(
    motor: Union[Motor, str], data: DataLike, *, plausible: Plausible = None, tolerances: Tolerances = None
) -> Calibration:
    """Calibrates the uncertain baseline parameters of ``motor`` to measurements, as
    ``trum calibrate`` does (a maximum a posteriori fit, each parameter's tolerance as its
    prior; docs/DIAGNOSIS.md). ``data`` is a measurement table in the layout of
    docs/MEASUREMENTS.md: a path, the file's bytes, an open file or a pandas DataFrame.
    Returns a :class:`Calibration` (``.motor`` is the calibrated motor,
    ``.to_pandas()`` the parameter table). The reader's notes (ignored columns) come as
    ``warnings.warn``; a bad file raises ``trum.InputError`` naming the file, line and
    column. ``plausible`` replaces plausible ranges and ``tolerances`` sets the priors as
    in :func:`diagnose` (a mapping, or the path of a TOML file with a ``[plausible]`` or
    ``[tolerances]`` table, such as the motor file; without ``tolerances`` the default
    tolerances apply). The GIL is released while it runs."""
    m = _motor(motor)
    raw, source = _read_data(data)
    specs, toml = _plausible_args(plausible)
    tol, tol_toml = _tolerances_args(tolerances)
    d = _trum.calibrate_csv(m, raw, source, specs, toml, tol, tol_toml)
    for w in d["notes"]:
        warnings.warn(w, stacklevel=2)
    return Calibration(d)
