"""Drives `rinscope live --serve-web`'s class page in headless Chromium over the DevTools protocol,
as a teacher would: load the page, wait for the sliders, move one, and check that the scenario file
changed and that the session logged the reload. Called by tests/web/run.sh (which starts rinscope).

    drive.py PAGE_URL CONFIG_FILE CHROME_PORT
"""
import json
import subprocess
import sys
import tempfile
import time
import urllib.request

import websocket

page, config, cport = sys.argv[1], sys.argv[2], int(sys.argv[3])


def fail(msg):
    print("web: FAILED:", msg)
    sys.exit(1)


chrome = subprocess.Popen(["chromium", "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
                           "--disable-background-networking", "--disable-component-update",
                           f"--user-data-dir={tempfile.mkdtemp()}", "--window-size=1600,1000",
                           f"--remote-debugging-port={cport}", "about:blank"],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
try:
    tabs = None
    for _ in range(150):
        try:
            tabs = json.load(urllib.request.urlopen(f"http://127.0.0.1:{cport}/json"))
            break
        except Exception:
            time.sleep(0.2)
    if not tabs:
        fail("chromium's DevTools did not answer")
    tab = next(t for t in tabs if t.get("type") == "page")
    ws = websocket.create_connection(tab["webSocketDebuggerUrl"], timeout=30, suppress_origin=True)
    seq = [0]

    def call(method, **params):
        seq[0] += 1
        ws.send(json.dumps({"id": seq[0], "method": method, "params": params}))
        while True:
            m = json.loads(ws.recv())
            if m.get("id") == seq[0]:
                return m

    def js(expr):
        r = call("Runtime.evaluate", expression=expr, awaitPromise=True, returnByValue=True)
        return r.get("result", {}).get("result", {}).get("value")

    call("Page.enable")
    call("Page.navigate", url=page)
    # 1. The page shows the viewer and the controls.
    n = 0
    for _ in range(100):
        n = js("document.querySelectorAll('#controls input').length") or 0
        if n > 0:
            break
        time.sleep(0.2)
    if n == 0:
        fail("no controls appeared on the page")
    src = js("document.getElementById('viewer').src")
    # The session so far (the class page's /history.rrd) and the live stream, in the dark theme.
    if not src or "url=rerun" not in src or "history.rrd" not in src or "theme=dark" not in src:
        fail(f"the viewer frame points to {src!r}")
    print(f"web: page loaded, {n} controls, viewer frame {src}")
    # 2. A teacher moves the inner swing slider to 450″ (the range input's value, then its change event,
    # as a release of the mouse does).
    moved = js("""(() => {
        const row = [...document.querySelectorAll('.control')].find(d => d.textContent.startsWith('inner swing half-angle'));
        if (!row) return 'no inner swing slider';
        const input = row.querySelector('input');
        input.value = 450; input.dispatchEvent(new Event('input')); input.dispatchEvent(new Event('change'));
        return 'moved';
    })()""")
    if moved != "moved":
        fail(moved)
    # 3. The file changes, through the same path as the terminal's sliders.
    for _ in range(100):
        text = open(config).read()
        if "swing_half_angle_arcsec = 450" in text:
            break
        time.sleep(0.1)
    else:
        fail("the scenario file was not written")
    print("web: the slider wrote the file (inner swing_half_angle_arcsec = 450.0)")
    # 4. The page follows the reload: the slider shows the value the session runs with.
    for _ in range(100):
        shown = js("(() => { const row = [...document.querySelectorAll('.control')].find(d => d.textContent.startsWith('inner swing half-angle')); return row.querySelector('output').textContent; })()")
        if shown and shown.startswith("450"):
            break
        time.sleep(0.1)
    else:
        fail(f"the page shows {shown!r} after the reload")
    # 5. A value the panel refuses is refused on the page too, with the reason shown.
    js("fetch('/set', {method: 'POST', headers: {'Content-Type': 'application/json'}, body: JSON.stringify({control: 0, value: 1e12})}).then(r => r.status).then(s => { document.body.dataset.refused = s; })")
    time.sleep(0.5)
    if js("document.body.dataset.refused") != "400":
        fail("an out-of-range value was not refused")
    print("web: an out-of-range value refused (400)")
    ws.close()
finally:
    chrome.terminate()
    chrome.wait(timeout=10)
print("web: page checks passed")
