"""The book's Python example runs as printed (scene paths made absolute, run elsewhere)."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys

import pytest

from conftest import REPO


def test_the_books_python_example_runs(tmp_path):
    # The design study needs the extras (pinned in requirements-test.txt for Python 3.11+).
    study = all(importlib.util.find_spec(m) for m in ["pandas", "xarray", "matplotlib"])
    page = (REPO / "docs/book/src/python.md").read_text()
    section = page.split("# From Python", 1)[1]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    # The first block, then the design study that continues it (with its extras).
    code = blocks[0]
    if study:
        code += "\nimport matplotlib\nmatplotlib.use('Agg')\n" + blocks[1]
    code = code.replace('"scenes/', f'"{REPO}/scenes/')
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == "[-2.35, 107.5, 0.325]"
    assert (tmp_path / "out/py-notebook14/flux.exr").is_file()
    assert (tmp_path / "out/py-notebook14-opt/optimized.toml").is_file()
    assert (tmp_path / "out/sheet.bsdf").read_text().count("DataBegin") == 1
    if not study:
        pytest.skip("the design study needs pandas, xarray and matplotlib")
    # The sweep's DataFrame: a row per design, values with their errors.
    table = lines[-5:]
    assert table[0].split() == ["surfaces.lgp_back.ink_albedo", "efficiency", "efficiency_stderr", "cv_debiased"]
    assert len(table) == 5 and all(float(r.split()[3]) > 0 for r in table[1:])
