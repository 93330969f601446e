#!/usr/bin/env bash
# The class page of `rinscope live --serve-web` in a real browser (headless Chromium, Debian's
# `chromium` driven over the DevTools protocol by tests/web/drive.py): the page loads with the viewer
# and the sliders, a slider moved writes the scenario file, the page follows the reload, an
# out-of-range value is refused, and the saved recording holds the reload event. Loopback only.
#
#   tests/web/run.sh [RINSCOPE_BINARY]     (default $CARGO_TARGET_DIR/release/rinscope)
#
# Installs chromium (apt-get) and a small venv with websocket-client when missing, and fails if it
# cannot; RINSCOPE_SKIP_WEB=1 skips the test and says so. Last line: "web: 1 passed, 0 failed" or
# "web: 0 passed, 1 failed" (exit 1). About 20 s.
set -euo pipefail
if [[ ${RINSCOPE_SKIP_WEB:-} == 1 ]]; then
  echo "web: SKIPPED (RINSCOPE_SKIP_WEB=1): the class page was not tested in a browser"
  exit 0
fi
bin=$(realpath "${1:-${CARGO_TARGET_DIR:-$HOME/.cache/rinscope-target}/release/rinscope}")
here=$(cd "$(dirname "$0")" && pwd)
command -v chromium >/dev/null || { (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium) >/dev/null 2>&1 || sudo -n apt-get install -y -qq chromium >/dev/null 2>&1 || true; }
command -v chromium >/dev/null || { echo "web: chromium is required (apt-get install chromium), or RINSCOPE_SKIP_WEB=1"; echo "web: 0 passed, 1 failed"; exit 1; }
venv=${RINSCOPE_WEB_VENV:-$HOME/.cache/rinscope-web-venv}
[ -x "$venv/bin/python" ] && "$venv/bin/python" -c "import websocket" 2>/dev/null || { python3 -m venv "$venv" && "$venv/bin/pip" install -q websocket-client==1.8.0; }
work=$(mktemp -d)
pid=
# RINSCOPE_WEB_KEEP=DIR keeps the logs, latency samples and screenshots there (to read a failure).
cleanup() { [[ -n $pid ]] && kill "$pid" 2>/dev/null; wait 2>/dev/null || true; [[ -n ${RINSCOPE_WEB_KEEP:-} ]] && cp -r "$work/." "$RINSCOPE_WEB_KEEP/"; rm -rf "$work"; }
trap cleanup EXIT
# Three consecutive free ports on 127.0.0.1 (page, viewer, stream) and one for Chromium's DevTools.
read -r port cport < <(python3 - <<'PY'
import socket
def free(n):
    for base in range(20000, 60000, 7):
        socks = []
        try:
            for k in range(n):
                s = socket.socket(); s.bind(("127.0.0.1", base + k)); socks.append(s)
            return base
        except OSError:
            pass
        finally:
            for s in socks: s.close()
print(free(3), free(1) + 40)
PY
)
cd "$work"
"$bin" live --scenario jiang2017-dual-axis --no-panel --serve-web "$port" --save "$work/session.rrd" --duration-s 600 >"$work/live.log" 2>&1 &
pid=$!
for _ in $(seq 100); do grep -q "class page" "$work/live.log" && break; sleep 0.1; done
url=$(grep -o "class page (viewer and sliders): http://[^ ]*" "$work/live.log" | sed 's/.*: //')
[[ -n $url ]] || { cat "$work/live.log"; echo "web: 0 passed, 1 failed"; exit 1; }
passed=0 failed=0
if "$venv/bin/python" "$here/drive.py" "$url" "$work/rinscope-live/jiang2017-dual-axis.toml" "$cport"; then
  sleep 1
  kill -INT "$pid"; wait "$pid" || true; pid=
  # The events read whole first: `events | grep -q` under pipefail fails at random when grep quits
  # at its first match and `events` then writes into a closed pipe.
  events=$("$bin" events "$work/session.rrd" 2>&1) || events+=$'\n(rinscope events failed)'
  if grep -q "reloaded at .*inner swing half-angle 300″ → 450″" <<<"$events"; then
    echo "web: the recording holds the reload: $(grep -m1 reloaded <<<"$events")"
    passed=$((passed + 1))
  else
    echo "$events"
    echo "web: the reload is not in the recording"; failed=$((failed + 1))
  fi
else
  cat "$work/live.log"; failed=$((failed + 1))
fi
[[ -n $pid ]] && { kill -INT "$pid"; wait "$pid" || true; pid=; }

