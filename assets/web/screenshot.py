import json, subprocess, sys, time, base64, urllib.request, websocket
url, out, wait = sys.argv[1], sys.argv[2], float(sys.argv[3]) if len(sys.argv) > 3 else 25
p = subprocess.Popen(["chromium", "--headless=new", "--no-sandbox", "--enable-unsafe-swiftshader", "--use-angle=swiftshader", "--enable-webgl", "--ignore-gpu-blocklist",
    "--disable-quic", "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--user-data-dir=/tmp/chr2", "--window-size=1600,1000", "--remote-debugging-port=9333", "about:blank"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
try:
    for _ in range(50):
        try:
            tabs = json.load(urllib.request.urlopen("http://127.0.0.1:9333/json")); break
        except Exception: time.sleep(0.2)
    ws = websocket.create_connection([t for t in tabs if t["type"] == "page"][0]["webSocketDebuggerUrl"], timeout=60)
    n = [0]
    def call(method, **params):
        n[0] += 1; ws.send(json.dumps({"id": n[0], "method": method, "params": params}))
        while True:
            m = json.loads(ws.recv())
            if m.get("id") == n[0]: return m
            if m.get("method") in ("Runtime.consoleAPICalled", "Runtime.exceptionThrown", "Log.entryAdded"):
                txt = json.dumps(m["params"])[:300]; print("console:", txt)
    call("Runtime.enable"); call("Log.enable")
    call("Emulation.setDeviceMetricsOverride", width=1600, height=1000, deviceScaleFactor=1, mobile=False)
    call("Page.navigate", url=url)
    t0 = time.time()
    ws.settimeout(1)
    while time.time() - t0 < wait:
        try:
            m = json.loads(ws.recv())
            if m.get("method") in ("Runtime.consoleAPICalled", "Runtime.exceptionThrown", "Log.entryAdded"):
                print("console:", json.dumps(m["params"])[:300])
        except Exception: pass
    ws.settimeout(60)
    r = call("Page.captureScreenshot", format="png")
    open(out, "wb").write(base64.b64decode(r["result"]["data"]))
    print("saved", out)
finally:
    p.kill()
