"""Optimization from Python: dot density (feedback) and scene numbers (vary)."""

from __future__ import annotations

import pytest

import blutrace as bt


def test_feedback_tunes_the_density_and_writes_the_command_lines_files(phone, tmp_path):
    heard = []
    opt = phone.optimize(
        method="feedback", photons=60_000, max_iter=2, verify_photons=0, threads=2,
        progress=heard.append,
    )
    assert isinstance(opt.scene, bt.Scene) and opt.scene.name == "phone-led-optimized"
    assert "density_table" in opt.scene.source["surfaces"]["lgp_back"]
    assert len(opt.history) == 3 and len(heard) == 3  # the first trace and 2 rounds
    assert heard[0]["iteration"] == opt.history[0]["iteration"] == 0
    s = opt.summary
    assert s["method"] == "feedback" and s["tag"] == "lgp_back"
    assert opt.interrupted is False
    files = {p.split("/")[-1] for p in opt.write(tmp_path / "opt")}
    assert {"optimized.toml", "history.csv", "optimize.json", "initial", "final"} <= files
    again = bt.Scene.load(tmp_path / "opt" / "optimized.toml")
    assert again.content_hash == opt.scene.content_hash


def test_a_grid_over_a_key_path_traces_each_value(phone, capsys):
    key = "sources.*.center.2"
    opt = phone.optimize(
        method="grid", vary={key: (0.2, 0.35)}, grid_points=3, photons=20_000,
        verify_photons=0, objective="efficiency", progress=True,
    )
    assert len(opt.history) == 3
    lines = [l for l in capsys.readouterr().err.splitlines() if l.startswith("eval")]
    assert len(lines) == 3 and key in lines[0]
    assert sorted(round(h["values"][0], 6) for h in opt.history) == [0.2, 0.275, 0.35]
    assert opt.scene.get(key) in (0.2, 0.275, 0.35)
    assert opt.summary["variables"][0]["name"] == key


@pytest.mark.parametrize(
    "kwargs, error, says",
    [
        ({"method": "annealing"}, ValueError, "method"),
        ({"no_such_option": 1}, TypeError, "no_such_option"),
        ({"vary": {"sources.0.center.2": (5, 1)}}, ValueError, "empty or inverted"),
        ({"vary": {"sources.0.center.2": 3}}, ValueError, "pair"),
        ({"photons": 0}, ValueError, "photons"),
        ({"tag": "nope"}, ValueError, "tag: no tag 'nope'"),
        ({"tag": "led_housing"}, ValueError, "option `tag`: surface 'led_housing' is not"),
        ({"tag": 5}, TypeError, "tag"),
        ({"cells": (4,)}, ValueError, "cells"),
        ({"estimator": 1}, TypeError, "estimator"),
        ({"objective": 2}, TypeError, "objective"),
        ({"vary": {3: (0.0, 1.0)}}, TypeError, "vary"),
    ],
)
def test_bad_optimize_arguments_are_errors_naming_them(phone, kwargs, error, says):
    with pytest.raises(error) as e:
        phone.optimize(**{"verify_photons": 0, **kwargs})
    assert says in str(e.value)  # the message itself, not a note pytest's match= also reads


def test_an_unknown_tag_is_the_same_value_error_everywhere(phone):
    with pytest.raises(ValueError) as by_optimize:
        phone.optimize(tag="nope", verify_photons=0)
    with pytest.raises(ValueError) as by_characterise:
        phone.characterise("nope")
    assert type(by_optimize.value) is type(by_characterise.value) is ValueError
    assert str(by_optimize.value) == str(by_characterise.value)
    assert str(by_optimize.value).startswith("tag: no tag 'nope' in ")