# The class: the viewer in the page keeps up with the session (its own time cursor within 1 s of the
# session's at steady state) while a teacher moves sliders, each change shown within 1 s; the same for
# a coning lesson and for a finished `run --serve-web`. tests/web/latency.py reads the viewer's time
# through its WebHandle. RINSCOPE_WEB_LONG=1: the 10-minute class (and every preset for 90 s).
class_seconds=120; coning_seconds=60  # of watching, from the viewer's first data
[[ ${RINSCOPE_WEB_LONG:-} == 1 ]] && { class_seconds=600; coning_seconds=600; }
watch() {  # watch NAME SCENARIO SECONDS MOVE_LABEL MOVE_VALUES
  local name=$1 scenario=$2 seconds=$3 label=$4 values=$5 port
  read -r port < <(python3 -c "$free_py" 3)
  mkdir -p "$work/$name"
  (cd "$work/$name" && exec "$bin" live --scenario "$scenario" --no-panel --serve-web "$port" --save "$work/$name/session.rrd" --duration-s 3600) >"$work/$name/live.log" 2>&1 &
  pid=$!
  for _ in $(seq 100); do grep -q "class page" "$work/$name/live.log" && break; sleep 0.1; done
  # The viewer within a second of the session: its median lag at most 1 s, and again at the end (at
  # 2 fps; a viewer painting slower lags by its own frame period, which latency.py adds); no stall
  # over 5 s. The class's target, no sample over 1.5 s (the stream's flush plus one
  # software-rendered frame at 1.6-2.5 fps), is reported, not asserted: a neighbour on this shared
  # machine stalls the software renderer for seconds (see latency.py).
  local args=(--page "http://127.0.0.1:$port/" --viewer-origin "http://127.0.0.1:$((port + 1))" --cdp "$cport" --seconds "$seconds"
              --controls "http://127.0.0.1:$port/controls" --max-lag 1.0 --max-lag-peak 5 --target-lag-peak 1.5 --json "$work/$name/latency.json" --screenshot "$work/$name/page.png")
  # A slider's change is shown once the viewer's lag (at most 1 s, above) has passed it and the viewer
  # has painted one more frame (2-2.5 fps in software: 0.4-0.5 s): 1.5 s after the release in the
  # median (asserted; plus twice a slower viewer's frame period beyond 0.5 s) and for every change
  # (the target, reported); none later than 5 s.
  [[ -n $label ]] && args+=(--move-every 15 --move-label "$label" --move-values "$values" --max-move-median 1.5 --max-move 5 --target-move 1.5)
  if "$venv/bin/python" "$here/latency.py" "${args[@]}" >"$work/$name/latency.log" 2>&1; then
    echo "web: $name: $(grep '^summary' "$work/$name/latency.log")"; grep '^latency: targets\|^around the peak' "$work/$name/latency.log" | sed "s/^/web: $name: /"; passed=$((passed + 1))
  else
    tail -n 15 "$work/$name/latency.log"; echo "web: $name: FAILED"; failed=$((failed + 1))
  fi
  kill -INT "$pid"; wait "$pid" || true; pid=
}
free_py='
import socket, sys
n = int(sys.argv[1]) if len(sys.argv) > 1 else 3
for base in range(23000, 60000, 11):
    socks = []
    try:
        for k in range(n):
            s = socket.socket(); s.bind(("127.0.0.1", base + k)); socks.append(s)
        print(base); break
    except OSError:
        pass
    finally:
        for s in socks: s.close()
'
watch class jiang2017-dual-axis "$class_seconds" "inner swing half-angle" "450,300"
watch coning pure-coning "$coning_seconds" "cone half-angle" "2,1"
if [[ ${RINSCOPE_WEB_LONG:-} == 1 ]]; then
  for preset in $("$bin" scenarios | awk '{print $1}'); do watch "preset-$preset" "$preset" 90 "" ""; done
fi
# A finished run served to a browser: the viewer shows its end (lag 0) once loaded.
read -r port < <(python3 -c "$free_py" 2)
mkdir -p "$work/run"
(cd "$work/run" && exec "$bin" run --scenario jiang2017-dual-axis --duration-s 120 --serve-web "$port" --save "$work/run/run.rrd") >"$work/run/run.log" 2>&1 &
pid=$!
for _ in $(seq 300); do grep -q "viewer stays" "$work/run/run.log" && break; sleep 0.1; done
if "$venv/bin/python" "$here/latency.py" --page "http://127.0.0.1:$port/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A$((port + 1))%2Fproxy" --viewer-origin "http://127.0.0.1:$port" \
     --cdp "$cport" --seconds 30 --end-t 119.95 --newest --max-lag 1.0 --max-lag-peak 1.5 --json "$work/run/latency.json" >"$work/run/latency.log" 2>&1; then
  echo "web: run --serve-web: $(grep '^summary' "$work/run/latency.log")"; passed=$((passed + 1))
else
  tail -n 15 "$work/run/latency.log"; echo "web: run --serve-web: FAILED"; failed=$((failed + 1))
fi
kill -INT "$pid"; wait "$pid" || true; pid=
echo "web: $passed passed, $failed failed"
[[ $failed == 0 ]]
