"""A small DevTools-protocol client for headless Chromium (Debian's `chromium`), shared by the web
tests: start the browser, open a page, evaluate JavaScript in the page or in one of its frames (the
Rerun viewer's own frame, where its `window._handle` lives), take a screenshot. Loopback only.
"""
import base64
import json
import subprocess
import tempfile
import time
import urllib.request

import websocket


class Browser:
    """A headless Chromium with one tab, driven over the DevTools protocol."""

    def __init__(self, port, size=(1600, 1000), dark=False):
        args = ["chromium", "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
                "--disable-background-networking", "--disable-component-update", "--disable-sync",
                "--disable-quic", f"--user-data-dir={tempfile.mkdtemp()}",
                f"--window-size={size[0]},{size[1]}", f"--remote-debugging-port={port}", "about:blank"]
        self.proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        tabs = None
        for _ in range(150):
            try:
                tabs = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json"))
                break
            except Exception:
                time.sleep(0.2)
        if not tabs:
            self.close()
            raise RuntimeError("chromium's DevTools did not answer")
        tab = next(t for t in tabs if t.get("type") == "page")
        self.ws = websocket.create_connection(tab["webSocketDebuggerUrl"], timeout=60, suppress_origin=True)
        self.seq = 0
        self.contexts = {}  # execution context id -> (origin, frame id, is default)
        self.call("Runtime.enable")
        self.call("Page.enable")
        if dark:
            self.call("Emulation.setEmulatedMedia", features=[{"name": "prefers-color-scheme", "value": "dark"}])

    def _event(self, m):
        if m.get("method") == "Runtime.executionContextCreated":
            c = m["params"]["context"]
            aux = c.get("auxData", {})
            self.contexts[c["id"]] = (c.get("origin", ""), aux.get("frameId"), aux.get("isDefault", False))
        elif m.get("method") == "Runtime.executionContextDestroyed":
            self.contexts.pop(m["params"]["executionContextId"], None)
        elif m.get("method") == "Runtime.executionContextsCleared":
            self.contexts.clear()

    def call(self, method, **params):
        self.seq += 1
        want = self.seq
        self.ws.send(json.dumps({"id": want, "method": method, "params": params}))
        while True:
            m = json.loads(self.ws.recv())
            if m.get("id") == want:
                return m
            self._event(m)

    def pump(self):
        """Reads the events that arrived (new frames' contexts)."""
        self.call("Runtime.evaluate", expression="0")

    def js(self, expr, context=None):
        """The value of `expr` (awaited), in the page or in execution context `context`."""
        params = {"expression": expr, "awaitPromise": True, "returnByValue": True}
        if context is not None:
            params["contextId"] = context
        r = self.call("Runtime.evaluate", **params)
        res = r.get("result", {})
        if "exceptionDetails" in res:
            return None
        return res.get("result", {}).get("value")

    def context_of(self, origin):
        """The default execution context of the frame whose origin is `origin` (None: not yet)."""
        self.pump()
        for cid, (o, _, default) in sorted(self.contexts.items(), reverse=True):
            if default and o.rstrip("/") == origin.rstrip("/"):
                return cid
        return None

    def find_viewer_handle(self, context):
        """Makes the Rerun viewer's `WebHandle` in `context` reachable as `window.__rinscope_handle`.
        Rerun's index.html keeps it in a local variable (it sets `window._handle` only once `start()`
        resolves, which 0.36 does not do while it streams): the heap is asked for the objects whose
        prototype is `WebHandle.prototype` (`Runtime.queryObjects`). True when found."""
        r = self.call("Runtime.evaluate", expression="wasm_bindgen.WebHandle.prototype", contextId=context)
        proto = r.get("result", {}).get("result", {}).get("objectId")
        if not proto:
            return False
        r = self.call("Runtime.queryObjects", prototypeObjectId=proto)
        arr = r.get("result", {}).get("objects", {}).get("objectId")
        if not arr:
            return False
        r = self.call("Runtime.callFunctionOn", objectId=arr, returnByValue=True,
                      functionDeclaration="function() { const h = this.find(x => x.__wbg_ptr); if (h) window.__rinscope_handle = h; return !!h; }")
        return bool(r.get("result", {}).get("result", {}).get("value"))

    def navigate(self, url):
        self.call("Page.navigate", url=url)

    def screenshot(self, path):
        r = self.call("Page.captureScreenshot", format="png")
        with open(path, "wb") as f:
            f.write(base64.b64decode(r["result"]["data"]))

    def close(self):
        try:
            self.ws.close()
        except Exception:
            pass
        self.proc.terminate()
        try:
            self.proc.wait(timeout=10)
        except Exception:
            self.proc.kill()


# What the Rerun viewer shows, read from its own handle (index.html sets `window._handle` once the app
# has started): the active recording, its time cursor on `sim_time` and the range of the data it holds.
VIEWER_STATE = """(() => {
  const h = window._handle || window.__rinscope_handle;
  if (!h) return null;
  if (window.__rinscope_frames === undefined) {
    // Frames the viewer's page paints (requestAnimationFrame callbacks), counted from here on.
    window.__rinscope_frames = 0;
    const tick = () => { window.__rinscope_frames++; requestAnimationFrame(tick); };
    requestAnimationFrame(tick);
  }
  const frames = window.__rinscope_frames;
  const rec = h.get_active_recording_id();
  if (!rec) return {rec: null, frames};
  return {rec, timeline: h.get_active_timeline(rec), t: h.get_time_for_timeline(rec, 'sim_time'),
          range: h.get_timeline_time_range(rec, 'sim_time'), playing: h.get_playing(rec), frames};
})()"""
