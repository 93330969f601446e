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
        # Execution contexts: (session, context id) -> (origin, frame id, is default). A frame of
        # another origin may run in a process of its own (an out-of-process iframe): its contexts
        # come through a session attached to its target (`Target.setAutoAttach`, flattened).
        self.contexts = {}
        self.pending_sessions = []
        self.call("Runtime.enable")
        self.call("Page.enable")
        self.call("Target.setAutoAttach", autoAttach=True, waitForDebuggerOnStart=False, flatten=True)
        if dark:
            self.call("Emulation.setEmulatedMedia", features=[{"name": "prefers-color-scheme", "value": "dark"}])

    def _event(self, m):
        session = m.get("sessionId")
        method = m.get("method")
        if method == "Runtime.executionContextCreated":
            c = m["params"]["context"]
            aux = c.get("auxData", {})
            self.contexts[(session, c["id"])] = (c.get("origin", ""), aux.get("frameId"), aux.get("isDefault", False))
        elif method == "Runtime.executionContextDestroyed":
            self.contexts.pop((session, m["params"]["executionContextId"]), None)
        elif method == "Runtime.executionContextsCleared":
            self.contexts = {k: v for k, v in self.contexts.items() if k[0] != session}
        elif method == "Target.attachedToTarget":
            self.pending_sessions.append(m["params"]["sessionId"])
        elif method == "Target.detachedFromTarget":
            gone = m["params"].get("sessionId")
            self.contexts = {k: v for k, v in self.contexts.items() if k[0] != gone}

    def call(self, method, session=None, **params):
        self.seq += 1
        want = self.seq
        msg = {"id": want, "method": method, "params": params}
        if session:
            msg["sessionId"] = session
        self.ws.send(json.dumps(msg))
        while True:
            m = json.loads(self.ws.recv())
            if m.get("id") == want and m.get("sessionId") == session:
                break
            self._event(m)
        # Frames attached meanwhile get their contexts reported (and run on).
        while self.pending_sessions:
            s = self.pending_sessions.pop()
            self.call("Runtime.enable", session=s)
            self.call("Runtime.runIfWaitingForDebugger", session=s)
        return m

    def pump(self):
        """Reads the events that arrived (new frames' contexts)."""
        self.call("Runtime.evaluate", expression="0")

    def js(self, expr, context=None):
        """The value of `expr` (awaited), in the page or in `context` (from `context_of`)."""
        params = {"expression": expr, "awaitPromise": True, "returnByValue": True}
        session = None
        if context is not None:
            session, params["contextId"] = context
        r = self.call("Runtime.evaluate", session=session, **params)
        res = r.get("result", {})
        if "exceptionDetails" in res:
            return None
        return res.get("result", {}).get("value")

    def context_of(self, origin):
        """The default execution context of the frame whose origin is `origin`, as (session, id)
        (None: not yet)."""
        self.pump()
        for key, (o, _, default) in sorted(self.contexts.items(), key=lambda kv: kv[0][1], reverse=True):
            if default and o.rstrip("/") == origin.rstrip("/"):
                return key
        return None

    def find_viewer_handle(self, context):
        """Makes the Rerun viewer's `WebHandle` in `context` reachable as `window.__rinscope_handle`.
        Rerun's index.html keeps it in a local variable (it sets `window._handle` only once `start()`
        resolves, which 0.36 does not do while it streams): the heap is asked for the objects whose
        prototype is `WebHandle.prototype` (`Runtime.queryObjects`). True when found."""
        session, cid = context
        r = self.call("Runtime.evaluate", session=session, expression="wasm_bindgen.WebHandle.prototype", contextId=cid)
        proto = r.get("result", {}).get("result", {}).get("objectId")
        if not proto:
            return False
        r = self.call("Runtime.queryObjects", session=session, prototypeObjectId=proto)
        arr = r.get("result", {}).get("objects", {}).get("objectId")
        if not arr:
            return False
        r = self.call("Runtime.callFunctionOn", session=session, objectId=arr, returnByValue=True,
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
