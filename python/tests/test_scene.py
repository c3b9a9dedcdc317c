"""Scenes: loading, key paths, copies, check, errors."""

from __future__ import annotations

import copy
import json
import pickle

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


def test_a_star_reads_the_value_every_element_holds(phone):
    assert phone.get("sources.*.center.2") == phone.get("sources.0.center.2")
    with pytest.raises(ValueError, match="the elements differ"):
        phone.get("sources.*.center.1")  # the LEDs sit at different y


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


def test_set_of_a_value_toml_cannot_hold_is_a_type_error(box):
    with pytest.raises(TypeError):
        box.copy().set("trace.seed", object())


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
