"""A spectral scene's colour block reaches Python, with errors; a monochrome one has none."""

from __future__ import annotations

import pytest

import blutrace as bt

from conftest import SCENES


def test_a_white_led_scene_reports_its_colour_with_errors():
    run = bt.Scene.load(SCENES / "notebook14-led").trace(photons=100_000, seed=3)
    color = run.summary["color"]
    for key in ("x", "y", "u_prime", "v_prime", "cct_k", "delta_uv_13pt", "delta_uv_max"):
        assert color[key]["stderr"] > 0.0, key
    # CIE LED-B5 emits at x 0.3118, y 0.3237; the guide moves it by far less than 0.01.
    assert color["x"]["value"] == pytest.approx(0.3118, abs=0.01)
    assert color["y"]["value"] == pytest.approx(0.3237, abs=0.01)
    assert 5500.0 < color["cct_k"]["value"] < 8000.0
    assert run.summary["luminance"]["efficacy_lm_per_w"] == pytest.approx(305.29, rel=1e-3)


def test_a_monochrome_run_has_no_colour(box):
    assert "color" not in box.trace(photons=10_000, seed=1).summary


def test_the_colour_objective_reaches_the_search():
    scene = bt.Scene.load(SCENES / "notebook14-led")
    opt = scene.optimize(
        objective="cv=1,delta-uv-13pt=10", photons=40_000, max_iter=1, verify_photons=0,
        threads=2,
    )
    # Every iteration reports the best design's debiased colour spread beside its cv.
    for h in opt.history:
        assert h["delta_uv_13pt_debiased"] >= 0.0
        assert h["objective"] == pytest.approx(h["cv"] + 10.0 * h["delta_uv_13pt_debiased"])
    with pytest.raises(ValueError, match="nelder-mead"):
        scene.optimize(method="feedback", objective="delta-uv-13pt", verify_photons=0)


def test_a_monochrome_scene_refuses_the_colour_objective(box):
    with pytest.raises(ValueError, match="needs a spectral scene"):
        box.optimize(objective="delta-uv-13pt", verify_photons=0)
