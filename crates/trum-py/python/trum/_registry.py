"""Registries of the core: presets, effects, output quantities, motor parameter keys."""
from __future__ import annotations

from typing import Any, List, NamedTuple, Tuple

from . import _trum


class PresetInfo(NamedTuple):
    """A built-in motor."""

    name: str
    summary: str
    sources: str


class EffectParam(NamedTuple):
    """One parameter of an effect (name carries its unit).

    ``shape`` marks a shape parameter, not a strength: ``NAME=STRENGTH`` leaves it at
    ``typical`` (the effect's plainest form). The diagnosis fits ``preload_stiffening``'s
    ``modal_fraction`` over ``[min, max]``; a ``held`` one (every other effect's family:
    ``knee_current_a``, ``stick_sharpness``, the preload exponents, ...) it scans at a few
    levels before its local fits, which keep it where the scan put it.
    """

    name: str
    doc: str
    typical: float
    min: float
    max: float
    shape: bool = False
    held: bool = False


class EffectInfo(NamedTuple):
    """A named, switchable unmodelled effect; ``params[0]`` is the primary strength."""

    name: str
    summary: str
    source: str
    params: Tuple[EffectParam, ...]


class QuantityInfo(NamedTuple):
    """An output quantity: column name (with unit suffix), unit, meaning."""

    name: str
    unit: str
    doc: str


class ParameterInfo(NamedTuple):
    """A motor parameter: dotted key (with unit suffix) and meaning."""

    key: str
    doc: str


def presets() -> List[PresetInfo]:
    """The built-in motors (``Motor(info.name)`` builds one)."""
    return [PresetInfo(*p) for p in _trum.presets_list()]


def preset_toml(name: str) -> str:
    """A preset as a commented TOML motor file, with each value's provenance."""
    return _trum.preset_toml(name)


def effects() -> List[EffectInfo]:
    """The registry of switchable effects (``Motor.with_effects``)."""
    return [EffectInfo(n, s, src, tuple(EffectParam(*p) for p in ps)) for n, s, src, ps in _trum.effects_list()]


def quantities() -> List[QuantityInfo]:
    """Every output quantity, in the column order of ``Result.to_dict`` and ``map``."""
    return [QuantityInfo(*q) for q in _trum.quantities_list()]


def parameters() -> List[ParameterInfo]:
    """Every motor parameter key, in motor-file order."""
    return [ParameterInfo(*k) for k in _trum.parameter_keys()]


STATUS_NAMES: Tuple[str, ...] = tuple(_trum.STATUS_NAMES)
#: The ``[limits]`` keys of a motor file, in the bit order of ``warning_code``.
LIMIT_KEYS: Tuple[str, ...] = tuple(_trum.LIMIT_KEYS)


def warning_words(codes: Any) -> Any:
    """``warning_code`` bits as the ``;``-joined limit keys ("" for none), same shape (object array)."""
    import numpy as np

    codes = np.asarray(codes)
    table = np.array(
        [";".join(k for i, k in enumerate(LIMIT_KEYS) if c & (1 << i)) for c in range(1 << len(LIMIT_KEYS))],
        dtype=object,
    )
    out = np.empty(codes.shape, dtype=object)
    out[...] = table[codes & ((1 << len(LIMIT_KEYS)) - 1)]
    return out
QUANTITY_NAMES: Tuple[str, ...] = tuple(q[0] for q in _trum.quantities_list())
