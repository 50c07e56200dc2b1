"""The bad-input corpus from Python: every motor file in tests/data/bad/motor/ makes
``trum.Motor.from_toml(path)`` raise ``trum.ParameterError`` (a ``TrumError``) with the
message of its sibling ``.expected`` file, word for word as the CLI prints it.

Files named ``sweep_*`` break only the ``[sweep]`` table, which ``trum map`` reads; the
Python module reads motors only: ``Motor::from_toml_str`` checks that table's shape but
not its values, so those files either load or fail with the same message.

The measurement corpus (tests/data/bad/measurements/) is not checked here: the Python
module has no CSV reader (``trum`` exposes no ``parse_measurements``); the test below
says so explicitly and starts checking the day one appears.
"""
from pathlib import Path

import pytest

import trum

ROOT = Path(__file__).resolve().parents[3]
MOTOR_DIR = ROOT / "tests" / "data" / "bad" / "motor"
FILES = sorted(MOTOR_DIR.glob("*.toml"))
# Files whose message is known to be wrong in the core (checked by
# tests/reliability_known_bugs.rs until fixed); skipped here like in the Rust tests.
KNOWN_BUGS = {
    line.split("#")[0].strip()
    for line in (MOTOR_DIR / "known_bugs.txt").read_text(encoding="utf-8").splitlines()
    if line.split("#")[0].strip()
}


def _is_utf8(path: Path) -> bool:
    try:
        path.read_bytes().decode("utf-8")
        return True
    except UnicodeDecodeError:
        return False


def _expected(path: Path) -> str:
    return path.with_suffix(".expected").read_text(encoding="utf-8").rstrip("\n").replace("{source}", str(path))


UTF8 = [p for p in FILES if _is_utf8(p) and not p.name.startswith("sweep_") and p.name not in KNOWN_BUGS]
SWEEP = [p for p in FILES if p.name.startswith("sweep_")]
NOT_UTF8 = [p for p in FILES if not _is_utf8(p)]


def test_corpus_is_there():
    assert len(FILES) >= 20
    assert all(p.with_suffix(".expected").exists() for p in FILES)
    assert NOT_UTF8, "the corpus should hold at least one file that is not UTF-8"


@pytest.mark.parametrize("path", UTF8, ids=lambda p: p.name)
def test_bad_motor_file_raises_parameter_error_with_the_cli_message(path):
    with pytest.raises(trum.ParameterError) as info:
        trum.Motor.from_toml(path)
    assert isinstance(info.value, trum.TrumError)
    assert str(info.value) == _expected(path)
    # the same through the text API, with the source named by the caller
    with pytest.raises(trum.ParameterError) as info2:
        trum.Motor.from_toml_str(path.read_text(encoding="utf-8"), "mine.toml")
    assert str(info2.value) == _expected(path).replace(str(path), "mine.toml")
    assert info2.value.source == "mine.toml"


@pytest.mark.parametrize("path", [p for p in SWEEP if p.name not in KNOWN_BUGS], ids=lambda p: p.name)
def test_sweep_table_values_are_not_checked_by_the_python_reader(path):
    # Motor::from_toml_str checks the [sweep] table's shape (unknown axis, wrong type) but
    # not its values (negative preload, fractional count): those only `trum map` reads.
    try:
        m = trum.Motor.from_toml(path)
    except trum.ParameterError as e:
        assert str(e) == _expected(path)
    else:
        assert m.preset_name == "trum60a"


@pytest.mark.parametrize("path", NOT_UTF8, ids=lambda p: p.name)
def test_non_utf8_motor_file_raises_trum_error(path):
    # A motor file that is not UTF-8 raises a TrumError that names the file, like the CLI
    # ("cannot read motor file ...: ... UTF-8"), not Python's UnicodeDecodeError.
    with pytest.raises(trum.TrumError) as info:
        trum.Motor.from_toml(path)
    assert str(path) in str(info.value)
    assert "UTF-8" in str(info.value)


def test_measurement_corpus_from_python():
    """Every bad measurement file raises trum.InputError through trum.diagnose with the
    reader's exact message (the same `.expected` text the CLI test checks)."""
    bad = sorted((ROOT / "tests" / "data" / "bad" / "measurements").glob("*.csv"))
    assert len(bad) >= 20
    problems = []
    for path in bad:
        expected = path.with_suffix(".expected").read_text(encoding="utf-8").rstrip("\n")
        expected = expected.replace("{source}", str(path))
        try:
            trum.diagnose("trum60a", path)
            problems.append(f"{path.name}: no error")
        except trum.InputError as e:
            if expected not in str(e):
                problems.append(f"{path.name}:\n   got      {e}\n   expected {expected}")
    assert not problems, "\n".join(problems)
