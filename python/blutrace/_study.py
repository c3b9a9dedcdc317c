"""Design studies: runs as xarray Datasets, sweeps to pandas DataFrames, notebook views.

xarray and pandas are optional (``pip install 'blutrace[study]'``): imported only when
``Run.to_xarray`` or ``sweep`` is called.
"""

from __future__ import annotations

import html
import itertools
import math
from typing import Any, Iterable, Mapping

import numpy as np

#: Maps on the flux grid: attribute, unit, description.
FLUX_MAPS = [
    ("flux", "W/mm^2", "irradiance on the target"),
    ("luminance", "cd/m^2", "luminance within the detector's luminance cone (normal view)"),
    ("X", "lx", "CIE 1931 X (lux-scaled)"),
    ("Y", "lx", "CIE 1931 Y: illuminance"),
    ("Z", "lx", "CIE 1931 Z (lux-scaled)"),
    ("u_prime", "1", "CIE 1976 u'"),
    ("v_prime", "1", "CIE 1976 v'"),
]
#: Maps on the angular grid.
ANGULAR_MAPS = [
    ("angular", "W/sr", "radiant intensity"),
    ("angular_luminance", "cd/m^2", "luminance averaged over the target"),
]
#: Where each map's photons per bin are, when it has its own.
HITS = {"flux": "hits", "angular": "angular_hits", "luminance": "luminance_hits"}


def _need(module: str, what: str):
    try:
        return __import__(module)
    except ImportError as e:
        raise ImportError(
            f"{what} needs {module}: pip install 'blutrace[study]' (or pip install {module})"
        ) from e


def summary_attributes(summary: Mapping[str, Any]) -> dict[str, Any]:
    """The summary's scalars (numbers, str, bool) flattened to ``section_key`` names;
    lists and undefined values (None) are left out, as netCDF attributes cannot hold them.
    """
    out: dict[str, Any] = {}

    def walk(prefix: str, v: Any) -> None:
        if isinstance(v, Mapping):
            for k, x in v.items():
                walk(f"{prefix}_{k}" if prefix else str(k), x)
        elif isinstance(v, (bool, int, float, str)):
            out[prefix] = v

    walk("", summary)
    return out


def run_to_xarray(run):
    """``Run.to_xarray()``: see its docstring."""
    xr = _need("xarray", "Run.to_xarray")
    coords = {
        "x_mm": ("x_mm", run.x_mm, {"units": "mm", "long_name": "bin centre along detector u"}),
        "y_mm": ("y_mm", run.y_mm, {"units": "mm", "long_name": "bin centre along detector v"}),
        "theta_deg": ("theta_deg", run.theta_deg, {"units": "deg", "long_name": "polar angle"}),
        "phi_deg": ("phi_deg", run.phi_deg, {"units": "deg", "long_name": "azimuth from u"}),
    }
    data = {}

    def add(name, dims, unit, what):
        value = getattr(run, name)
        if value is None:
            return
        data[name] = (dims, value, {"units": unit, "long_name": what})
        data[f"{name}_stderr"] = (
            dims, getattr(run, f"{name}_stderr"), {"units": unit, "long_name": f"standard error of {name}"},
        )
        if name in HITS:
            data[HITS[name]] = (dims, getattr(run, HITS[name]), {"long_name": f"photons per bin of {name}"})

    for name, unit, what in FLUX_MAPS:
        add(name, ("y_mm", "x_mm"), unit, what)
    for name, unit, what in ANGULAR_MAPS:
        add(name, ("theta_deg", "phi_deg"), unit, what)
    if run.stokes is not None:
        dims = ("component", "y_mm", "x_mm")
        coords["component"] = ("component", ["S0", "S1", "S2", "S3"])
        data["stokes"] = (dims, run.stokes, {"units": "W/mm^2", "long_name": "Stokes vector per bin"})
        data["stokes_stderr"] = (dims, run.stokes_stderr, {"units": "W/mm^2"})
    return xr.Dataset(data, coords=coords, attrs=summary_attributes(run.summary))


