"""The Python package's overhead: a 60 s run of the default scenario from Python against the same
run through the library in Rust, alternated in one process on the same input.

    python python/benchmarks/overhead.py [--rounds 40] [--duration-s 60] [--json out.json]

Each round times, in random order:
- rust:       the library's run, timed in Rust from the TOML text to the finished in-memory tables
              (`_rinscope._time_run`: no conversion for Python);
- python:     `rinscope.run(scenario, duration_s=60)` timed in Python: the scenario object's TOML,
              the worker thread and its Ctrl-C watch, the summary dict and the tables as Arrow;
- python+df:  the same and every series made into a pandas DataFrame.
Prints the median time of each and the median and interquartile range of the per-round ratios
(python / rust). The target (issue 24): python within 20 % of rust.
"""
import argparse
import json
import random
import statistics
import sys
import time

import rinscope
from rinscope import _rinscope


def quartiles(values):
    q = statistics.quantiles(values, n=4)
    return q[0], statistics.median(values), q[2]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=40)
    ap.add_argument("--duration-s", type=float, default=60.0)
    ap.add_argument("--json")
    args = ap.parse_args()
    scenario = rinscope.load(rinscope.DEFAULT_SCENARIO)
    toml = scenario.toml

    def rust():
        return _rinscope._time_run(toml, args.duration_s, 1)[0]

    def python():
        t = time.perf_counter()
        rinscope.run(scenario, duration_s=args.duration_s)
        return time.perf_counter() - t

    def python_df():
        t = time.perf_counter()
        r = rinscope.run(scenario, duration_s=args.duration_s)
        for k in r.series:
            r.series[k]
        return time.perf_counter() - t

    kinds = {"rust": rust, "python": python, "python+df": python_df}
    for f in kinds.values():  # warm up
        f()
    times = {k: [] for k in kinds}
    for _ in range(args.rounds):
        order = list(kinds)
        random.shuffle(order)
        for k in order:
            times[k].append(kinds[k]())
    r = rinscope.run(scenario, duration_s=args.duration_s)
    out = {"scenario": rinscope.DEFAULT_SCENARIO, "duration_s": args.duration_s, "rounds": args.rounds, "tables": len(r.series), "python": sys.version.split()[0]}
    print(f"{args.rounds} rounds of a {args.duration_s:g} s run of {rinscope.DEFAULT_SCENARIO} ({r.summary['steps']} steps, {len(r.series)} tables), alternated in random order")
    for k, v in times.items():
        lo, med, hi = quartiles(v)
        out[f"{k}_median_s"] = med
        print(f"  {k:<10} median {med * 1e3:7.2f} ms   (quartiles {lo * 1e3:.2f} .. {hi * 1e3:.2f} ms)")
    for k in ("python", "python+df"):
        ratios = [p / q for p, q in zip(times[k], times["rust"])]
        lo, med, hi = quartiles(ratios)
        out[f"{k}_over_rust"] = {"median": med, "q1": lo, "q3": hi}
        print(f"  {k} / rust: median {med:.3f}  (quartiles {lo:.3f} .. {hi:.3f}; target <= 1.20)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
