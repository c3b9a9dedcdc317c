"""One run split into shards traced by a process pool, merged bit for bit.

Shards are values: a `Run` traced with `shard=(k, m)` pickles, so any executor that
returns Python objects (concurrent.futures, Dask, Ray) is a cluster runner. The merge
equals a single run of all the photons, bit for bit, which this example checks.

    python examples/shards_process_pool.py [--scene scenes/bench-box] [--photons 4e5]
"""

from __future__ import annotations

import argparse
import concurrent.futures
import pathlib
import sys

import numpy as np

import blutrace as bt

REPO = pathlib.Path(__file__).resolve().parents[2]


def trace_shard(scene: bt.Scene, photons: int, seed: int, k: int, m: int) -> bt.Run:
    """Trace shard k of m in a worker process (one thread each: the pool is the parallelism)."""
    return scene.trace(photons=photons, seed=seed, shard=(k, m), threads=1)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(REPO / "scenes/bench-box"))
    p.add_argument("--photons", type=float, default=4e5)
    p.add_argument("--shards", type=int, default=4)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--out", help="write the merged run's outputs here")
    a = p.parse_args(argv)
    photons = int(a.photons)

    scene = bt.Scene.load(a.scene)
    with concurrent.futures.ProcessPoolExecutor(max_workers=a.workers) as pool:
        futures = [
            pool.submit(trace_shard, scene, photons, a.seed, k, a.shards) for k in range(a.shards)
        ]
        shards = [f.result() for f in futures]
    merged = bt.merge(shards)

    single = scene.trace(photons=photons, seed=a.seed)
    identical = np.array_equal(merged.flux, single.flux) and np.array_equal(
        merged.angular, single.angular
    )
    eff, err = merged.efficiency
    cv = merged.summary["cv_debiased"]
    cv = float("nan") if cv is None else cv  # None: no light on the target
    print(f"{scene.name}: {a.shards} shards of {photons} photons merged")
    print(f"efficiency {eff:.4f} +- {err:.4f}, debiased cv {cv:.4f}")
    print(f"merged == single run, bit for bit: {identical}")
    if a.out:
        for f in merged.write(a.out):
            print(f"wrote {f}")
    return 0 if identical else 1


if __name__ == "__main__":
    sys.exit(main())
