"""The sim-to-real diagnosis from Python (the document: docs/DIAGNOSIS_JSON.md)."""
from __future__ import annotations

import json
import os
import warnings
from typing import Any, Dict, Mapping, Optional, Union

from . import _trum
from ._api import _motor
from ._errors import InputError
from ._motor import Motor


def diagnose(
    motor: Union[Motor, str],
    data: Union[str, "os.PathLike[str]", bytes],
    *,
    exact_cv: bool = False,
    plausible: Optional[Mapping[str, Any]] = None,
) -> Dict[str, Any]:
    """Where the calibrated baseline misses the measurements, which unmodelled effect
    causes it, and how far the held-out gap shrinks once it is added.

    ``motor`` is the nominal motor (a ``trum.Motor`` or a preset name); ``data`` a
    measurement CSV in the layout of docs/MEASUREMENTS.md, as a path, the file's bytes,
    its text (a string with a line break), or a pandas DataFrame with those columns. Returns the JSON document of ``trum diagnose --json`` as a dict
    (``verdict``, ``confounded_with``, ``partial``, ``gap``, ``ranking``, ``notes``, ...;
    every field in docs/DIAGNOSIS_JSON.md, the method in docs/DIAGNOSIS.md). Columns the reader ignores are reported with
    ``warnings.warn``. A bad file, or data that cannot support a held-out test, raises
    ``trum.InputError`` naming the file, line and column. The GIL is released while it runs.

    A value outside its column's plausible range (docs/MEASUREMENTS.md) is such an error;
    ``plausible={"speed_rpm": (0, 2e4), "preload_n": None}`` replaces ranges when the
    values are real (``None`` for no bound at all; ``None`` at either end of a pair for
    no bound there).
    """
    specs = []
    for col, rng in (plausible or {}).items():
        if rng is None:
            specs.append(f"{col}=any")
        else:
            lo, hi = rng
            specs.append(f"{col}={'' if lo is None else repr(float(lo))}:{'' if hi is None else repr(float(hi))}")
    m = _motor(motor)
    if hasattr(data, "to_csv") and hasattr(data, "columns"):
        # a pandas DataFrame: its columns are the file's (docs/MEASUREMENTS.md)
        raw, source = data.to_csv(index=False).encode("utf-8"), "<DataFrame>"
    elif isinstance(data, (bytes, bytearray)):
        raw, source = bytes(data), "<bytes>"
    elif isinstance(data, str) and ("\n" in data or "\r" in data):
        # CSV text rather than a path (no file name has a line break)
        raw, source = data.encode("utf-8"), "<text>"
    elif isinstance(data, (str, os.PathLike)):
        source = os.fspath(data)
        if os.path.isdir(source):
            raise InputError(f"measurement file '{source}' is a directory")
        try:
            with open(source, "rb") as f:
                raw = f.read()
        except FileNotFoundError:
            raise InputError(f"measurement file '{source}' does not exist") from None
        except OSError as e:
            raise InputError(f"cannot read measurement file '{source}': {e.strerror}") from None
    else:
        raise TypeError(
            f"data: expected a measurement file's path or bytes, its text, or a pandas DataFrame, "
            f"got {type(data).__name__}"
        )
    motor_source = motor if isinstance(motor, str) else (m.preset or m.name)
    text, notes = _trum.diagnose_csv(m, raw, source, motor_source, bool(exact_cv), specs)
    for w in notes:
        warnings.warn(w, stacklevel=2)
    return json.loads(text)
