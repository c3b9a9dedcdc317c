"""The book's Python example runs as printed (scene paths made absolute, run elsewhere)."""

from __future__ import annotations

import re
import subprocess
import sys

from conftest import REPO


def test_the_books_python_example_runs(tmp_path):
    page = (REPO / "docs/book/src/python.md").read_text()
    section = page.split("# From Python", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    code = code.replace('"scenes/', f'"{REPO}/scenes/')
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == "[-2.35, 107.5, 0.325]"
    assert (tmp_path / "out/py-notebook14/flux.exr").is_file()
    assert (tmp_path / "out/py-notebook14-opt/optimized.toml").is_file()
    assert (tmp_path / "out/sheet.bsdf").read_text().count("DataBegin") == 1
