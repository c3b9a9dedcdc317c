"""Sweep the lamp height of a direct-lit backlight: uniformity and efficiency per height.

Every lamp's height is one key path with a `*` (`sources.*.center.2`, as `blutrace
optimize --vary` names it); each design is a copy of the scene with that value set. With
matplotlib installed, `--out DIR` also writes `sweep.png` (cv and efficiency against
height).

    python examples/lamp_height_sweep.py [--photons 2e5] [--heights 4,6,8,10,12] [--out DIR]
"""

from __future__ import annotations

import argparse
import pathlib
import sys

import blutrace as bt

REPO = pathlib.Path(__file__).resolve().parents[2]
KEY = "sources.*.center.2"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(REPO / "scenes/direct-lit"))
    p.add_argument("--photons", type=float, default=2e5)
    p.add_argument("--heights", default="4,6,8,10,12", help="lamp heights (mm), comma-separated")
    p.add_argument("--out", help="folder for sweep.csv (and sweep.png with matplotlib)")
    a = p.parse_args(argv)

    scene = bt.Scene.load(a.scene)
    rows = []
    print(f"{scene.name}: {KEY} was {scene.get(KEY)} mm")
    print("height_mm  cv_debiased  efficiency  stderr")
    for h in (float(x) for x in a.heights.split(",")):
        design = scene.copy()
        design.set(KEY, h)
        run = design.trace(photons=a.photons, seed=1)
        eff, err = run.efficiency
        cv = run.summary["cv_debiased"]
        cv = float("nan") if cv is None else cv  # None: no light on the target
        rows.append((h, cv, eff, err))
        print(f"{h:9.2f}  {cv:11.4f}  {eff:10.4f}  {err:.4f}")

    if a.out:
        out = pathlib.Path(a.out)
        out.mkdir(parents=True, exist_ok=True)
        lines = ["height_mm,cv_debiased,efficiency,efficiency_stderr"]
        lines += [",".join(f"{x:.6g}" for x in r) for r in rows]
        (out / "sweep.csv").write_text("\n".join(lines) + "\n")
        try:
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("matplotlib not installed: no plot")
            return 0
        fig, ax = plt.subplots(figsize=(6, 4))
        heights = [r[0] for r in rows]
        ax.plot(heights, [r[1] for r in rows], "o-", label="cv (debiased)")
        ax.set_xlabel("lamp height (mm)")
        ax.set_ylabel("cv")
        ax2 = ax.twinx()
        ax2.errorbar(heights, [r[2] for r in rows], yerr=[r[3] for r in rows], fmt="s--",
                     color="tab:orange", label="efficiency")
        ax2.set_ylabel("efficiency")
        fig.legend(loc="upper center")
        fig.tight_layout()
        fig.savefig(out / "sweep.png", dpi=100)
        print(f"wrote {out / 'sweep.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
