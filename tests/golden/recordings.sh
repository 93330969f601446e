#!/usr/bin/env bash
# What the viewer is given, before and after a change of structure: every command's recording
# (each preset 30 s, calibrate, tpr, selfcal, allan, modulation, a table replay, a calibration log,
# a strapdown replay), /events dropped (it holds wall times), compacted by `rerun rrd optimize`,
# then compared recording by recording with `rerun rrd compare --unordered` (the data, not the
# chunking). A developer's check, not a CI test (it needs the viewer's `rerun` CLI):
#   tests/golden/recordings.sh capture OLD_BIN /tmp/rec-before
#   tests/golden/recordings.sh capture NEW_BIN /tmp/rec-after
#   tests/golden/recordings.sh compare /tmp/rec-before /tmp/rec-after
# Two captures of the same binary differ only where a value is NaN (a NaN never equals itself:
# pure coning's log10 plot at t = 0) and in documents that state a wall time (docs/selfcal, docs/tpr).
set -euo pipefail
R=${RERUN:-$HOME/.cache/rinscope-viewer/bin/rerun}
presets=$(realpath "$(dirname "$0")/../../assets/scenarios")
case "$1" in
capture)
  bin=$(realpath "$2"); out=$(realpath -m "$3"); mkdir -p "$out"; rm -f "$out"/*.rrd "$out"/*.diff
  # A fixed folder: paths named in the documents are the same in every capture.
  work=/tmp/rinscope-recordings-golden; rm -rf "$work"; mkdir -p "$work"; cd "$work"
  keep() { "$R" rrd filter --drop-entity /events "$work/$1.rrd" 2>/dev/null | "$R" rrd optimize 2>/dev/null >"$out/$1.rrd"; }
  for p in $("$bin" scenarios | grep -v '^ ' | awk '{print $1}'); do
    "$bin" run --scenario "$p" --duration-s 30 --save "$work/run-$p.rrd" >/dev/null 2>&1; keep "run-$p"
  done
  "$bin" calibrate --save cal.rrd >/dev/null 2>&1; keep cal
  "$bin" tpr --save tpr.rrd >/dev/null 2>&1; keep tpr
  "$bin" selfcal --navigate-hours 0.1 --save selfcal.rrd >/dev/null 2>&1; keep selfcal
  "$bin" allan --duration-s 600 --save allan.rrd >/dev/null 2>&1; keep allan
  "$bin" modulation --hours 0.2 --save modulation.rrd >/dev/null 2>&1; keep modulation
  sed -E "s/^duration_s = [0-9.]+/duration_s = 300/" "$presets/dual-axis-16-position.toml" >rot.toml
  "$bin" export-log --config rot.toml --out rot-log >/dev/null 2>&1
  "$bin" replay rot-log --save replay.rrd >/dev/null 2>&1; keep replay
  "$bin" export-log --scenario jiang2017-calibration --out cal-log >/dev/null 2>&1
  "$bin" calibrate --log cal-log --save cal-log.rrd >/dev/null 2>&1; keep cal-log
  sed -E "s/^duration_s = [0-9.]+/duration_s = 300/" "$presets/static-imu-10h.toml" >st.toml
  "$bin" export-log --config st.toml --out st-log >/dev/null 2>&1
  "$bin" replay --imu st-log/imu.csv --position 45 10 0 --save strap.rrd >/dev/null 2>&1; keep strap
  echo "$(ls "$out" | wc -l) recordings in $out"
  ;;
compare)
  for f in "$2"/*.rrd; do
    n=$(basename "$f")
    if "$R" rrd compare --unordered "$f" "$3/$n" >"$3/$n.diff" 2>&1; then echo "same $n"; rm "$3/$n.diff"
    else echo "DIFF $n: $(grep -a 'entity_path' "$3/$n.diff" | sort -u | sed 's/.*entity_path: //; s/ *│//' | tr '\n' ' ')"; fi
  done
  ;;
*) echo "usage: $0 capture BIN OUT | compare BEFORE AFTER" >&2; exit 2 ;;
esac
