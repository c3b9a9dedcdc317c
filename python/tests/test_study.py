"""Design studies (issue 49): coordinates, every map the CLI writes, xarray, whole runs
that pickle and load back, sweeps to DataFrames, notebook manners, bundled scenes."""

from __future__ import annotations

import inspect
import json
import pathlib
import pickle
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import blutrace as bt

from conftest import SCENES, run_cli

N = 60_000


@pytest.fixture(scope="module")
def run(box) -> bt.Run:
    return box.trace(photons=N, seed=5)


@pytest.fixture(scope="module")
def color_scene() -> bt.Scene:
    """notebook14-color on a coarse 10 x 8 grid, so every bin sees light at few photons."""
    s = bt.Scene.load(SCENES / "notebook14-color")
    s.set("detector.bins", [10, 8])
    return s


@pytest.fixture(scope="module")
def color_run(color_scene) -> bt.Run:
    return color_scene.trace(photons=40_000, seed=2)


@pytest.fixture(scope="module")
def polarized(box) -> bt.Run:
    text = box.to_toml().replace("polarization = false", "polarization = true")
    assert "polarization = true" in text
    return bt.Scene.from_toml(text, box.path).trace(photons=N, seed=4)


def f32(a):
    return np.asarray(a, dtype=np.float32)


# --- coordinates ---------------------------------------------------------------------

def test_bin_centres_are_in_mm_and_degrees_in_the_detector_frame(box, run):
    # bench-box: 120 x 80 mm in 120 x 80 bins; 18 x 36 angular bins.
    assert run.flux.shape == (run.y_mm.size, run.x_mm.size) == (80, 120)
    assert run.x_mm[0] == 0.5 and run.x_mm[-1] == 119.5
    assert np.allclose(np.diff(run.x_mm), 1.0) and run.y_mm[-1] == 79.5
    assert run.angular.shape == (run.theta_deg.size, run.phi_deg.size) == (18, 36)
    assert run.theta_deg[0] == 2.5 and run.theta_deg[-1] == 87.5
    assert run.phi_deg[0] == 5.0 and run.phi_deg[-1] == 355.0
    # The centres the summary's luminance rows use.
    lit = bt.Scene.load(SCENES / "phone-led").trace(photons=5_000, seed=1)
    rows = [r["theta_deg"] for r in lit.summary["luminance"]["by_theta"]]
    assert np.array_equal(np.asarray(rows), lit.theta_deg)


# --- the CLI's other outputs -----------------------------------------------------------

def cli_folder(cli, scene: bt.Scene, tmp_path: pathlib.Path, photons: int, seed: int):
    """The CLI's outputs of `scene` (as edited): its folder copied, the file replaced."""
    import shutil

    copy = tmp_path / "scene"
    shutil.copytree(pathlib.Path(scene.path).parent, copy)
    (copy / "scene.toml").write_text(scene.to_toml())
    out = tmp_path / "cli"
    run_cli(cli, "trace", str(copy), "--photons", str(photons), "--seed", str(seed),
            "--out", str(out), "--quiet")
    return out


def test_luminance_colour_and_uv_equal_the_command_lines_images(cli, color_scene, color_run, tmp_path):
    out = cli_folder(cli, color_scene, tmp_path, 40_000, 2)
    lum = bt.read_exr(out / "luminance.exr")
    assert np.array_equal(f32(color_run.luminance), lum["Y"])
    assert np.array_equal(f32(color_run.luminance_stderr), lum["stderr.Y"])
    ang = bt.read_exr(out / "angular.exr")
    assert np.array_equal(f32(color_run.angular_luminance), ang["luminance.Y"])
    col = bt.read_exr(out / "color.exr")
    for name in ["X", "Y", "Z"]:
        assert np.array_equal(f32(getattr(color_run, name)), col[name]), name
        assert np.array_equal(f32(getattr(color_run, f"{name}_stderr")), col[f"stderr.{name}"])
    assert np.array_equal(f32(color_run.u_prime), col["u_prime"], equal_nan=True)
    assert np.array_equal(f32(color_run.v_prime), col["v_prime"], equal_nan=True)
    assert np.array_equal(f32(color_run.u_prime_stderr), col["stderr.u_prime"], equal_nan=True)
    assert np.array_equal(f32(color_run.v_prime_stderr), col["stderr.v_prime"], equal_nan=True)
    # Y is the illuminance: its mean is the summary's, in lux.
    lux = color_run.summary["color"]["illuminance_lux"]["value"]
    assert color_run.Y.mean() == pytest.approx(lux, rel=1e-9)