def metrics(summary: Mapping[str, Any]) -> dict[str, float]:
    """Every scalar metric of a summary with its standard error (``name``,
    ``name_stderr``); undefined values are NaN."""
    nan = float("nan")

    def num(v):
        return nan if v is None else float(v)

    out = {
        "efficiency": num(summary["extraction_efficiency"]),
        "efficiency_stderr": num(summary["extraction_efficiency_stderr"]),
    }
    for k, v in summary["uniformity"].items():
        out[k] = num(v)
        out[f"{k}_stderr"] = num(summary["uniformity_stderr"][k])
    out["cv_debiased"] = num(summary["cv_debiased"])
    out["cv_debiased_stderr"] = num(summary["cv_debiased_stderr"])
    out["cv_noise_floor"] = num(summary["cv_noise_floor"])
    lum = summary.get("luminance")
    if lum:
        out["luminance_on_axis_cd_m2"] = num(lum["on_axis_cd_m2"])
        out["luminance_on_axis_cd_m2_stderr"] = num(lum["on_axis_stderr_cd_m2"])
    for section in ("luminance_map", "color", "polarization"):
        for k, v in (summary.get(section) or {}).items():
            if isinstance(v, Mapping) and "value" in v:
                out[f"{section}_{k}"] = num(v["value"])
                out[f"{section}_{k}_stderr"] = num(v["stderr"])
    return out


def _designs(vary: Mapping[str, Iterable], zipped: bool) -> tuple[list[str], list[tuple]]:
    if not isinstance(vary, Mapping) or not vary:
        raise TypeError(f"vary must be a non-empty dict {{key path: values}}, got {vary!r}")
    keys = [str(k) for k in vary]
    values = []
    for k, v in vary.items():
        v = list(np.asarray(v).tolist()) if isinstance(v, np.ndarray) else list(v)
        if not v:
            raise ValueError(f"vary[{k!r}] has no values")
        values.append(v)
    if zipped:
        lengths = {len(v) for v in values}
        if len(lengths) != 1:
            raise ValueError(f"vary: zipped lists must have one length, got {sorted(lengths)}")
        return keys, list(zip(*values))
    return keys, list(itertools.product(*values))


def trace_design(scene, keys, values, photons, seed, threads):
    """Trace one design of a sweep: ``scene`` with ``keys`` set to ``values``; its row."""
    design = scene.copy()
    for k, v in zip(keys, values):
        design.set(k, v)
    run = design.trace(photons=photons, seed=seed, threads=threads)
    row = dict(zip(keys, values))
    row.update(metrics(run.summary))
    row["photons"] = run.photons
    row["runtime_s"] = run.runtime_s
    return row


def sweep(scene, vary, photons=None, seed=None, executor=None, zipped=False, threads=None):
    """Trace every design of ``vary`` and return a pandas DataFrame, one row per design.

    ``vary`` maps key paths (as ``Scene.set``'s) to values: every combination is traced
    (the grid), or with ``zipped=True`` the i-th values of each list together. Columns:
    the varied keys, then every summary metric with its standard error (``efficiency``,
    ``efficiency_stderr``, ``mean``, ``cv``, ``cv_debiased``, ``nine_point_min_over_max``,
    ..., the luminance, colour and polarization estimates when measured), ``photons`` and
    ``runtime_s``. Every design uses the same ``seed`` (common random numbers: differences
    between designs are less noisy than their values). With an ``executor``
    (``concurrent.futures``, e.g. a ProcessPoolExecutor) the designs run in parallel;
    rows keep the designs' order. Needs pandas (``pip install 'blutrace[study]'``).
    """
    pd = _need("pandas", "blutrace.sweep")
    from ._native import Scene

    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a blutrace.Scene, got {type(scene).__name__}")
    keys, designs = _designs(vary, zipped)
    args = [(scene, keys, d, photons, seed, threads) for d in designs]
    if executor is None:
        rows = [trace_design(*a) for a in args]
    else:
        futures = [executor.submit(trace_design, *a) for a in args]
        rows = [f.result() for f in futures]
    return pd.DataFrame(rows)


