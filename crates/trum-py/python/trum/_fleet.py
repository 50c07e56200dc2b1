"""A fleet: diagnose or calibrate many measurement files in parallel on Dask, one summary
table out (the same columns as ``trum diagnose/calibrate --summary``, docs/CLI.md)."""
from __future__ import annotations

import functools
import glob
import os
import warnings
from typing import Any, Callable, Dict, List, Optional, Sequence, Union

from ._api import _motor
from ._diagnosis import (
    Plausible,
    SensorNoise,
    Tolerances,
    _plausible_args,
    _portable,
    _tolerances_args,
    calibrate,
    diagnose,
)
from ._errors import InputError
from ._motor import Motor
from ._result import _require_pandas

#: The columns of a diagnosis fleet's summary between ``rows`` and the calibrated
#: baseline parameters (docs/CLI.md, "Fleets").
DIAGNOSE_FLEET_COLUMNS = (
    "verdict",
    "complete",
    "confounded_with",
    "partial",
    "evidence",
    "shrink",
    "shrink_low",
    "shrink_high",
    "baseline_heldout_nrmse",
    "remaining_heldout_nrmse",
    "noise_nrmse",
    "readings",
)
#: The same for a calibration fleet (each fitted parameter and ``std_error.KEY`` follow).
CALIBRATE_FLEET_COLUMNS = ("readings", "chi2_per_reading", "evaluations")

Files = Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]]


def _files(files: Files) -> List[str]:
    """The measurement files: a list of paths as given, or a pattern (``runs/*.csv``,
    ``**`` recursive) expanded here, in sorted order. A pattern without a match, or no
    file at all, is an ``InputError``."""
    specs = [files] if isinstance(files, (str, os.PathLike)) else list(files)
    out: List[str] = []
    for f in specs:
        f = os.fspath(f)
        if glob.has_magic(f) and not os.path.exists(f):
            hits = sorted(p for p in glob.glob(f, recursive=True) if os.path.isfile(p))
            if not hits:
                raise InputError(f"files: no file matches '{f}'")
            out.extend(hits)
        else:
            out.append(f)
    if not out:
        raise InputError("files: no measurement file given")
    return out


def _same_set(a: str, b: str) -> bool:
    return sorted(a.split("+")) == sorted(b.split("+"))


def _row(work: Callable[[str], Dict[str, Any]], path: str) -> Dict[str, Any]:
    """One file's summary row; an exception is the row's ``error``, never a crash."""
    row: Dict[str, Any] = {
        "file": path,
        "motor_id": os.path.splitext(os.path.basename(path))[0],
        "status": "ok",
        "rows": None,
    }
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            row.update(work(path))
        except Exception as e:  # every failure of one file is that file's row
            row["status"] = "error"
            row["error"] = str(e) if isinstance(e, InputError) else f"{type(e).__name__}: {e}"
    row["warnings"] = "; ".join(str(w.message) for w in caught)
    return row


def _diagnose_cells(
    path: str, motor: Motor, plausible: Any, tolerances: Any, exact_cv: bool, sensor_noise: SensorNoise = None
) -> Dict[str, Any]:
    d = diagnose(
        motor, path, exact_cv=exact_cv, plausible=plausible, tolerances=tolerances, sensor_noise=sensor_noise
    )
    ranking = d.get("ranking", [])
    verdict = d["verdict"]
    of_verdict = next((r for r in ranking if _same_set(r["effect"], verdict)), None)
    entry = of_verdict
    if entry is None and verdict == "unexplained" and d.get("partial"):
        entry = next((r for r in ranking if r["effect"] == d["partial"]), None)
    gap = d["gap"]
    cells: Dict[str, Any] = {
        "rows": d["n_rows"],
        "verdict": verdict,
        "complete": d["complete"],
        "confounded_with": ";".join(d.get("confounded_with", [])),
        "partial": d.get("partial") or "",
        "evidence": entry["evidence"] if entry else None,
        "shrink": entry["shrink"] if entry else None,
        "shrink_low": entry["shrink_interval"][0] if entry else None,
        "shrink_high": entry["shrink_interval"][1] if entry else None,
        "baseline_heldout_nrmse": gap["baseline_heldout_nrmse"],
        "remaining_heldout_nrmse": gap["remaining_heldout_nrmse"],
        "noise_nrmse": gap["noise_nrmse"],
        "readings": d["n_readings"],
    }
    for p in d.get("baseline_params", []):
        cells[p["name"]] = p["value"]
    return cells


def _calibrate_cells(path: str, motor: Motor, plausible: Any, tolerances: Any) -> Dict[str, Any]:
    c = calibrate(motor, path, plausible=plausible, tolerances=tolerances)
    cells: Dict[str, Any] = {
        "rows": c.n_rows,
        "readings": c.n_readings,
        "chi2_per_reading": c.chi2_per_reading,
        "evaluations": c.evaluations,
    }
    for p in c.params:
        cells[p["name"]] = p["value"]
        cells[f"std_error.{p['name']}"] = p["std_error"]
    for w in c.warnings:
        warnings.warn(w, stacklevel=2)
    return cells


