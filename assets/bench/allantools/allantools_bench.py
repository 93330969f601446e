"""The allantools side of `rinscope bench --peer allantools` (docs/benchmarks.md).

    python3 allantools_bench.py make SERIES.npy N SEED
        writes N samples of a fractional-frequency series (white FM plus a random walk FM, numpy's
        PCG64 generator) as a 1-column float64 .npy: the input both tools read.
    python3 allantools_bench.py run SERIES.npy RATE_HZ ESTIMATOR TAUS_JSON
        loads the series, times allantools.<ESTIMATOR>(y, rate, data_type="freq", taus=...) on the
        τ values of TAUS_JSON (the ones rinscope evaluated), and prints one JSON line: the timed
        region's seconds, the τ and deviations it returned, the peak RSS.
"""
import json
import resource
import sys
import time

import numpy as np


def make(path, n, seed):
    rng = np.random.default_rng(seed)
    white = rng.standard_normal(n) * 1e-11
    walk = np.cumsum(rng.standard_normal(n)) * 1e-14
    np.save(path, (white + walk).reshape(n, 1))


def run(path, rate, estimator, taus_json):
    import allantools

    y = np.load(path)[:, 0].copy()
    with open(taus_json) as f:
        taus = np.array(json.load(f), dtype=float)
    fn = getattr(allantools, estimator)
    t0 = time.perf_counter()
    taus_out, devs, _errs, _ns = fn(y, rate=rate, data_type="freq", taus=taus)
    seconds = time.perf_counter() - t0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(json.dumps({"seconds": seconds, "tau_s": list(map(float, taus_out)), "dev": list(map(float, devs)),
                      "peak_rss_mb": rss, "allantools": allantools.__version__}))


if __name__ == "__main__":
    if sys.argv[1] == "make":
        make(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))
    else:
        run(sys.argv[2], float(sys.argv[3]), sys.argv[4], sys.argv[5])
