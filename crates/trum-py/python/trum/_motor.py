"""``trum.Motor``: presets, TOML files and dicts of unit-suffixed keys; vectorised solve."""
from __future__ import annotations

import math
import numbers
import os
from typing import Any, Dict, Iterable, List, Mapping, Optional, Tuple, Union

import numpy as np

from . import _trum
from ._errors import InputError, ParameterError, ParameterKeyError, TrumError, decode_utf8
from ._result import Result

ArrayLike = Any  # scalar or array of real numbers
_TOP_LEVEL = ("preset", "name", "effects")


def _number(source: str, key: str, v: Any) -> float:
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real):
        raise ParameterError(
            f"{source}, key '{key}': expected a number, got {type(v).__name__} {v!r}",
            source=source,
            key=key,
            reason=f"expected a number, got {type(v).__name__} {v!r}",
        )
    return float(v)


def _effect_specs(source: str, key: str, v: Any) -> List[str]:
    """Effect assignments (``name=strength`` / ``name:p=v,...``) from the dict forms."""
    if isinstance(v, str):
        return [v]
    if isinstance(v, Mapping):
        out = []
        for name, val in v.items():
            if isinstance(val, Mapping):
                parts = ",".join(f"{p}={_number(source, f'{key}.{name}.{p}', x)!r}" for p, x in val.items())
                out.append(f"{name}:{parts}" if parts else f"{name}=0")
            elif isinstance(val, str) and val == "none":
                out.append("none")
            else:
                out.append(f"{name}={_number(source, f'{key}.{name}', val)!r}")
        return out
    if isinstance(v, Iterable):
        return [str(s) for s in v]
    raise ParameterError(
        f"{source}, key '{key}': expected a dict, a string or a list of effect assignments",
        source=source,
        key=key,
        reason="expected a dict, a string or a list of effect assignments",
    )


def _flatten(d: Mapping[str, Any], prefix: str = "") -> Iterable[Tuple[str, Any]]:
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, Mapping) and key != "effects":
            yield from _flatten(v, key + ".")
        else:
            yield key, v


def _as_f64(name: str, x: ArrayLike) -> np.ndarray:
    if isinstance(x, np.ma.MaskedArray):
        # A masked entry has no value to solve; NaN makes it an invalid point (status
        # ``invalid_input``) instead of solving whatever the mask hides.
        x = np.ma.filled(np.ma.asarray(x, dtype=np.float64), np.nan)
    a = np.asarray(x)
    if a.dtype.kind not in "iuf":
        raise InputError(f"{name}: expected real numbers, got an array of dtype {a.dtype}")
    if a.dtype != np.float64 or not a.dtype.isnative:
        a = a.astype(np.float64)  # the only copy: integer/float32/byte-swapped input
    return a


#: Memory of one solved point in a ``Result`` (every quantity as float64, status, inputs).
_BYTES_PER_POINT = 485


def _max_points(max_points: object) -> int:
    """``max_points`` as a whole number >= 1, else ``ValueError`` naming it."""
    if isinstance(max_points, bool) or not isinstance(max_points, (int, np.integer)):
        raise ValueError(f"max_points must be a whole number >= 1, got {max_points!r}")
    if max_points < 1:
        raise ValueError(f"max_points must be a whole number >= 1, got {max_points}")
    # a limit beyond what the core counts in (u64) is no limit: no point count reaches it
    return min(int(max_points), 2**64 - 1)


