"""Scene.characterise: a part of a scene as an IS BSDF table, from Python."""

from __future__ import annotations

import numpy as np
import pytest

import blutrace as bt

# A 100 x 100 mm Lambertian sheet (albedo 0.6) facing +z, an LED above it, a detector.
SHEET = """version = 1
[[geometry]]
file = "sheet.obj"
[surfaces.sheet]
model = "lambert"
albedo = 0.6
[[sources]]
type = "led"
center = [0.0, 0.0, 5.0]
normal = [0.0, 0.0, -1.0]
u = [1.0, 0.0, 0.0]
width_mm = 2.0
height_mm = 2.0
power_w = 1.0
[detector]
origin = [-50.0, -50.0, 6.0]
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = [100.0, 100.0]
bins = [2, 2]
"""
OBJ = "v -50 -50 0\nv 50 -50 0\nv 50 50 0\nv -50 50 0\nusemtl sheet\nf 1 2 3\nf 1 3 4\n"
N = 50_000


@pytest.fixture()
def sheet(tmp_path) -> bt.Scene:
    (tmp_path / "sheet.obj").write_text(OBJ)
    return bt.Scene.from_toml(SHEET, tmp_path / "scene.toml")


def test_a_lambert_sheet_reflects_its_albedo_at_every_incidence(sheet):
    c = sheet.characterise("sheet", photons=N, aoi=[0, 45, 80], seed=2)
    assert c.aoi == [0, 45, 80] and c.rotations == [0]
    assert "sheet" in c.part
    f = c.fates
    assert f["reflected"].shape == (1, 3) and f["reflected"].dtype == np.float64
    # Binomial: within 4 standard errors of the albedo; nothing goes through.
    assert np.all(np.abs(f["reflected"] - 0.6) < 4 * np.sqrt(0.6 * 0.4 / N))
    assert np.all(f["transmitted"] == 0) and np.all(f["lost"] == 0)
    assert np.allclose(f["reflected"] + f["absorbed"], 1.0)


def test_the_written_table_is_a_bsdf_table_face(sheet, tmp_path):
    c = sheet.characterise("sheet", photons=N, aoi=[0, 40, 80])
    text = c.to_bsdf()
    assert "ScatterType BRDF" in text.replace("  ", " ") and "BTDF" not in text
    c.write(tmp_path / "sheet.bsdf")
    assert (tmp_path / "sheet.bsdf").read_text() == text
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], "a temporary left"
    # The table on the sheet instead of lambert: the same detected power.
    table = sheet.copy()
    table.set("surfaces.sheet", {"model": "bsdf_table", "file": "sheet.bsdf"})
    a = sheet.trace(photons=200_000, seed=4).efficiency[0]
    b = table.trace(photons=200_000, seed=4).efficiency[0]
    assert abs(a - b) < 4 * np.sqrt(2 * a * (1 - a) / 200_000), (a, b)


def test_nothing_is_written_over_a_file_the_scene_reads(sheet, tmp_path):
    c = sheet.characterise("sheet", photons=1000, aoi=[0])
    mesh = tmp_path / "sheet.obj"
    with pytest.raises(bt.BlutraceError, match="an input of this run"):
        c.write(mesh)
    run = sheet.trace(photons=1000, seed=1)
    with pytest.raises(bt.BlutraceError, match="scene.toml, an input of this run"):
        run.write(tmp_path)
    assert mesh.read_text() == OBJ


@pytest.mark.parametrize(
    "kwargs, says",
    [
        ({"tag": "nothing"}, "nothing"),
        ({"tag": "sheet", "aoi": [0, 95]}, "95"),
        ({"tag": "sheet", "photons": 0}, "photons"),
        ({"tag": "sheet", "u_axis": (1.0, 0.0)}, "u_axis"),
    ],
)
def test_a_bad_argument_is_a_value_error_naming_it(sheet, kwargs, says):
    with pytest.raises(ValueError) as e:
        sheet.characterise(**kwargs)
    assert says in str(e.value)  # the message itself, not a note pytest's match= also reads


@pytest.mark.parametrize(
    "kwargs, says",
    [
        ({"radial_step": "fine"}, "radial_step"),
        ({"azimuth_step": None}, "azimuth_step"),
        ({"aoi": [0, "x"]}, "aoi"),
        ({"rotations": 90.0}, "rotations"),
        ({"u_axis": 5}, "u_axis"),
    ],
)
def test_an_argument_of_a_wrong_type_is_a_type_error_naming_it(sheet, kwargs, says):
    with pytest.raises(TypeError) as e:
        sheet.characterise("sheet", **kwargs)
    assert says in str(e.value)  # the message itself, not a note pytest's match= also reads


def test_progress_hears_the_photons_of_every_incidence(sheet):
    seen = []
    sheet.characterise(
        "sheet", photons=10_000, aoi=[0, 30, 60, 80], progress=lambda d, t: seen.append((d, t))
    )
    assert seen and seen[-1] == (40_000, 40_000)
    assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:]))
    assert all(d % 10_000 == 0 for d, _ in seen), "whole incidences"


def test_an_exception_of_the_progress_callable_stops_it(sheet):
    def fail(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        sheet.characterise("sheet", photons=2_000_000, aoi=list(range(0, 90, 5)), progress=fail)
