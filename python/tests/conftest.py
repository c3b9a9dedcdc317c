"""Shared fixtures: the repository's bundled scenes and the command-line binary."""

from __future__ import annotations

import os
import pathlib
import subprocess

import pytest

import blutrace as bt

REPO = pathlib.Path(__file__).resolve().parents[2]
SCENES = REPO / "scenes"


@pytest.fixture(scope="session")
def box() -> bt.Scene:
    """bench-box: one LED, a dotted guide, 120 x 80 bins; 1e5 photons in ~0.1 s."""
    return bt.Scene.load(SCENES / "bench-box")


@pytest.fixture(scope="session")
def phone() -> bt.Scene:
    """phone-led: six LEDs (for `*` key paths) and a dots surface."""
    return bt.Scene.load(SCENES / "phone-led")


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    """The `blutrace` binary built from this checkout (BLUTRACE_BIN, or target/release)."""
    path = pathlib.Path(os.environ.get("BLUTRACE_BIN", REPO / "target/release/blutrace"))
    if not path.is_file():
        pytest.skip(f"{path} not built: run `cargo build --release` or set BLUTRACE_BIN")
    return path


def run_cli(cli: pathlib.Path, *args: str) -> subprocess.CompletedProcess:
    """Run the binary, failing the test with its stderr when it fails."""
    done = subprocess.run([str(cli), *args], capture_output=True, text=True)
    assert done.returncode == 0, f"blutrace {args} failed:\n{done.stderr}"
    return done
