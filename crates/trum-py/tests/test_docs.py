"""Every ```python block of docs/PYTHON.md and README.md runs as written: in order, sharing
one namespace, as a reader pastes them into one interpreter; a block that guards its work with
``if __name__ == "__main__":`` (the Dask example, whose worker processes import the script)
runs as a script of its own in a fresh interpreter."""
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
DOC = ROOT / "docs" / "PYTHON.md"
README = ROOT / "README.md"
# optional dependency -> how a block shows that it needs it
OPTIONAL = {
    "pandas": ("pandas", "to_pandas"),
    "xarray": ("to_xarray",),
    "matplotlib": ("matplotlib", ".plot("),
    "distributed": ("dask.distributed",),
}


def blocks(path=DOC):
    text = path.read_text(encoding="utf-8")
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def _skip_if_missing(code):
    for module, marks in OPTIONAL.items():
        if any(m in code for m in marks):
            pytest.importorskip(module, reason=f"the example needs the optional dependency {module}")


def _run(path, tmp_path):
    ns = {"__name__": "__main__"}
    scripts = 0
    for i, code in enumerate(blocks(path)):
        _skip_if_missing(code)
        name = f"{path.name}[block {i}]"
        if 'if __name__ == "__main__":' in code:
            script = tmp_path / f"block{i}.py"
            script.write_text(code, encoding="utf-8")
            p = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=600)
            assert p.returncode == 0, f"{name} failed as a script:\n{p.stderr[-3000:]}"
            scripts += 1
        else:
            exec(compile(code, name, "exec"), ns)
    return scripts


def test_readme_snippets_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert blocks(README), "README.md has a Python example"
    _run(README, tmp_path)


def test_doc_has_examples():
    assert len(blocks()) >= 3
    # the Dask example starts its cluster under the main guard, or it fails as a script
    dask = [b for b in blocks() if "LocalCluster" in b]
    assert dask and all('if __name__ == "__main__":' in b for b in dask)


def test_doc_snippets_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert _run(DOC, tmp_path) >= 1
    # the plot examples wrote their pictures
    pngs = sorted(p.name for p in tmp_path.glob("*.png"))
    assert {"speed_torque.png", "efficiency_map.png", "resonance.png"} <= set(pngs)