class Motor:
    """A motor definition: preset values plus overrides and switched-on effects.

    Immutable: ``with_params`` / ``with_effects`` return new motors. Picklable (it travels
    as its TOML text), so it can be shipped to worker processes.

    >>> m = Motor("trum60a")
    >>> m["stator.modal_mass_kg"]
    0.005
    """

    __slots__ = ("_m",)

    def __init__(self, preset: str) -> None:
        if isinstance(preset, _trum.Motor):
            self._m = preset
        else:
            self._m = _trum.Motor(str(preset))

    @classmethod
    def _wrap(cls, m: "_trum.Motor") -> "Motor":
        obj = cls.__new__(cls)
        obj._m = m
        return obj

    # ------------------------------------------------------------------ construction
    @classmethod
    def preset(cls, name: str) -> "Motor":
        """The motor of a built-in preset (``trum.presets()`` lists them)."""
        return cls(name)

    @classmethod
    def from_toml_str(cls, text: str, source: str = "<string>") -> "Motor":
        """Reads the text of a TOML motor file; ``source`` names it in error messages."""
        return cls._wrap(_trum.Motor.from_toml_str(text, source))

    @classmethod
    def from_toml(cls, path: Union[str, "os.PathLike[str]"]) -> "Motor":
        """Reads a TOML motor file (``preset = "..."`` plus overrides, or every key)."""
        with open(path, "rb") as f:
            raw = f.read()
        return cls.from_toml_str(decode_utf8(raw, os.fspath(path), TrumError), os.fspath(path))

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], source: str = "dict") -> "Motor":
        """A motor from ``{"preset": ..., "stator.modal_damping_ns_per_m": 12, ...}``.

        Keys are dotted and unit-suffixed (nested dicts ``{"stator": {...}}`` work too);
        ``name`` sets the display name; ``effects`` is ``{"radial_friction": 0.5}``,
        ``{"hertz_softening": {"beta_n_per_m3": 2e19, "preload_gain_per_n": 0.005}}``, a
        string or a list of ``NAME=STRENGTH`` assignments. Without ``preset`` every key is
        required. Unknown keys raise ``ParameterError`` naming the key.
        """
        if not isinstance(d, Mapping):
            raise TypeError(f"from_dict expects a mapping, got {type(d).__name__}")
        preset: Optional[str] = None
        name: Optional[str] = None
        params: List[Tuple[str, float]] = []
        effects: List[str] = []
        for key, v in _flatten(d):
            if key == "preset":
                preset = str(v)
            elif key == "name":
                name = str(v)
            elif key == "effects":
                effects += _effect_specs(source, key, v)
            elif key.startswith("effects."):
                rest = key[len("effects.") :]
                if "." in rest:  # effects.NAME.param = value
                    e, p = rest.split(".", 1)
                    effects.append(f"{e}:{p}={_number(source, key, v)!r}")
                else:
                    effects += _effect_specs(source, "effects", {rest: v})
            else:
                params.append((key, _number(source, key, v)))
        return cls._wrap(_trum.Motor.from_parts(preset, name, params, effects, source))

    def with_params(self, params: Optional[Mapping[str, Any]] = None, **kwargs: Any) -> "Motor":
        """A copy with numeric parameters replaced: ``{"stator.modal_mass_kg": 0.006}`` or
        keyword form ``stator__modal_mass_kg=0.006``."""
        items = dict(_flatten(params or {}))
        items.update({k.replace("__", "."): v for k, v in kwargs.items()})
        src = "with_params"
        return Motor._wrap(self._m.with_params([(k, _number(src, k, v)) for k, v in items.items()], src))

    def with_effects(self, *specs: str, **strengths: float) -> "Motor":
        """A copy with effects switched on: ``"radial_friction=0.5"``,
        ``"hertz_softening:beta_n_per_m3=2e19,preload_gain_per_n=0"``, ``"none"``, or
        keyword form ``radial_friction=0.5``."""
        all_specs = [str(s) for s in specs]
        all_specs += [f"{k}={_number('with_effects', 'effects.' + k, v)!r}" for k, v in strengths.items()]
        return Motor._wrap(self._m.with_effects(all_specs, "with_effects"))

    # ------------------------------------------------------------------ inspection
    @property
    def name(self) -> str:
        """Display name."""
        return self._m.name

    @property
    def preset_name(self) -> Optional[str]:
        """The preset this motor started from (None for a complete motor file)."""
        return self._m.preset

    @property
    def drive(self) -> Optional[Tuple[float, float]]:
        """``(voltage_v, frequency_hz)`` of the motor file's ``[drive]`` table or its preset's
        (the drive its source figures were taken at); ``None`` when neither gives one.
        ``solve``, ``trum.map`` and ``trum.optimize`` use it when no drive is given."""
        return self._m.drive

    @property
    def effects(self) -> str:
        """Active effects in the core's display form (``none`` for the baseline model)."""
        return self._m.effects

    @property
    def active_effects(self) -> Dict[str, Dict[str, float]]:
        """``{effect: {param: value}}`` of the switched-on effects."""
        return {n: dict(ps) for n, ps in self._m.active_effects}

    def overrides(self) -> Dict[str, float]:
        """Parameters whose value differs from the preset's."""
        return {k: v for k, v, _ in self._m.overrides()}

    def keys(self) -> List[str]:
        """Dotted parameter keys (``stator.modal_mass_kg``), in motor-file order."""
        return [k for k, _ in self._m.params()]

    def __getitem__(self, key: str) -> float:
        try:
            return self._m.get(key)
        except ParameterError as e:
            raise ParameterKeyError(str(e), source=e.source, line=e.line, key=e.key, reason=e.reason) from None

    def __contains__(self, key: object) -> bool:
        return key in self.keys()

    def to_dict(self) -> Dict[str, Any]:
        """Flat ``{dotted_key: value}`` plus ``name``, ``preset``, ``effects``; ``Motor.from_dict``
        reads it back to an equal motor."""
        d: Dict[str, Any] = {"name": self.name}
        if self.preset_name is not None:
            d["preset"] = self.preset_name
        d.update(self._m.params())
        d["effects"] = self.active_effects
        return d

    def to_toml(self) -> str:
        """A complete TOML motor file that reads back to an identical motor."""
        return self._m.to_toml()

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Motor) and self._m == other._m

    __hash__ = None  # type: ignore[assignment]

    def __reduce__(self) -> Tuple[Any, Tuple[str]]:
        return (_from_toml, (self.to_toml(),))

    def __repr__(self) -> str:
        parts = [f"preset={self.preset_name!r}" if self.preset_name else f"name={self.name!r}"]
        parts.append(f"effects={self.effects!r}")
        ov = self.overrides()
        if ov:
            parts.append(f"overrides={ov!r}")
        return f"Motor({', '.join(parts)})"

    # ------------------------------------------------------------------ solving
    def solve(
        self,
        *,
        preload_n: ArrayLike,
        voltage_v: Optional[ArrayLike] = None,
        frequency_hz: Optional[ArrayLike] = None,
        torque_nm: ArrayLike = 0.0,
        elapsed_s: ArrayLike = 0.0,
        parallel: Optional[bool] = None,
        max_points: int = 20_000_000,
    ) -> Result:
        """Solves every operating point of the broadcast inputs (NumPy rules).

        Scalars or arrays of any real dtype; contiguous float64 arrays are read in place.
        Each point is solved from a cold start, so values equal ``trum_core::solve``
        bitwise whatever the array's size, chunking or process. Invalid points
        (e.g. a negative preload) do not raise: they get NaN and status
        ``invalid_input`` with ``Result.reason``. ``parallel=None`` uses all cores from
        4096 points on. The GIL is released while solving. A masked array's masked
        entries are invalid points (NaN in, ``invalid_input`` out).

        ``max_points`` bounds the broadcast size (each point's result takes about 485
        bytes): a larger broadcast raises ``InputError`` with its shape and estimated
        memory before anything is allocated; split it, or raise ``max_points``.

        Without ``voltage_v``/``frequency_hz`` the motor's drive is used (``Motor.drive``:
        its ``[drive]`` table or its preset's, else 200 V and 43 kHz), as the CLI does. A
        pandas Series input lends its index to ``Result.to_pandas()`` when the result is
        1-D and of its length.
        """
        limit = _max_points(max_points)
        v0, f0 = self.drive or (200.0, 43e3)
        voltage_v = v0 if voltage_v is None else voltage_v
        frequency_hz = f0 if frequency_hz is None else frequency_hz
        index = None
        for x in (preload_n, torque_nm, voltage_v, frequency_hz, elapsed_s):
            if hasattr(x, "index") and hasattr(x, "to_numpy") and getattr(x, "ndim", 0) == 1:
                index = x.index
                break
        ins = {
            "preload_n": _as_f64("preload_n", preload_n),
            "torque_nm": _as_f64("torque_nm", torque_nm),
            "voltage_v": _as_f64("voltage_v", voltage_v),
            "frequency_hz": _as_f64("frequency_hz", frequency_hz),
            "elapsed_s": _as_f64("elapsed_s", elapsed_s),
        }
        try:
            shape = np.broadcast_shapes(*(v.shape for v in ins.values()))
        except ValueError:
            shape = None  # the solver names the axes that do not broadcast
        if shape is not None:
            n = math.prod(shape)
            if n > limit:
                raise InputError(
                    f"the broadcast inputs have {n} points (shape {shape}): about "
                    f"{n * _BYTES_PER_POINT / 1e9:.1f} GB of results; more than max_points = {limit}; "
                    "solve them in pieces, or raise max_points"
                )
        data = _trum.solve_arrays(self._m, *ins.values(), parallel=parallel)
        res = Result(data, ins)
        if index is not None and len(res.shape) == 1 and res.shape[0] == len(index):
            res._index = index
        res.motor, res.effects = self.name, self.effects
        return res


def _from_toml(text: str) -> Motor:
    """Unpickling helper."""
    return Motor.from_toml_str(text, "pickle")
