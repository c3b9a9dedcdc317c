"""The book's Python API reference (docs/book/src/python-api.md) is the one
tools/python-api.py generates from the package's docstrings today."""

from __future__ import annotations

import subprocess
import sys

from conftest import REPO


def test_the_api_page_is_up_to_date():
    done = subprocess.run(
        [sys.executable, str(REPO / "tools/python-api.py"), "--check"], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr


def test_the_api_page_names_every_public_name():
    import blutrace as bt

    page = (REPO / "docs/book/src/python-api.md").read_text()
    for name in bt.__all__:
        if name != "__version__":
            assert f"`{name}`" in page, name