def test_a_monochrome_run_has_no_colour_and_a_radiometric_one_no_luminance(run):
    for name in ["X", "Y_stderr", "u_prime", "v_prime_stderr", "luminance", "stokes"]:
        assert getattr(run, name) is None, name


def test_uv_prime_errors_match_the_scatter_between_seeds(color_scene, color_run):
    # The jackknife error of u', v' per bin against the spread of 8 independent runs:
    # over 80 bins the mean ratio std/stderr is 1 within a few percent.
    runs = [color_scene.trace(photons=40_000, seed=100 + k) for k in range(8)]
    for name in ["u_prime", "v_prime"]:
        values = np.stack([getattr(r, name) for r in runs])
        errors = np.stack([getattr(r, f"{name}_stderr") for r in runs])
        assert np.isfinite(values).all() and np.isfinite(errors).all()
        ratio = values.std(axis=0, ddof=1).mean() / errors.mean()
        # Sample std of 8 runs: ~26 % error per bin, ~4 % over 80 bins (and its mean is
        # biased low by ~3 %): 5 standard errors either side.
        assert 0.75 < ratio < 1.2, (name, ratio)


def test_stokes_maps_are_the_command_lines_and_add_up_to_the_summary(polarized, tmp_path):
    assert polarized.stokes.shape == (4, 80, 120) == polarized.stokes_stderr.shape
    assert np.array_equal(polarized.stokes[0], polarized.flux)
    assert np.array_equal(polarized.stokes_stderr[0], polarized.flux_stderr)
    pol = polarized.summary["polarization"]
    s = polarized.stokes.sum(axis=(1, 2))
    for k, name in [(1, "s1"), (2, "s2"), (3, "s3")]:
        assert s[k] / s[0] == pytest.approx(pol[name]["value"], rel=1e-9, abs=1e-12)
    polarized.write(tmp_path / "out")
    exr = bt.read_exr(tmp_path / "out" / "stokes.exr")
    for k in range(4):
        assert np.array_equal(f32(polarized.stokes[k]), exr[f"S{k}"])
        assert np.array_equal(f32(polarized.stokes_stderr[k]), exr[f"stderr.S{k}"])


# --- xarray ----------------------------------------------------------------------------

def test_to_xarray_has_every_map_with_errors_coordinates_and_the_summary(polarized):
    pytest.importorskip("xarray")
    ds = polarized.to_xarray()
    assert np.array_equal(ds["flux"].values, polarized.flux)
    assert np.array_equal(ds["flux_stderr"].values, polarized.flux_stderr)
    assert np.array_equal(ds["hits"].values, polarized.hits)
    assert np.array_equal(ds["angular"].values, polarized.angular)
    assert np.array_equal(ds["x_mm"].values, polarized.x_mm)
    assert np.array_equal(ds["theta_deg"].values, polarized.theta_deg)
    assert ds["flux"].dims == ("y_mm", "x_mm") and ds["flux"].attrs["units"] == "W/mm^2"
    assert ds["stokes"].sel(component="S1").shape == (80, 120)
    # A bin picked by its coordinates in mm.
    assert ds["flux"].sel(x_mm=60.5, y_mm=40.5).item() == polarized.flux[40, 60]
    assert ds.attrs["extraction_efficiency"] == polarized.efficiency[0]
    assert ds.attrs["uniformity_cv"] == polarized.summary["uniformity"]["cv"]
    assert "luminance" not in ds  # no lumens in bench-box


def test_to_xarray_without_xarray_names_the_extra(run, monkeypatch):
    monkeypatch.setitem(sys.modules, "xarray", None)
    with pytest.raises(ImportError, match=r"Run.to_xarray needs xarray: pip install 'blutrace\[study\]'"):
        run.to_xarray()


def test_to_xarray_of_a_spectral_run_has_colour_and_luminance(color_run):
    pytest.importorskip("xarray")
    ds = color_run.to_xarray()
    for name in ["luminance", "luminance_stderr", "X", "Z_stderr", "u_prime_stderr", "angular_luminance"]:
        assert name in ds, name
    assert np.array_equal(ds["v_prime"].values, color_run.v_prime, equal_nan=True)


# --- whole runs pickle, load back --------------------------------------------------------

MAPS = ["flux", "flux_stderr", "hits", "angular", "angular_stderr", "angular_hits"]


#: What differs between two traces of one design (timing), or in a pickled run (its scene
#: file, made absolute so a worker in another folder finds the geometry).
TIMING = {"runtime_s", "photons_per_s", "interactions_per_s", "figure_of_merit", "scene_file"}


