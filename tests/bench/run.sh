#!/usr/bin/env bash
# Speed against the fastest peer, printed and never asserted (these machines are shared and noisy: a
# speed target is a benchmark, not a test; docs/benchmarks.md): `rinscope bench --peer pyins`, whole
# processes alternated with python-ins 1.0.1 on the same 2 M-sample streams, 3 rounds (median and range), and the recording
# size per simulated hour of every preset (`bench --only recorded`), and the designer's search time.
#
#   tests/bench/run.sh [RINSCOPE]
#
# pyins (and numba, numpy, pandas, scipy as locked in assets/bench/pyins/requirements-lock.txt) goes into
# a venv kept at $RINSCOPE_PYINS_VENV (default ~/.cache/pyins-venv), downloaded once. RINSCOPE_SKIP_BENCH=1
# skips all this and says so; a peer that cannot be installed is said and skipped. Exit 0 whatever the
# figures (a command that fails is printed and is a failure: the benchmark itself must run).
set -euo pipefail
if [[ ${RINSCOPE_SKIP_BENCH:-} == 1 ]]; then
  echo "bench: SKIPPED (RINSCOPE_SKIP_BENCH=1): no ratios against pyins printed"
  exit 0
fi
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=$(realpath "${1:-${CARGO_TARGET_DIR:-$HOME/.cache/rinscope-target}/release/rinscope}")
venv=${RINSCOPE_PYINS_VENV:-$HOME/.cache/pyins-venv}
if ! "$venv/bin/python" -c "import pyins, numpy" 2>/dev/null; then
  { python3 -m venv "$venv" && "$venv/bin/pip" install -q -r "$root/assets/bench/pyins/requirements-lock.txt"; } >/dev/null 2>&1 ||
    echo "bench: python-ins 1.0.1 could not be installed into $venv (offline?): the peer comparison is skipped"
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
if "$venv/bin/python" -c "import pyins" 2>/dev/null; then
  "$bin" bench --peer pyins --python "$venv/bin/python" --rounds 3 2>&1 | grep -v "round [0-9] of 3" | sed 's/^/bench: /'
fi
"$bin" bench --only recorded 2>&1 | grep "recorded 1 h" | sed 's/^/bench: /'
# Issue 34's search target (1000 candidate schemes under 10 minutes on two cores): the default design
# (budget-dual-axis-16, 72 h, 1000 sequences ranked by the averaged model), the exact confirmation cut
# to the best sequence and one seed; its own time line (responses, model, exact, all).
"$bin" design --confirm 1 --seeds 1 --save "$work/design.rrd" 2>/dev/null | grep "^time:\|^designed:" | sed 's/^/bench: design: /'
