"""Shards as values: traced anywhere, pickled, merged bit for bit into one run."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import blutrace as bt

N = 120_000


@pytest.fixture(scope="module")
def single(box) -> bt.Run:
    return box.trace(photons=N, seed=9)


@pytest.fixture(scope="module")
def shards(box) -> list:
    return [box.trace(photons=N, seed=9, shard=(k, 4)) for k in range(4)]


def same_maps(a: bt.Run, b: bt.Run) -> None:
    for name in ["flux", "flux_stderr", "hits", "angular", "angular_stderr", "angular_hits"]:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_four_shards_merge_to_one_run_bit_for_bit(single, shards):
    assert [s.shard for s in shards] == [(k, 4) for k in range(4)]
    assert sum(s.photons for s in shards) == N
    merged = bt.merge(shards)
    assert merged.photons == N and merged.shard is None
    same_maps(merged, single)
    assert merged.efficiency == single.efficiency
    a, b = merged.summary, single.summary
    assert a["uniformity"] == b["uniformity"] and a["ledger"] == b["ledger"]


def test_the_order_of_the_shards_does_not_matter(single, shards):
    same_maps(bt.merge(shards[::-1]), single)


def test_shards_pickle_with_their_tallies(single, shards):
    back = [pickle.loads(pickle.dumps(s)) for s in shards]
    for a, b in zip(back, shards):
        assert a.shard == b.shard and a.photons == b.photons
        same_maps(a, b)
    same_maps(bt.merge(back), single)


def test_a_missing_shard_is_an_error_unless_partial(shards):
    with pytest.raises(ValueError, match="shards missing: 2/4"):
        bt.merge([shards[0], shards[1], shards[3]])
    partial = bt.merge([shards[0], shards[1], shards[3]], partial=True)
    assert partial.photons == N - shards[2].photons


def test_a_shard_given_twice_is_an_error(shards):
    with pytest.raises(ValueError, match="given twice"):
        bt.merge([shards[0], shards[0], shards[1], shards[2], shards[3]])


def test_shards_of_different_runs_do_not_merge(box, shards):
    other = box.trace(photons=N, seed=10, shard=(1, 4))
    with pytest.raises(ValueError, match="seed"):
        bt.merge([shards[0], other])


def test_a_whole_run_is_no_shard(single):
    with pytest.raises(ValueError, match="not a shard run"):
        bt.merge([single])
    with pytest.raises(ValueError, match="at least one"):
        bt.merge([])