def same_maps(a: bt.Run, b: bt.Run, maps=MAPS) -> None:
    for name in maps:
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None and y is None) or np.array_equal(x, y, equal_nan=True), name


def same_run(a: bt.Run, b: bt.Run, maps=MAPS, timed=True) -> None:
    """Equal maps and summaries (bit for bit: NaN as null); `timed`: and history."""
    same_maps(a, b, maps)
    strip = lambda s: {k: v for k, v in s.items() if k not in TIMING}  # noqa: E731
    assert json.dumps(strip(a.summary)) == json.dumps(strip(b.summary))
    if timed:
        assert a.runtime_s == b.runtime_s
        assert json.dumps(a.history) == json.dumps(b.history)


def test_a_whole_run_pickles_bit_for_bit(polarized, color_run):
    for r in [polarized, color_run]:
        back = pickle.loads(pickle.dumps(r))
        same_run(back, r, MAPS + ["stokes", "X", "u_prime_stderr", "luminance"])
        assert (back.photons, back.seed, back.shard, back.stopped_by) == (
            r.photons, r.seed, None, r.stopped_by)


def test_a_process_pool_returns_whole_runs(box, run):
    with ProcessPoolExecutor(2) as pool:
        back = pool.submit(box.trace, photons=N, seed=5).result()
    same_run(back, run, timed=False)


def test_a_target_error_run_pickles_with_its_history(box):
    r = box.trace(target_error=0.05, seed=2)
    back = pickle.loads(pickle.dumps(r))
    same_run(back, r)
    assert back.stopped_by == r.stopped_by == "target_error"


def test_load_reads_the_command_lines_output_folder(cli, box, run, tmp_path):
    out = tmp_path / "cli"
    run_cli(cli, "trace", str(SCENES / "bench-box"), "--photons", str(N), "--seed", "5",
            "--out", str(out), "--quiet")
    loaded = bt.Run.load(out)
    for name in MAPS:
        assert np.array_equal(getattr(loaded, name), f32(getattr(run, name)).astype(getattr(run, name).dtype)), name
    assert loaded.summary == json.loads((out / "summary.json").read_text())
    assert loaded.efficiency == run.efficiency and loaded.photons == N and loaded.seed == 5
    assert np.array_equal(loaded.x_mm, run.x_mm) and np.array_equal(loaded.phi_deg, run.phi_deg)
    assert len(loaded.history) == len(run.history)
    assert loaded.history[-1]["photons"] == N
    assert loaded.folder == str(out) and loaded.scene.content_hash == box.content_hash
    with pytest.raises(bt.BlutraceError, match="read from .*write needs a traced run"):
        loaded.write(tmp_path / "again")
    same_run(pickle.loads(pickle.dumps(loaded)), loaded)


def test_load_reads_what_write_wrote_with_colour(color_run, tmp_path):
    color_run.write(tmp_path / "out")
    loaded = bt.Run.load(tmp_path / "out")
    for name in ["luminance", "X", "Y_stderr", "u_prime", "angular_luminance"]:
        assert np.array_equal(getattr(loaded, name), f32(getattr(color_run, name)), equal_nan=True), name
    for name in ["u_prime_stderr", "v_prime_stderr"]:
        assert np.array_equal(getattr(loaded, name), f32(getattr(color_run, name))), name


def test_load_of_a_folder_without_a_run_names_it(tmp_path):
    with pytest.raises(bt.BlutraceError, match=f"{tmp_path}: no summary.json or shard.json"):
        bt.Run.load(tmp_path)
    with pytest.raises(TypeError, match="dir"):
        bt.Run.load(3)


def test_a_damaged_output_folder_is_an_error_naming_the_file_and_field(run, tmp_path):
    out = tmp_path / "out"
    run.write(out)
    summary = json.loads((out / "summary.json").read_text())
    del summary["detector"]["bins"]
    (out / "summary.json").write_text(json.dumps(summary))
    with pytest.raises(bt.BlutraceError, match=r"summary.json: detector.bins"):
        bt.Run.load(out)
    (out / "summary.json").write_text("{ not json")
    with pytest.raises(bt.BlutraceError, match=r"summary.json: not a summary file"):
        bt.Run.load(out)
    run.write(out)
    (out / "flux.exr").unlink()
    with pytest.raises(bt.BlutraceError, match=f"{out}: no flux.exr"):
        bt.Run.load(out)