def _frame(rows: List[Dict[str, Any]], fixed: Sequence[str]) -> Any:
    """The summary DataFrame: ``file``, ``motor_id``, ``status``, ``rows``, the command's
    columns, the columns only some files have (in order of first appearance),
    ``warnings``, ``error``."""
    pd = _require_pandas()
    head = ["file", "motor_id", "status", "rows", *fixed]
    extra: List[str] = []
    for r in rows:
        for k in r:
            if k not in head and k not in extra and k not in ("warnings", "error"):
                extra.append(k)
    df = pd.DataFrame(rows, columns=[*head, *extra, "warnings", "error"])
    df["rows"] = df["rows"].astype("Int64")
    for col in ("readings", "evaluations"):
        if col in df:
            df[col] = df[col].astype("Int64")
    if "complete" in df:
        df["complete"] = df["complete"].astype("boolean")
    for col in ("error", "warnings", "confounded_with", "partial", "verdict"):
        if col in df:
            df[col] = df[col].fillna("")
    return df


def _scheduler(client: Any) -> Any:
    """The Dask scheduler: the given ``distributed.Client``, else the default client when
    one is running, else threads of this process (the work releases the GIL)."""
    if client is not None:
        return client
    try:
        from distributed import default_client

        return default_client()
    except (ImportError, ValueError):
        return "threads"


def _map(work: Callable[[str], Dict[str, Any]], files: List[str], client: Any, npartitions: Optional[int]) -> List[Dict[str, Any]]:
    func = functools.partial(_row, work)
    try:
        import dask.bag as db
    except ImportError:
        if client is not None:
            raise
        # without Dask: one file after another in this process
        return [func(f) for f in files]
    n = len(files) if npartitions is None else max(1, min(int(npartitions), len(files)))
    bag = db.from_sequence(files, npartitions=n)
    return list(bag.map(func).compute(scheduler=_scheduler(client)))


def diagnose_fleet(
    motor: Union[Motor, str],
    files: Files,
    *,
    client: Any = None,
    npartitions: Optional[int] = None,
    exact_cv: bool = False,
    plausible: Plausible = None,
    tolerances: Tolerances = None,
    sensor_noise: SensorNoise = None,
) -> Any:
    """Diagnoses every measurement file in ``files`` on its own, in parallel on Dask, and
    returns one summary row per file as a pandas DataFrame, the table of ``trum diagnose
    --summary`` (docs/CLI.md, "Fleets"): ``file``, ``motor_id`` (the file name without
    directory and extension), ``status`` (``ok`` or ``error``), ``rows``, ``verdict``,
    ``complete``, ``confounded_with``, ``partial``, ``evidence``, ``shrink``,
    ``shrink_low``, ``shrink_high``, ``baseline_heldout_nrmse``,
    ``remaining_heldout_nrmse``, ``noise_nrmse``, ``readings``, the calibrated baseline
    parameters by motor-file key, ``warnings`` and ``error``.

    ``files`` is a list of paths or a pattern (``"runs/*.csv"``), expanded here; the
    workers open the files, so on a cluster they must see them at the same paths (shared
    storage). Each row equals :func:`trum.diagnose` on that file. A file that fails
    (unreadable, a bad cell, too little data) is a row with ``status == "error"`` and the
    message in ``error``; the others go on.

    ``client``: a ``distributed.Client`` (default: the running default client, else
    threads of this process). ``npartitions``: Dask tasks (default one per file).
    ``exact_cv``, ``plausible``, ``tolerances`` and ``sensor_noise`` as for :func:`trum.diagnose`; a
    ``plausible`` or ``tolerances`` TOML file is read once here and its text shipped to the
    workers. Rows come in the order of the
    file list."""
    m = Motor._wrap(_motor(motor))
    paths = _files(files)
    work = functools.partial(
        _diagnose_cells,
        motor=m,
        plausible=_portable(plausible, _plausible_args),
        tolerances=_portable(tolerances, _tolerances_args),
        exact_cv=bool(exact_cv),
        sensor_noise=dict(sensor_noise) if sensor_noise is not None else None,
    )
    return _frame(_map(work, paths, client, npartitions), DIAGNOSE_FLEET_COLUMNS)


def calibrate_fleet(
    motor: Union[Motor, str],
    files: Files,
    *,
    client: Any = None,
    npartitions: Optional[int] = None,
    plausible: Plausible = None,
    tolerances: Tolerances = None,
) -> Any:
    """Calibrates ``motor`` to every measurement file in ``files`` on its own, in parallel
    on Dask, as :func:`diagnose_fleet` does for the diagnosis; the table is that of
    ``trum calibrate --summary``: ``file``, ``motor_id``, ``status``, ``rows``,
    ``readings``, ``chi2_per_reading``, ``evaluations``, each fitted parameter by its
    motor-file key with its standard error as ``std_error.KEY``, ``warnings`` (the
    reader's and the fit's) and ``error``. Each row equals :func:`trum.calibrate` on that
    file (``plausible`` and ``tolerances`` as there)."""
    m = Motor._wrap(_motor(motor))
    paths = _files(files)
    work = functools.partial(
        _calibrate_cells,
        motor=m,
        plausible=_portable(plausible, _plausible_args),
        tolerances=_portable(tolerances, _tolerances_args),
    )
    return _frame(_map(work, paths, client, npartitions), CALIBRATE_FLEET_COLUMNS)
