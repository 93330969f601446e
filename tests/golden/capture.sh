#!/usr/bin/env bash
# The documents every command writes (--summary-json / --json), on every preset and on a log set,
# normalised (wall times, memory, file sizes and paths removed) into OUT/<name>.json. tests/golden.rs
# runs it with the binary under test and compares with tests/golden/expected/, which this script
# wrote with the program as it was before commands got their owners in app/ (issue 31): a change of
# structure must not change a number a user sees. Regenerate (only for an intended change of output):
#   tests/golden/capture.sh target/release/rinscope tests/golden/expected
# Short durations keep it to about a minute on 2 cores; each command's whole path still runs.
set -euo pipefail
bin=$(realpath "$1"); out=$(realpath -m "$2"); presets=$(realpath "$(dirname "$0")/../../assets/scenarios")
mkdir -p "$out"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cd "$work"
norm() {  # norm NAME FILE: the document without what differs between runs of the same input
  python3 - "$2" "$out/$1.json" <<'EOF'
import json, re, sys
VARIES = re.compile(r"(wall|rss|elapsed|recording_path|recording_bytes|threads|per_s$|per_second|speed|cpu|^analysis_s$|^gather_s$|^estimation_s$)", re.I)
def clean(v):
    if isinstance(v, dict):
        return {k: clean(x) for k, x in v.items() if not VARIES.search(k)}
    if isinstance(v, list):
        return [clean(x) for x in v]
    if isinstance(v, str):
        return re.sub(r"/tmp/[^\s\"']*", "<tmp>", v)
    return v
doc = json.load(open(sys.argv[1]))
json.dump(clean(doc), open(sys.argv[2], "w"), indent=1, sort_keys=True)
open(sys.argv[2], "a").write("\n")
EOF
}
# run: every preset, 60 simulated seconds (the embedded default too).
for p in $("$bin" scenarios | grep -v '^ ' | awk '{print $1}'); do
  "$bin" run --scenario "$p" --duration-s 60 --save "$work/run-$p.rrd" --summary-json "$work/run-$p.json" >/dev/null
  norm "run-$p" "$work/run-$p.json"
done
"$bin" calibrate --save "$work/cal.rrd" --json "$work/calibrate.json" >/dev/null
norm calibrate "$work/calibrate.json"
"$bin" montecarlo --runs 4 --json "$work/montecarlo.json" >/dev/null 2>&1
norm montecarlo "$work/montecarlo.json"
"$bin" tpr --save "$work/tpr.rrd" --json "$work/tpr.json" >/dev/null
norm tpr "$work/tpr.json"
"$bin" selfcal --navigate-hours 0.5 --save "$work/selfcal.rrd" --json "$work/selfcal.json" >/dev/null
norm selfcal "$work/selfcal.json"
"$bin" selfcal --plan --no-recording --json "$work/selfcal-plan.json" >/dev/null
norm selfcal-plan "$work/selfcal-plan.json"
"$bin" allan --duration-s 600 --save "$work/allan.rrd" --json "$work/allan.json" >/dev/null
norm allan "$work/allan.json"
# A log set of the calibration and one of a rotating table, read back by every command that reads logs.
"$bin" export-log --scenario jiang2017-calibration --out "$work/cal-log" >/dev/null
"$bin" calibrate --log "$work/cal-log" --save "$work/cal-log.rrd" --json "$work/calibrate-log.json" >/dev/null
norm calibrate-log "$work/calibrate-log.json"
shorter() {  # shorter PRESET SECONDS: the preset as a file that runs SECONDS
  sed -E "s/^duration_s = [0-9.]+/duration_s = $2/" "$presets/$1.toml" >"$work/$1-short.toml"
  echo "$work/$1-short.toml"
}
"$bin" export-log --config "$(shorter dual-axis-16-position 600)" --out "$work/rot-log" >/dev/null
"$bin" replay "$work/rot-log" --save "$work/replay.rrd" --summary-json "$work/replay.json" >/dev/null
norm replay "$work/replay.json"
"$bin" export-log --config "$(shorter static-imu-10h 600)" --format npy --out "$work/static-log" >/dev/null
"$bin" allan "$work/static-log" --no-recording --json "$work/allan-log.json" >/dev/null
norm allan-log "$work/allan-log.json"
"$bin" export-log --scenario selfcal-nav-grade --format npy --out "$work/selfcal-log" >/dev/null
"$bin" selfcal --log "$work/selfcal-log" --no-recording --json "$work/selfcal-log.json" >/dev/null
norm selfcal-log "$work/selfcal-log.json"
