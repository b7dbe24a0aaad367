"""Summary statistics of the reports: means, sample std and percentile-bootstrap CIs.

Shared by Table 3 (:mod:`headless.analysis.tables`) and ``stealth mechanics``
(:mod:`headless.mechanics.measures`). The bootstrap is ``scipy.stats.bootstrap``: it draws
its resample indices as one ``integers(0, n, size=(resamples, n))`` matrix from the
generator it is given; :func:`bootstrap_ci` seeds that generator from a label, so a table
cell's interval depends only on its own values and label. The interval is read from
scipy's bootstrap distribution at exactly the 2.5th and 97.5th percentiles: scipy's own
bounds take the quantile at ``(1 - 0.95) / 2`` = 0.025000000000000022, which changed the
last bits of 59 bounds of the ``paper`` table.csv; read here, the tables keep their bits.

>>> bootstrap_ci([2.0, 2.0, 2.0], "x")
(2.0, 2.0)
>>> summarise([1.0, 2.0, 3.0], "x").mean
2.0
"""

from __future__ import annotations

import math
import warnings
import zlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

__all__ = ["BOOTSTRAP_RESAMPLES", "BOOTSTRAP_SEED", "Stat", "bootstrap_ci", "label_rng",
           "mean_or_nan", "percentile_ci", "summarise"]

BOOTSTRAP_RESAMPLES = 2000
"""Resamples of the percentile bootstrap of the mean."""

BOOTSTRAP_SEED = 20240917
"""Root of every labelled bootstrap generator: ``SeedSequence([BOOTSTRAP_SEED, crc32(label)])``."""

Values = Sequence[float] | np.ndarray


@dataclass(frozen=True)
class Stat:
    """Summary of one table cell: n, mean, sample std (ddof=1) and the 95 % CI of the mean."""

    n: int
    mean: float
    std: float
    ci_low: float
    ci_high: float


def percentile_ci(values: Values, rng: np.random.Generator,
                  resamples: int = BOOTSTRAP_RESAMPLES,
                  percentiles: tuple[float, float] = (2.5, 97.5)) -> tuple[float, float]:
    """Percentile bootstrap interval of the mean of ``values``, resampled with ``rng`` by
    ``scipy.stats.bootstrap`` (``(nan, nan)`` for no values).

    One value is its own interval; ``rng`` still advances as for a resample of one, so a
    generator shared by several intervals (``stealth mechanics``) gives the later ones the
    same draws whatever the size of the earlier ones.
    """
    x = np.asarray(values, dtype=np.float64)
    n = len(x)
    if n == 0:
        return (math.nan, math.nan)
    if n == 1:  # scipy refuses a sample of one: every resample's mean is the value
        rng.integers(0, 1, size=(resamples, 1))
        return (float(x[0]), float(x[0]))
    with warnings.catch_warnings():  # NaN values: a NaN interval, as the mean is
        warnings.simplefilter("ignore", stats.DegenerateDataWarning)
        result = stats.bootstrap((x,), np.mean, n_resamples=resamples, vectorized=True,
                                 method="percentile", rng=rng)
    low, high = np.percentile(result.bootstrap_distribution, list(percentiles))
    return (float(low), float(high))


def label_rng(label: str) -> np.random.Generator:
    """``PCG64(SeedSequence([BOOTSTRAP_SEED, zlib.crc32(label)]))``."""
    return np.random.Generator(np.random.PCG64(
        np.random.SeedSequence([BOOTSTRAP_SEED, zlib.crc32(label.encode("utf-8"))])))


def bootstrap_ci(values: Values, label: str, resamples: int = BOOTSTRAP_RESAMPLES,
                 level: float = 0.95) -> tuple[float, float]:
    """Percentile bootstrap confidence interval of the mean with the generator of ``label``."""
    if len(values) == 0:
        return (math.nan, math.nan)
    tail = 100 * (1 - level) / 2
    return percentile_ci(values, label_rng(label), resamples, (tail, 100 - tail))


def mean_or_nan(values: Values) -> float:
    """The mean, NaN for no values."""
    x = np.asarray(values, dtype=np.float64)
    return float(x.mean()) if len(x) else math.nan


def summarise(values: Values, label: str) -> Stat:
    """:class:`Stat` of a list of numbers (NaN/None-free); n = 0 gives NaNs."""
    x = np.asarray(values, dtype=np.float64)
    if len(x) == 0:
        return Stat(0, math.nan, math.nan, math.nan, math.nan)
    std = float(x.std(ddof=1)) if len(x) > 1 else math.nan
    low, high = bootstrap_ci(x, label)
    return Stat(len(x), float(x.mean()), std, low, high)
