"""Sweep axes: a number, or explicit values (a list, a NumPy array, a pandas Series); ranges
are spelled ``trum.linspace(start, stop, n)`` (or ``np.linspace``)."""
from __future__ import annotations

import numbers
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

from ._errors import InputError

#: A value, or explicit values.
Values = Union[float, Sequence[float], np.ndarray]


def linspace(start: float, stop: float, n: int) -> np.ndarray:
    """``n`` evenly spaced values from ``start`` to ``stop`` (both included), computed as
    trum's grids compute them (``start + (stop - start) * i / (n - 1)``), so that
    ``trum.map(m, preload_n=trum.linspace(150, 400, 6), ...)`` is the CLI's
    ``--preload-n 150:400:6`` value for value. ``np.linspace`` gives the same points to
    within a rounding step and is accepted everywhere too."""
    if isinstance(n, bool) or not (isinstance(n, numbers.Integral) or (isinstance(n, float) and n.is_integer())):
        raise InputError(f"linspace: the point count {n!r} must be a whole number >= 1")
    n = int(n)
    if n < 1:
        raise InputError(f"linspace: the point count {n} must be >= 1")
    a, b = float(start), float(stop)
    if n == 1:
        return np.array([a])
    i = np.arange(n, dtype=np.float64)
    return a + (b - a) * i / float(n - 1)


def _range_hint(name: str, spec: Tuple[Any, ...]) -> str:
    if len(spec) == 3:
        a, b, n = spec
        return (f"for {n} points from {a} to {b} write {name}=trum.linspace({a}, {b}, {n}); "
                f"for these three values write {name}=[{a}, {b}, {n}]")
    return f"give the values as a list, e.g. {name}={list(spec)!r}, or a range as {name}=trum.linspace(start, stop, n)"


def values(name: str, spec: Any) -> np.ndarray:
    """The values of one axis as a 1-D float64 array: a number gives one value; a list, a
    NumPy array or a pandas Series gives its values, in order. A tuple is refused:
    ``(150, 400, 6)`` reads as a range to some readers and as three values to others, and
    either guess computes points the other did not mean."""
    if isinstance(spec, tuple):
        raise InputError(f"{name}: a tuple is not accepted for an axis ({spec!r}); {_range_hint(name, spec)}")
    if isinstance(spec, (bool, np.bool_)):
        raise InputError(f"{name}: expected numbers, got {spec!r}")
    if isinstance(spec, numbers.Real):
        return np.array([float(spec)])
    if isinstance(spec, (str, bytes)) or spec is None:
        raise InputError(f"{name}: expected a number or a list/array of numbers, got {spec!r}")
    if isinstance(spec, np.ma.MaskedArray) and np.ma.is_masked(spec):
        # a masked entry has no value; a grid point made of it would be computed from the
        # data underneath the mask
        at = np.flatnonzero(np.ma.getmaskarray(spec)).tolist()
        raise InputError(f"{name}: masked entries (at {at[:10]}{' ...' if len(at) > 10 else ''}) have no value to "
                         "map; drop them (spec.compressed()) or fill them")
    try:
        arr = np.asarray(spec)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected numbers, got {spec!r}") from None
    if arr.dtype.kind not in "iuf":
        raise InputError(f"{name}: expected numbers, got an array of dtype {arr.dtype}")
    arr = arr.astype(np.float64).reshape(-1) if arr.ndim == 0 else arr.astype(np.float64)
    if arr.ndim != 1 or arr.size == 0:
        raise InputError(f"{name}: expected a number or a non-empty 1-D list/array, got shape {arr.shape}")
    return arr


def as_range(v: np.ndarray) -> Optional[Tuple[float, float, int]]:
    """``(start, stop, n)`` when ``v`` is evenly spaced (to 1e-12 of its span, so that
    ``np.linspace`` output qualifies), else ``None``."""
    n = v.size
    if n == 1:
        return (float(v[0]), float(v[0]), 1)
    a, b = float(v[0]), float(v[-1])
    r = linspace(a, b, n)
    scale = max(abs(a), abs(b), abs(b - a))
    if not np.all(np.isfinite(v)) or a == b:
        return None
    return (a, b, n) if np.all(np.abs(v - r) <= 1e-12 * scale) else None
