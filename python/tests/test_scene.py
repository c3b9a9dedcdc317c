"""Scenes: loading, key paths, copies, check, errors."""

from __future__ import annotations

import copy
import json
import pickle

import numpy as np
import pytest

import blutrace as bt

from conftest import SCENES, run_cli


def test_a_folder_and_its_scene_file_load_the_same_scene(box):
    by_file = bt.Scene.load(str(SCENES / "bench-box" / "scene.toml"))
    assert by_file.name == box.name == "bench-box"
    assert by_file.path == box.path and box.path.endswith("scene.toml")
    assert by_file.content_hash == box.content_hash


def test_get_reads_numbers_arrays_and_tables(box):
    assert box.get("trace.seed") == box.default_seed
    assert isinstance(box.get("trace.seed"), int)
    center = box.get("sources.0.center")
    assert isinstance(center, list) and len(center) == 3
    assert box.get("sources.0.center.2") == center[2]
    assert box.get("detector.bins") == list(box.source["detector"]["bins"])


def test_a_star_reads_the_value_every_element_holds_or_each_value(phone):
    assert phone.get("sources.*.center.2") == phone.get("sources.0.center.2")
    # The LEDs sit at different y: one value per element, in order.
    ys = [src["center"][1] for src in phone.source["sources"]]
    assert len(set(ys)) > 1
    assert phone.get("sources.*.center.1") == ys
    assert phone.get("sources.*.center") == [src["center"] for src in phone.source["sources"]]


def test_set_changes_the_scene_and_copies_are_independent(phone):
    s = phone.copy()
    s.set("surfaces.lgp_back.ink_albedo", 0.8)
    assert s.get("surfaces.lgp_back.ink_albedo") == 0.8
    assert phone.get("surfaces.lgp_back.ink_albedo") == 0.9
    assert s.content_hash != phone.content_hash
    c = copy.deepcopy(s)
    c.set("surfaces.lgp_back.ink_albedo", 0.7)
    assert s.get("surfaces.lgp_back.ink_albedo") == 0.8


def test_set_with_a_star_sets_every_element(phone):
    s = phone.copy()
    s.set("sources.*.center.2", 0.3)
    assert [src["center"][2] for src in s.source["sources"]] == [0.3] * 6


def test_set_of_a_missing_key_is_a_value_error_and_changes_nothing(box):
    s = box.copy()
    with pytest.raises(ValueError, match="no key 'nope'"):
        s.set("surfaces.nope.albedo", 1.0)
    with pytest.raises(ValueError, match="not a dotted path"):
        s.set("surfaces..albedo", 1.0)
    assert s.content_hash == box.content_hash


def test_set_of_an_invalid_value_is_a_scene_error_naming_file_and_field(phone):
    s = phone.copy()
    with pytest.raises(bt.SceneError) as e:
        s.set("surfaces.lgp_back.ink_albedo", 2.0)
    assert "scene.toml" in str(e.value) and "ink_albedo" in str(e.value)
    assert s.get("surfaces.lgp_back.ink_albedo") == 0.9


def test_set_of_a_value_toml_cannot_hold_is_a_type_error_naming_the_key(box):
    with pytest.raises(TypeError, match="trace.seed"):
        box.copy().set("trace.seed", object())


def test_set_of_an_array_longer_than_its_key_takes_is_an_error(phone):
    s = phone.copy()
    with pytest.raises(bt.BlutraceError, match=r"sources\[0\]\.center: has 4 elements"):
        s.set("sources.0.center", [1.0, 2.0, 3.0, 4.0])
    assert len(s.get("sources.0.center")) == 3


def test_set_takes_numpy_arrays_and_scalars(phone):
    s = phone.copy()
    s.set("sources.0.center", np.array([1.0, 2.0, 3.0]))
    assert s.get("sources.0.center") == [1.0, 2.0, 3.0]
    s.set("surfaces.lgp_back.ink_albedo", np.float64(0.5))
    assert s.get("surfaces.lgp_back.ink_albedo") == 0.5
    s.set("surfaces.lgp_back.ink_albedo", np.float32(0.75))
    assert s.get("surfaces.lgp_back.ink_albedo") == 0.75
    s.set("trace.seed", np.int64(7))
    assert s.get("trace.seed") == 7 and isinstance(s.get("trace.seed"), int)
    t = phone.copy()
    t.set("sources.*.center.2", np.array(0.3))  # a 0-d array is its one value
    assert t.get("sources.*.center.2") == 0.3
    s.set("detector.bins", np.array([60, 40], dtype=np.int32))
    assert s.get("detector.bins") == [60, 40]