def test_python_and_cli_shards_merge_either_way(cli, box, tmp_path):
    single = box.trace(photons=N, seed=8)
    py_shard = box.trace(photons=N, seed=8, shard=(0, 2))
    files = py_shard.write(tmp_path / "s0")
    assert files == [str(tmp_path / "s0" / "shard.json")]
    run_cli(cli, "trace", str(SCENES / "bench-box"), "--photons", str(N), "--seed", "8",
            "--shard", "1/2", "--out", str(tmp_path / "s1"), "--quiet")
    # Python merges the CLI's shard; the CLI merges Python's.
    merged = bt.merge([bt.Run.load(tmp_path / "s0"), bt.Run.load(tmp_path / "s1")])
    same_maps(merged, single)
    assert merged.efficiency == single.efficiency
    run_cli(cli, "merge", str(tmp_path / "s0"), str(tmp_path / "s1"), "--out", str(tmp_path / "m"))
    assert np.array_equal(bt.read_exr(tmp_path / "m" / "flux.exr")["Y"], f32(single.flux))


# --- sweeps ---------------------------------------------------------------------------------

KEY = "surfaces.lgp_back.ink_albedo"


def test_sweep_traces_the_grid_into_a_dataframe(box):
    pytest.importorskip("pandas")
    df = bt.sweep(box, {KEY: [0.5, 0.9], "trace.max_bounces": [1000, 100000]}, photons=20_000, seed=3)
    assert len(df) == 4 and list(df.columns[:2]) == [KEY, "trace.max_bounces"]
    assert df[KEY].tolist() == [0.5, 0.5, 0.9, 0.9]
    for col in ["efficiency", "efficiency_stderr", "cv", "cv_stderr", "cv_debiased",
                "cv_debiased_stderr", "nine_point_min_over_max_stderr", "mean", "mean_stderr"]:
        assert col in df.columns, col
    # Each row is the design's own trace.
    design = box.copy()
    design.set(KEY, 0.9)
    design.set("trace.max_bounces", 1000)
    r = design.trace(photons=20_000, seed=3)
    row = df.iloc[2]
    assert (row["efficiency"], row["efficiency_stderr"]) == r.efficiency
    assert row["cv_debiased"] == r.summary["cv_debiased"]
    # Whiter ink wastes less light.
    assert df.loc[df[KEY] == 0.9, "efficiency"].mean() > df.loc[df[KEY] == 0.5, "efficiency"].mean()


def test_sweep_zips_lists_and_runs_on_an_executor(box):
    pytest.importorskip("pandas")
    vary = {KEY: np.array([0.6, 0.8, 0.95]), "trace.seed": [1, 2, 3]}
    serial = bt.sweep(box, vary, photons=10_000, seed=1, zipped=True)
    assert len(serial) == 3 and serial[KEY].tolist() == [0.6, 0.8, 0.95]
    with ProcessPoolExecutor(2) as pool:
        parallel = bt.sweep(box, vary, photons=10_000, seed=1, zipped=True, executor=pool)
    assert serial.drop(columns="runtime_s").equals(parallel.drop(columns="runtime_s"))
    with pytest.raises(ValueError, match="vary: zipped lists must have one length"):
        bt.sweep(box, {KEY: [0.5, 0.6], "trace.seed": [1]}, photons=1000, zipped=True)


def test_sweep_arguments_of_a_wrong_kind_are_errors_naming_them(box):
    pytest.importorskip("pandas")
    with pytest.raises(TypeError, match="scene must be a blutrace.Scene, got str"):
        bt.sweep("scenes/bench-box", {KEY: [0.5]})
    with pytest.raises(TypeError, match="vary must be a non-empty dict"):
        bt.sweep(box, [KEY, 0.5])
    with pytest.raises(ValueError, match=r"vary\['surfaces.lgp_back.ink_albedo'\] has no values"):
        bt.sweep(box, {KEY: []})
    with pytest.raises(ValueError, match="photons"):
        bt.sweep(box, {KEY: [0.5]}, photons=0)
    with pytest.raises(ValueError, match="no key 'nope'"):
        bt.sweep(box, {"surfaces.lgp_back.nope": [0.5]}, photons=1000)


def test_sweep_without_pandas_names_the_extra(box, monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match=r"pip install 'blutrace\[study\]'"):
        bt.sweep(box, {KEY: [0.5]}, photons=1000)


# --- notebook manners -----------------------------------------------------------------------

def test_scenes_compare_by_content(box, phone):
    c = box.copy()
    assert c == box and not (c != box) and box != phone and box != "bench-box"
    c.set(KEY, 0.5)
    assert c != box
    c.set(KEY, box.get(KEY))
    assert c == box
    with pytest.raises(TypeError, match="unhashable"):  # a value that set() changes
        hash(c)


