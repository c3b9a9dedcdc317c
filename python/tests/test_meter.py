"""The luminance meter's estimator from Python (issue 47): the estimator argument, one
luminance map per view of the detector, and the same maps back from an output folder."""

from __future__ import annotations

import numpy as np
import pytest

import blutrace as bt

from conftest import SCENES


@pytest.fixture(scope="module")
def scene() -> bt.Scene:
    """notebook14 on a 10 x 8 grid, seen along the normal and from 40 degrees."""
    text = bt.Scene.load(SCENES / "notebook14").to_toml()
    text = text.replace("[detector]\n", "[detector]\nviews = [[0.0, 0.0], [40.0, 0.0]]\n")
    s = bt.Scene.from_toml(text, SCENES / "notebook14" / "scene.toml")
    s.set("detector.bins", [10, 8])
    return s


def test_every_view_has_its_map_and_the_first_is_the_luminance(scene):
    run = scene.trace(photons=30_000, seed=3)
    maps = run.luminance_views
    assert maps.shape == (2, 8, 10)
    assert run.views_deg == [[0.0, 0.0], [40.0, 0.0]]
    np.testing.assert_array_equal(maps[0], run.luminance)
    assert run.luminance_views_stderr.shape == (2, 8, 10)
    # The meter's peel-off lights every bin of both views at these few photons.
    assert (maps > 0).all()
    summary = run.summary
    assert summary["luminance_estimator"] == "meter"
    assert [v["view_deg"] for v in summary["luminance_views"]] == [[0.0, 0.0], [40.0, 0.0]]


def test_the_cone_count_is_the_other_estimator_and_agrees(scene):
    meter = scene.trace(photons=30_000, seed=3)
    cone = scene.trace(photons=30_000, seed=3, luminance_estimator="cone")
    assert cone.summary["luminance_estimator"] == "cone"
    # The photons' paths are the same: the flux is the same bits.
    np.testing.assert_array_equal(meter.flux, cone.flux)
    m = meter.summary["luminance_map"]["mean_cd_m2"]
    c = cone.summary["luminance_map"]["mean_cd_m2"]
    assert abs(m["value"] - c["value"]) < 4 * np.hypot(m["stderr"], c["stderr"])
    assert m["stderr"] < c["stderr"] / 3
    with pytest.raises(ValueError, match="luminance_estimator"):
        scene.trace(photons=1000, luminance_estimator="peel")


def test_views_come_back_from_the_output_folder(scene, tmp_path):
    run = scene.trace(photons=20_000, seed=4)
    run.write(tmp_path / "out")
    back = bt.Run.load(tmp_path / "out")
    assert back.views_deg == [[0.0, 0.0], [40.0, 0.0]]
    np.testing.assert_allclose(back.luminance_views, run.luminance_views, rtol=1e-6)