def _fmt(v, e=None) -> str:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "n/a"
    if e is None or (isinstance(e, float) and math.isnan(e)):
        return f"{v:.4g}"
    return f"{v:.4g} &plusmn; {e:.2g}"


def _svg_map(values: np.ndarray, width: int = 240) -> str:
    """A small grey-scale picture of a map (row 0 at the bottom, as on the detector)."""
    a = np.nan_to_num(np.asarray(values, dtype=float))
    step = max(1, math.ceil(max(a.shape) / 48))
    ny, nx = a.shape[0] // step or 1, a.shape[1] // step or 1
    a = a[: ny * step, : nx * step].reshape(ny, step, nx, step).mean(axis=(1, 3))
    top = a.max() or 1.0
    cell = width / nx
    rects = []
    for iy in range(ny):
        for ix in range(nx):
            g = int(255 * max(a[iy, ix], 0) / top)
            y = (ny - 1 - iy) * cell
            rects.append(
                f'<rect x="{ix * cell:.1f}" y="{y:.1f}" width="{cell + 0.5:.1f}" '
                f'height="{cell + 0.5:.1f}" fill="rgb({g},{g},{g})"/>'
            )
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{ny * cell:.0f}">'
        + "".join(rects) + "</svg>"
    )


def run_html(run) -> str:
    """``Run._repr_html_``: key metrics with their errors and a small flux map."""
    s = run.summary
    u, ue = s["uniformity"], s["uniformity_stderr"]
    rows = [
        ("photons", f"{run.photons:,}"),
        ("efficiency", _fmt(s["extraction_efficiency"], s["extraction_efficiency_stderr"])),
        ("mean flux (W/mm&sup2;)", _fmt(u["mean"], ue["mean"])),
        ("cv debiased", _fmt(s["cv_debiased"], s["cv_debiased_stderr"])),
        ("9-point min/max", _fmt(u["nine_point_min_over_max"], ue["nine_point_min_over_max"])),
        ("13-point min/max", _fmt(u["thirteen_point_min_over_max"], ue["thirteen_point_min_over_max"])),
    ]
    if s.get("luminance"):
        lum = s["luminance"]
        rows.append(("on-axis luminance (cd/m&sup2;)", _fmt(lum["on_axis_cd_m2"], lum["on_axis_stderr_cd_m2"])))
    if s.get("color"):
        c = s["color"]
        rows.append(("u', v'", f"{_fmt(c['u_prime']['value'])}, {_fmt(c['v_prime']['value'])}"))
    table = "".join(f"<tr><td>{k}</td><td>{v}</td></tr>" for k, v in rows)
    size = s["detector"]["size_mm"]
    return (
        f"<div><b>Run</b> of {html.escape(str(s['scene']))} (seed {run.seed})"
        f"<table>{table}</table>{_svg_map(run.flux)}"
        f"<div>flux map, {size[0]:g} &times; {size[1]:g} mm</div></div>"
    )


def scene_html(scene) -> str:
    """``Scene._repr_html_``: name, file, detector and sources."""
    d = scene.source.get("detector", {})
    n_sources = len(scene.source.get("sources", []))
    rows = [
        ("file", html.escape(scene.path)),
        ("detector size (mm)", html.escape(str(d.get("size_mm", "?")))),
        ("detector bins", html.escape(str(d.get("bins", "?")))),
        ("sources", str(n_sources)),
        ("photons, seed", f"{scene.default_photons:,}, {scene.default_seed}"),
        ("content hash", scene.content_hash),
    ]
    rows += [("warning", html.escape(w)) for w in scene.warnings]
    table = "".join(f"<tr><td>{k}</td><td>{v}</td></tr>" for k, v in rows)
    return f"<div><b>Scene</b> {html.escape(scene.name)}<table>{table}</table></div>"
