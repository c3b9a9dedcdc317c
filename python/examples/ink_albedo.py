"""Compare ink albedos of a dotted light guide: efficiency and uniformity per albedo.

Scenes are values: each albedo is a copy of the scene with one number changed, traced
with the same seed (common random numbers, so differences are the design's, not noise's).

    python examples/ink_albedo.py [--scene scenes/phone-led] [--albedos 0.7,0.8,0.9]
"""

from __future__ import annotations

import argparse
import pathlib
import sys

import blutrace as bt

REPO = pathlib.Path(__file__).resolve().parents[2]


def dotted_tag(scene: bt.Scene) -> str:
    """The scene's dots surface (the one with an ink albedo)."""
    for tag, surface in scene.source["surfaces"].items():
        if surface.get("model") == "dots":
            return tag
    raise SystemExit(f"{scene.path}: no dots surface")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(REPO / "scenes/phone-led"))
    p.add_argument("--photons", type=float, default=4e5)
    p.add_argument("--albedos", default="0.7,0.8,0.9")
    a = p.parse_args(argv)

    scene = bt.Scene.load(a.scene)
    key = f"surfaces.{dotted_tag(scene)}.ink_albedo"
    print(f"{scene.name}: {key}")
    print("albedo  efficiency  stderr   cv_debiased  mean_flux_W/mm2")
    for albedo in (float(x) for x in a.albedos.split(",")):
        design = scene.copy()
        design.set(key, albedo)
        run = design.trace(photons=a.photons, seed=1)
        eff, err = run.efficiency
        cv = run.summary["cv_debiased"]
        cv = float("nan") if cv is None else cv  # None: no light on the target
        print(f"{albedo:6.2f}  {eff:10.4f}  {err:.4f}  {cv:11.4f}  {run.flux.mean():.4e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
