"""Summary statistics shared by the experiment report scripts: mean +- sd and percentile
bootstrap confidence intervals of a statistic of two independent groups (seeded, groups
resampled independently), and the exact interval of a binomial rate. Needs numpy."""
import math

import numpy as np


def mean_sd(v, digits):
    """'mean ± sd' (sample sd, ddof 1; 0 for one value), '–' for no values."""
    v = np.asarray(v, dtype=float)
    if len(v) == 0:
        return "–"
    sd = np.std(v, ddof=1) if len(v) > 1 else 0.0
    return f"{np.mean(v):.{digits}f} ± {sd:.{digits}f}"


def bootstrap(a, b, stat, resamples, rng, level=0.95):
    """stat(a, b) and its percentile bootstrap interval at \\p level, or None if a group has fewer
    than two values. \\p stat takes the two groups as 2-D arrays, one resample per row (shape
    (resamples, n)), and returns one value per row; the estimate is stat of the groups as given
    (one row each)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if len(a) < 2 or len(b) < 2:
        return None
    ia = rng.integers(0, len(a), size=(resamples, len(a)))
    ib = rng.integers(0, len(b), size=(resamples, len(b)))
    d = stat(a[ia], b[ib])
    d = d[np.isfinite(d)]
    if len(d) == 0:
        return None
    tail = (1 - level) / 2 * 100
    lo, hi = np.percentile(d, [tail, 100 - tail])
    return float(stat(a[None, :], b[None, :])[0]), float(lo), float(hi)


def diff_of_means(a, b):
    return a.mean(axis=1) - b.mean(axis=1)


def relative_reduction(a, b):
    """1 - mean(a) / mean(b): the share by which a's mean lies below b's (nan where b's mean is 0)."""
    mb = b.mean(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(mb != 0, 1 - a.mean(axis=1) / mb, np.nan)


def bootstrap_diff(a, b, resamples, rng):
    """Mean(a) - mean(b) and its 95 % percentile bootstrap interval (None for groups under two)."""
    return bootstrap(a, b, diff_of_means, resamples, rng)


def bootstrap_mean(a, resamples, rng, level=0.95):
    """Mean(a) and its percentile bootstrap interval (None for fewer than two values)."""
    a = np.asarray(a, dtype=float)
    if len(a) < 2:
        return None
    m = a[rng.integers(0, len(a), size=(resamples, len(a)))].mean(axis=1)
    tail = (1 - level) / 2 * 100
    lo, hi = np.percentile(m, [tail, 100 - tail])
    return float(a.mean()), float(lo), float(hi)


def binomial_cdf(k, n, p):
    """P(X <= k) for X ~ Binomial(n, p)."""
    return sum(math.comb(n, i) * p**i * (1 - p)**(n - i) for i in range(k + 1))


def clopper_pearson(k, n, level=0.95):
    """The exact two-sided interval of a binomial rate with k successes in n trials (bisection on
    the binomial distribution; 0 and 1 at the ends)."""
    if n <= 0 or not 0 <= k <= n:
        raise ValueError(f"clopper_pearson: need 0 <= k <= n and n > 0, got k={k}, n={n}")
    alpha = (1 - level) / 2

    def solve(f):  # f increasing in p on [0, 1]; the p where f(p) = 0
        lo, hi = 0.0, 1.0
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            if f(mid) < 0:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    lower = 0.0 if k == 0 else solve(lambda p: (1 - binomial_cdf(k - 1, n, p)) - alpha)
    upper = 1.0 if k == n else solve(lambda p: alpha - binomial_cdf(k, n, p))
    return lower, upper