def test_exceptions_are_named_as_the_package_exports_them(tmp_path):
    import traceback

    for cls in (bt.BlutraceError, bt.SceneError):
        assert cls.__module__ == "blutrace" and cls.__qualname__ == cls.__name__
    with pytest.raises(bt.SceneError) as e:
        bt.Scene.load(tmp_path / "nothing-here.toml")
    shown = traceback.format_exception_only(e.type, e.value)[-1]
    assert shown.startswith("blutrace.SceneError: "), shown


def test_a_missing_scene_is_a_scene_error_naming_the_file(tmp_path):
    missing = tmp_path / "nothing-here.toml"
    with pytest.raises(bt.SceneError, match="nothing-here.toml"):
        bt.Scene.load(missing)


def test_a_broken_scene_file_is_a_scene_error_naming_the_file(tmp_path):
    bad = tmp_path / "scene.toml"
    bad.write_text("version = 1\n[detector\n")
    with pytest.raises(bt.SceneError) as e:
        bt.Scene.load(tmp_path)
    assert str(bad) in str(e.value)
    assert isinstance(e.value, bt.BlutraceError) and isinstance(e.value, Exception)


def test_a_missing_geometry_file_names_the_field(tmp_path, box):
    text = box.to_toml()
    moved = tmp_path / "scene.toml"
    moved.write_text(text)
    with pytest.raises(bt.SceneError, match=r"geometry\[0\]\.file"):
        bt.Scene.load(moved)


def test_from_toml_with_the_original_path_is_the_same_scene(box):
    again = bt.Scene.from_toml(box.to_toml(), box.path)
    assert again.content_hash == box.content_hash


def test_scenes_pickle(phone):
    s = phone.copy()
    s.set("surfaces.lgp_back.ink_albedo", 0.85)
    back = pickle.loads(pickle.dumps(s))
    assert back.content_hash == s.content_hash
    assert back.get("surfaces.lgp_back.ink_albedo") == 0.85


def test_check_is_what_check_json_prints(cli, box):
    mine = box.check()
    printed = json.loads(run_cli(cli, "check", box.path, "--json").stdout)
    assert mine == printed
    assert mine["scene"] == "bench-box" and mine["tally_bytes"] > 0


@pytest.mark.parametrize(
    "call, says",
    [
        (lambda box: bt.Scene.load(5), "path"),
        (lambda box: bt.Scene.from_toml(5, "scene.toml"), "text"),
        (lambda box: bt.Scene.from_toml(box.to_toml(), 5), "path"),
        (lambda box: box.get(5), "key"),
        (lambda box: box.copy().set(5, 1.0), "key"),
        (lambda box: box.trace(photons=1000, estimator=None), "estimator"),
        (lambda box: box.trace(photons=1000, target_metric=1), "target_metric"),
        (lambda box: box.trace(photons=1000, backend=1), "backend"),
        (lambda box: box.optimize(method=1), "method"),
        (lambda box: box.optimize(vary=[("sources.0.center.2", (0.1, 0.3))]), "vary"),
        (lambda box: box.characterise(5), "tag"),
        (lambda box: box.trace(photons=1000).write(5), "dir"),
        (lambda box: bt.merge(5), "runs"),
        (lambda box: bt.merge([box.trace(photons=1000, shard=(0, 1))], partial="yes"), "partial"),
        (lambda box: bt.read_exr(5), "path"),
    ],
    ids=lambda x: x if isinstance(x, str) else "call",
)
def test_an_argument_of_a_wrong_type_is_a_type_error_naming_it(box, call, says):
    with pytest.raises(TypeError) as e:
        call(box)
    assert str(e.value).startswith(f"{says}: "), str(e.value)
