"""The examples run as the README says (with few photons), from a scratch folder."""

from __future__ import annotations

import pathlib
import subprocess
import sys

import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def run_example(name: str, *args: str, cwd: pathlib.Path) -> str:
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / name), *args], capture_output=True, text=True, cwd=cwd
    )
    assert done.returncode == 0, f"{name} failed:\n{done.stdout}\n{done.stderr}"
    return done.stdout


def test_the_process_pool_shards_merge_to_the_single_run(tmp_path):
    out = run_example(
        "shards_process_pool.py", "--photons", "8e4", "--shards", "3", "--out",
        str(tmp_path / "merged"), cwd=tmp_path,
    )
    assert "merged == single run, bit for bit: True" in out
    assert (tmp_path / "merged" / "flux.exr").is_file()


def test_the_lamp_height_sweep_prints_a_row_per_height(tmp_path):
    out = run_example(
        "lamp_height_sweep.py", "--photons", "2e4", "--heights", "5,8,11", "--out",
        str(tmp_path / "sweep"), cwd=tmp_path,
    )
    rows = [line for line in out.splitlines() if line[:1] == " " and line.strip()[0].isdigit()]
    assert len(rows) == 3, out
    csv = (tmp_path / "sweep" / "sweep.csv").read_text().splitlines()
    assert csv[0].startswith("height_mm") and len(csv) == 4


def test_the_ink_albedo_comparison_ranks_the_albedos(tmp_path):
    out = run_example("ink_albedo.py", "--photons", "5e4", "--albedos", "0.5,0.95", cwd=tmp_path)
    effs = [float(line.split()[1]) for line in out.splitlines()[2:]]
    assert len(effs) == 2 and effs[1] > effs[0], out  # whiter ink wastes less light


def test_the_design_study_sweeps_to_a_dataframe_and_plots_in_mm(tmp_path):
    pytest.importorskip("pandas")
    pytest.importorskip("matplotlib")
    out = run_example(
        "design_study.py", "--photons", "2e4", "--albedos", "0.5,0.9", "--out",
        str(tmp_path / "study"), cwd=tmp_path,
    )
    assert "most uniform: surfaces.lgp_back.ink_albedo = " in out
    csv = (tmp_path / "study" / "study.csv").read_text().splitlines()
    assert csv[0].startswith("surfaces.lgp_back.ink_albedo,") and len(csv) == 3
    assert "efficiency_stderr" in csv[0]
    png = (tmp_path / "study" / "flux_mm.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
