"""Every ```python block of docs/PYTHON.md and README.md runs (in order, sharing one namespace)."""
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
DOC = ROOT / "docs" / "PYTHON.md"
README = ROOT / "README.md"


def blocks(path=DOC):
    text = path.read_text(encoding="utf-8")
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_readme_snippets_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code_blocks = blocks(README)
    assert code_blocks, "README.md has a Python example"
    ns = {"__name__": "__main__"}
    for i, code in enumerate(code_blocks):
        exec(compile(code, f"README.md[block {i}]", "exec"), ns)


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
