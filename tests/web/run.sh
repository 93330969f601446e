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
cleanup() { [[ -n $pid ]] && kill "$pid" 2>/dev/null; wait 2>/dev/null || true; rm -rf "$work"; }
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
if "$venv/bin/python" "$here/drive.py" "$url" "$work/rinscope-live/jiang2017-dual-axis.toml" "$cport"; then
  sleep 1
  kill -INT "$pid"; wait "$pid" || true; pid=
  if "$bin" events "$work/session.rrd" | grep -q "reloaded at .*inner swing half-angle 300″ → 450″"; then
    echo "web: the recording holds the reload: $("$bin" events "$work/session.rrd" | grep -m1 reloaded)"
    echo "web: 1 passed, 0 failed"; exit 0
  fi
  "$bin" events "$work/session.rrd" || true
  echo "web: the reload is not in the recording"
fi
cat "$work/live.log"
echo "web: 0 passed, 1 failed"; exit 1
