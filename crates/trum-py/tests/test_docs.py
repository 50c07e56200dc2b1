"""Every ```python block of docs/PYTHON.md runs (in order, sharing one namespace)."""
import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[3] / "docs" / "PYTHON.md"


def blocks():
    text = DOC.read_text(encoding="utf-8")
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_doc_has_examples():
    assert len(blocks()) >= 3


def test_doc_snippets_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ns = {"__name__": "__main__"}
    for i, code in enumerate(blocks()):
        if "distributed" in code:
            pytest.importorskip("distributed")
        if "pandas" in code or "to_pandas" in code:
            pytest.importorskip("pandas")
        exec(compile(code, f"{DOC.name}[block {i}]", "exec"), ns)
