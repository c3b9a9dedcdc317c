"""Traces: arrays, units, determinism, bit-identity with the command line, errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

import blutrace as bt

from conftest import run_cli

N = 100_000


@pytest.fixture(scope="module")
def run(box) -> bt.Run:
    return box.trace(photons=N, seed=3)


def test_maps_have_the_detectors_shape_and_types(box, run):
    nx, ny = box.get("detector.bins")
    n_theta, n_phi = box.get("detector.angular_bins")
    assert run.flux.shape == run.flux_stderr.shape == run.hits.shape == (ny, nx)
    assert run.flux.dtype == np.float64 and run.hits.dtype == np.uint64
    assert run.angular.shape == run.angular_stderr.shape == (n_theta, n_phi)
    assert run.photons == N and run.seed == 3 and run.shard is None
    assert run.stopped_by == "photons"


def test_flux_integrates_to_the_detected_power(box, run):
    size = box.get("detector.size_mm")
    nx, ny = box.get("detector.bins")
    bin_area = size[0] * size[1] / (nx * ny)
    detected = run.flux.sum() * bin_area
    assert detected == pytest.approx(run.summary["ledger"]["detected_w"], rel=1e-9)
    assert run.hits.sum() > 0 and (run.flux_stderr >= 0).all()


def test_efficiency_is_the_summarys(run):
    s = run.summary
    assert run.efficiency == (s["extraction_efficiency"], s["extraction_efficiency_stderr"])
    assert 0 < run.efficiency[0] < 1


def test_the_same_seed_gives_the_same_bits_on_any_thread_count(box, run):
    one = box.trace(photons=N, seed=3, threads=1)
    two = box.trace(photons=N, seed=3, threads=2)
    for a in (one, two):
        assert np.array_equal(a.flux, run.flux)
        assert np.array_equal(a.flux_stderr, run.flux_stderr)
        assert np.array_equal(a.angular, run.angular)
    other = box.trace(photons=N, seed=4)
    assert not np.array_equal(other.flux, run.flux)


def test_outputs_equal_the_command_lines_byte_for_byte(cli, box, run, tmp_path):
    mine = tmp_path / "py"
    files = run.write(mine)
    assert sorted(p.split("/")[-1] for p in files) == sorted(
        ["flux.exr", "angular.exr", "flux.png", "conoscope.png", "convergence.csv", "convergence.png", "summary.json"]
    )
    theirs = tmp_path / "cli"
    run_cli(cli, "trace", box.path, "--photons", str(N), "--seed", "3", "--quiet", "--out", str(theirs))
    for name in ["flux.exr", "angular.exr", "flux.png", "conoscope.png"]:
        assert (mine / name).read_bytes() == (theirs / name).read_bytes(), name
    timing = {"runtime_s", "photons_per_s", "interactions_per_s", "figure_of_merit", "threads"}
    a, b = (json.loads((d / "summary.json").read_text()) for d in (mine, theirs))
    assert {k: v for k, v in a.items() if k not in timing} == {
        k: v for k, v in b.items() if k not in timing
    }


def test_arrays_equal_the_command_lines_exr(cli, box, run, tmp_path):
    out = tmp_path / "cli"
    run_cli(cli, "trace", box.path, "--photons", str(N), "--seed", "3", "--quiet", "--out", str(out))
    flux = bt.read_exr(out / "flux.exr")
    assert np.array_equal(flux["Y"], run.flux.astype(np.float32))
    assert np.array_equal(flux["stderr.Y"], run.flux_stderr.astype(np.float32))
    assert np.array_equal(flux["hits.Y"], run.hits.astype(np.float32))
    angular = bt.read_exr(out / "angular.exr")
    assert np.array_equal(angular["Y"], run.angular.astype(np.float32))


def test_summary_is_summary_json(run, tmp_path):
    run.write(tmp_path)
    assert json.loads((tmp_path / "summary.json").read_text()) == run.summary


def test_write_is_all_or_nothing(run, tmp_path):
    blocked = tmp_path / "a-file"
    blocked.write_text("not a folder")
    with pytest.raises(bt.BlutraceError):
        run.write(blocked)
    assert blocked.read_text() == "not a folder"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]


@pytest.mark.parametrize(
    "kwargs, says",
    [
        ({"photons": 0}, "photons"),
        ({"photons": -5}, "photons"),
        ({"photons": 1.5}, "photons"),
        ({"estimator": "magic"}, "estimator"),
        ({"target_metric": "beauty"}, "target_metric"),
        ({"threads": 0}, "threads"),
        ({"shard": (4, 4)}, "shard"),
        ({"max_time": -1.0}, "max_time"),
        ({"target_error": 0.0}, "target_error"),
        ({"shard": (0, 2), "max_time": 1.0}, "max_time"),
        ({"backend": "gpu"}, "backend"),
    ],
)
def test_bad_arguments_are_value_errors_naming_them(box, kwargs, says):
    with pytest.raises(ValueError, match=says):
        box.trace(**{"photons": 1000, **kwargs})


@pytest.mark.parametrize(
    "kwargs, error, says",
    [
        ({"shard": (0,)}, ValueError, "shard"),
        ({"shard": "0/2"}, ValueError, "shard"),
        ({"target_error": "small"}, TypeError, "target_error"),
        ({"max_time": [1.0]}, TypeError, "max_time"),
    ],
)
def test_arguments_of_a_wrong_type_or_shape_are_errors_naming_them(box, kwargs, error, says):
    with pytest.raises(error) as e:
        box.trace(**{"photons": 1000, **kwargs})
    assert says in str(e.value)  # the message itself, not a note pytest's match= also reads


def test_photons_may_be_a_whole_float(box):
    assert box.trace(photons=2e4, seed=1).photons == 20_000


def test_a_target_error_stops_the_run_early(box):
    r = box.trace(target_error=0.05, target_metric="efficiency", seed=1)
    assert r.stopped_by == "target_error"
    assert r.photons < 1_000_000_000
    assert r.efficiency[1] / r.efficiency[0] <= 0.05


def test_a_progress_callable_hears_the_photons(box):
    seen = []
    box.trace(photons=N, seed=1, progress=lambda done, total: seen.append((done, total)))
    assert seen, "no report"
    assert seen[-1] == (N, N)
    assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:]))


def test_progress_true_reports_on_stderr_without_tqdm(box, capsys, monkeypatch):
    import builtins

    real_import = builtins.__import__

    def no_tqdm(name, *args, **kwargs):
        if name.startswith("tqdm"):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_tqdm)
    box.trace(photons=N, seed=1, progress=True)
    assert f"{N}/{N} photons" in capsys.readouterr().err


def test_progress_true_draws_a_tqdm_bar_of_the_photons(box, monkeypatch):
    import tqdm.auto

    bars = []

    class Watched(tqdm.auto.tqdm):
        def close(self):  # tqdm closes again when collected: count the first
            if not self.disable:
                bars.append((self.n, self.total, self.unit))
            super().close()

    monkeypatch.setattr(tqdm.auto, "tqdm", Watched)
    box.trace(photons=N, seed=1, progress=True)
    assert bars == [(N, N, "photons")]


def test_a_bad_progress_is_a_type_error(box):
    with pytest.raises(TypeError, match="progress"):
        box.trace(photons=1000, progress="yes")


def test_a_panic_in_rust_is_an_exception_not_a_crash():
    with pytest.raises(bt.BlutraceError, match="internal error.*deliberate panic"):
        bt._native._panic_on_worker()
    assert bt.Scene is not None  # the interpreter goes on


def test_a_scene_with_lumens_has_a_luminance_map_and_power_per_source(phone):
    s = phone.trace(photons=20_000, seed=2).summary
    m = s["luminance_map"]
    assert m["cone_deg"] == 2.0 and m["mean_cd_m2"]["stderr"] > 0.0
    by_source = s["ledger"]["detected_by_source_w"]
    assert len(by_source) == 6
    assert sum(b["w"] for b in by_source) == pytest.approx(s["ledger"]["detected_w"], rel=1e-12)


def test_undefined_values_of_a_run_without_light_on_the_target_are_none(box, tmp_path):
    """NaN in the library (a metric of an empty map) is None here, as null in the JSON."""
    dark = box.copy()
    x, y, z = dark.get("detector.origin")
    dark.set("detector.origin", [x + 1000.0, y, z])  # the detector beside the scene
    run = dark.trace(photons=20_000, seed=1)
    assert run.flux.sum() == 0.0
    s = run.summary
    assert s["uniformity"]["cv"] is None and s["uniformity"]["min_over_max"] is None
    json.dumps(s, allow_nan=False)  # no float NaN anywhere
    run.write(tmp_path)
    assert json.loads((tmp_path / "summary.json").read_text()) == s
