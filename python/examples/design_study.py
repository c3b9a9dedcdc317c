"""A design study as a notebook would run it: sweep the ink's albedo and the lamp's
power with bt.sweep into a pandas DataFrame, pick the most uniform design, and plot its
flux map with axes in mm (from run.to_xarray()).

    python design_study.py --photons 2e5 --out study/

Runs from an installed package (the scene is bundled: bt.scenes.path). Needs the
extras: pip install 'blutrace[study,plot]'.
"""

from __future__ import annotations

import argparse
import pathlib

import blutrace as bt

ALBEDO = "surfaces.lgp_back.ink_albedo"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="bench-box", help="a bundled scene (bt.scenes.names())")
    p.add_argument("--photons", type=float, default=2e5)
    p.add_argument("--albedos", default="0.6,0.75,0.9")
    p.add_argument("--out", required=True, help="folder for study.csv and flux_mm.png")
    a = p.parse_args(argv)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)

    # In [1]: the scene and the grid of designs.
    scene = bt.Scene.load(bt.scenes.path(a.scene))
    albedos = [float(x) for x in a.albedos.split(",")]

    # In [2]: one row per design: the varied key, every metric with its standard error.
    df = bt.sweep(scene, {ALBEDO: albedos}, photons=a.photons, seed=1)
    cols = [ALBEDO, "efficiency", "efficiency_stderr", "cv_debiased", "cv_debiased_stderr"]
    print(df[cols].to_string(index=False))
    df.to_csv(out / "study.csv", index=False)

    # In [3]: the most uniform design, traced again to keep its maps.
    best = df.loc[df["cv_debiased"].idxmin(), ALBEDO]
    design = scene.copy()
    design.set(ALBEDO, float(best))
    run = design.trace(photons=a.photons, seed=1)
    print(f"most uniform: {ALBEDO} = {best}")

    # In [4]: the flux map on its coordinates in mm.
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ds = run.to_xarray()
    fig, ax = plt.subplots(figsize=(6, 4))
    ds["flux"].plot(ax=ax, x="x_mm", y="y_mm", cbar_kwargs={"label": "irradiance (W/mm²)"})
    ax.set_aspect("equal")
    ax.set_title(f"{scene.name}, ink albedo {best}")
    fig.savefig(out / "flux_mm.png", dpi=100)
    print(f"wrote {out / 'flux_mm.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