def test_runs_and_scenes_show_as_html(run, color_run, box):
    h = run._repr_html_()
    eff, err = run.efficiency
    assert f"{eff:.4g} &plusmn; {err:.2g}" in h and "<svg" in h and "120 &times; 80 mm" in h
    assert "u&#x27;" not in h and "u', v'" in color_run._repr_html_()
    s = box._repr_html_()
    assert "bench-box" in s and "[120, 80]" in s and box.content_hash in s


def test_optimize_has_an_explicit_signature(box):
    params = inspect.signature(box.optimize).parameters
    for name in ["method", "vary", "photons", "seed", "max_iter", "objective", "grid_points",
                 "verify_photons", "threads", "progress", "export_placement"]:
        assert name in params, name
    assert params["photons"].kind == inspect.Parameter.KEYWORD_ONLY
    with pytest.raises(TypeError, match="nonsense"):
        box.optimize(nonsense=1)


# --- bundled scenes -------------------------------------------------------------------------

def test_bundled_scenes_come_with_the_installed_package():
    path = bt.scenes.path("notebook14")
    # From site-packages (tools/test-python.sh installs the wheel), not the checkout.
    assert "site-packages" in path.resolve().parts, path.resolve()
    assert SCENES not in path.resolve().parents, path.resolve()
    assert (path / "scene.toml").read_bytes() == (SCENES / "notebook14/scene.toml").read_bytes()
    scene = bt.Scene.load(path)
    assert scene.content_hash == bt.Scene.load(SCENES / "notebook14").content_hash
    assert "bench-box" in bt.scenes.names() and "test/slab" in bt.scenes.names()
    with pytest.raises(ValueError, match="name: no bundled scene 'nope' .*bench-box"):
        bt.scenes.path("nope")


# --- optimizations and characterisations pickle ---------------------------------------------

def files_of(folder: pathlib.Path) -> dict:
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_an_optimization_pickles_with_its_reports_and_files(phone, tmp_path):
    opt = phone.optimize(method="grid", vary={"sources.*.center.2": (0.2, 0.3)}, grid_points=2,
                         photons=10_000, verify_photons=0, objective="efficiency")
    with ProcessPoolExecutor(1) as pool:  # a worker process returns it, as pickle carries it
        back = pool.submit(pickle.loads, pickle.dumps(opt)).result()
    assert back.summary == opt.summary and back.history == opt.history
    assert back.interrupted is False and back.scene == opt.scene
    assert repr(back) == repr(opt)
    opt.write(tmp_path / "a")
    written = back.write(tmp_path / "b")
    assert sorted(pathlib.Path(w).name for w in written) == sorted(p.name for p in (tmp_path / "a").iterdir())
    assert files_of(tmp_path / "b") == files_of(tmp_path / "a")
    # Pickled again after unpickling: the same.
    assert pickle.loads(pickle.dumps(back)).summary == opt.summary


def test_a_characterisation_pickles_with_its_table(tmp_path):
    from test_characterise import OBJ, SHEET

    (tmp_path / "sheet.obj").write_text(OBJ)
    scene = bt.Scene.from_toml(SHEET, tmp_path / "scene.toml")
    c = scene.characterise("sheet", photons=5_000, aoi=[0, 60])
    back = pickle.loads(pickle.dumps(c))
    assert (back.part, back.aoi, back.rotations) == (c.part, c.aoi, c.rotations)
    assert back.to_bsdf() == c.to_bsdf() and "DataBegin" in c.to_bsdf()
    for k, v in c.fates.items():
        assert np.array_equal(back.fates[k], v), k
    with pytest.raises(bt.BlutraceError, match="sheet.obj"):  # still spares the scene's files
        back.write(tmp_path / "sheet.obj")


# --- the package's house ----------------------------------------------------------------------

def test_the_extension_modules_depend_on_each_other_without_a_circle():
    """python/src: scene -> run -> ... never back to scene (nor run <-> saved,
    optimization -> scene): each module's `crate::x` uses form an acyclic graph."""
    import re

    from conftest import REPO

    src = REPO / "python" / "src"
    deps = {
        p.stem: set(re.findall(r"crate::([a-z_]+)", p.read_text())) - {p.stem}
        for p in src.glob("*.rs")
    }
    mods = set(deps)

    def reaches(a, b, seen=()):
        return any(d == b or (d in mods and d not in seen and reaches(d, b, seen + (d,)))
                   for d in deps[a] & mods)

    circles = sorted(m for m in mods - {"lib"} if reaches(m, m))
    assert circles == [], {m: sorted(deps[m] & mods) for m in circles}
