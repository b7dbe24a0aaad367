"""One bootstrap, scipy's (issue 41): ``headless.analysis.stats`` resamples with
``scipy.stats.bootstrap`` and gives the same intervals, bit for bit, as the hand-written
bootstrap it replaced, so Table 3, the paired tables and ``stealth mechanics`` keep their
numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from headless.analysis.stats import BOOTSTRAP_RESAMPLES, bootstrap_ci, label_rng, percentile_ci


def _by_hand(values: np.ndarray, rng: np.random.Generator, resamples: int = BOOTSTRAP_RESAMPLES
             ) -> tuple[float, float]:
    """The bootstrap the tables were made with before scipy's (issue 36's notes)."""
    means = values[rng.integers(0, len(values), size=(resamples, len(values)))].mean(axis=1)
    low, high = np.percentile(means, [2.5, 97.5])
    return float(low), float(high)


SAMPLES = {
    "binary": (np.random.default_rng(1).random(200) < 0.3).astype(float),  # capture rates
    "times": np.round(np.random.default_rng(2).uniform(0, 60, 250), 2),
    "counts": np.random.default_rng(3).poisson(4, 97).astype(float),
    "two": np.array([0.0, 1.0]),
    "equal": np.full(40, 2.5),
}


@pytest.mark.parametrize("name", list(SAMPLES))
def test_scipy_bootstrap_gives_the_hand_written_intervals_bit_for_bit(name: str) -> None:
    values = SAMPLES[name]
    label = f"grid/pf/maxmin/{name}"
    assert bootstrap_ci(values, label) == _by_hand(values, label_rng(label))
    shared, again = np.random.default_rng(7), np.random.default_rng(7)  # mechanics' way
    for _ in range(3):
        assert percentile_ci(values, shared, 500) == _by_hand(values, again, 500)


def test_a_shared_generator_advances_alike_after_one_value() -> None:
    shared, again = np.random.default_rng(9), np.random.default_rng(9)
    assert percentile_ci([4.0], shared) == (4.0, 4.0) == _by_hand(np.array([4.0]), again)
    values = SAMPLES["times"]
    assert percentile_ci(values, shared) == _by_hand(values, again)
    assert all(math.isnan(v) for v in percentile_ci([], shared))


def test_the_interval_is_scipys_percentile_interval_read_at_exactly_2_5_and_97_5() -> None:
    values = SAMPLES["times"]
    ours = bootstrap_ci(values, "x")
    theirs = stats.bootstrap((values,), np.mean, n_resamples=BOOTSTRAP_RESAMPLES,
                             method="percentile", rng=label_rng("x")).confidence_interval
    assert ours[0] <= np.mean(values) <= ours[1]
    assert ours == pytest.approx((theirs.low, theirs.high), abs=1e-9)
