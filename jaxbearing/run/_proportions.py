"""Binomial proportions with confidence bounds: counts of revolutions that reached the corner,
also where the revolutions come in dependent clusters (the members of a settled ensemble).
Pure host-side numpy/scipy (docs/model.md 16, "Corner-contact risk")."""

from __future__ import annotations

import math

import numpy as np
from scipy import stats as _sp_stats

from ..io import require

#: default one-sided confidence of the bounds
CORNER_RISK_CONFIDENCE = 0.95


def revolutions_needed(level: float, confidence: float = CORNER_RISK_CONFIDENCE) -> int:
    """Revolutions without corner contact that bound the per-revolution probability at `level`
    by counting alone (independent revolutions): the smallest n with 1 - (1 - c)^(1/n) <= level,
    n = ceil(ln(1 - c) / ln(1 - level)) (2995 for 1e-3 at 95 %)."""
    require("level", level, lambda v: (v > 0) & (v < 1), "in (0, 1) (probability per revolution)")
    require("confidence", confidence, lambda v: (v > 0) & (v < 1), "in (0, 1)")
    n = math.log1p(-confidence) / math.log1p(-level)
    n_int = math.ceil(n - 1e-9)
    return int(n_int if -math.expm1(math.log1p(-confidence) / n_int) <= level else n_int + 1)


def clopper_pearson(count: float, trials: float, confidence: float = CORNER_RISK_CONFIDENCE) -> tuple:
    """One-sided Clopper-Pearson bounds (lower, upper), each at `confidence`, of a binomial
    probability seen `count` times in `trials` (real counts allowed, for effective samples):
    lower = B^-1(1 - c; x, n - x + 1) (0 for x = 0), upper = B^-1(c; x + 1, n - x) (1 for x = n),
    B^-1 the beta quantile (Clopper & Pearson 1934)."""
    x, n = float(count), float(trials)
    lower = 0.0 if x <= 0 else float(_sp_stats.beta.ppf(1 - confidence, x, n - x + 1))
    upper = 1.0 if x >= n else float(_sp_stats.beta.ppf(confidence, x + 1, n - x))
    return lower, upper


def cluster_design_effect(counts, sizes) -> float:
    """The design effect of a proportion whose trials come in independent clusters (members):
    counts x_k of sizes n_k, p^ = sum x / sum n, var = N/(N-1) sum (x_k - p^ n_k)^2 / n^2 (the
    ratio estimator's between-cluster variance; Cochran 1977, Sampling Techniques, sec. 6.11),
    deff = var / (p^(1 - p^)/n), at least 1; 1 when it cannot be estimated (one cluster, p^ in
    {0, 1})."""
    x, m = np.asarray(counts, float), np.asarray(sizes, float)
    keep = m > 0
    x, m = x[keep], m[keep]
    n, clusters = float(m.sum()), int(m.size)
    p = float(x.sum() / n) if n else 0.0
    if clusters < 2 or p <= 0 or p >= 1:
        return 1.0
    var = clusters / (clusters - 1) * float(np.sum((x - p * m) ** 2)) / n**2
    return max(1.0, var / (p * (1 - p) / n))
