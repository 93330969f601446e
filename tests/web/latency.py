"""How far behind the session the Rerun web viewer is, read in the viewer itself.

Opens PAGE in headless Chromium, finds the Rerun viewer's frame (origin VIEWER_ORIGIN; the page
itself when it is the viewer), and once a second reads the viewer's own time cursor and the range of
data it holds on `sim_time` (`window._handle`, set by Rerun's index.html) beside the session's
simulated time (`GET CONTROLS`: the class page's `sim_t_s`; without it, the viewer is compared with
END_T, a finished run's last instant). Optionally moves a slider every MOVE_EVERY seconds and times
how long until the viewer shows data past the change.

    latency.py --page URL --viewer-origin ORIGIN --cdp PORT --seconds N
               [--controls URL] [--end-t T] [--move-every S] [--json OUT] [--screenshot OUT.png]

Prints one line per sample and a summary; with --json, writes the samples and the summary.
"""
import argparse
import json
import statistics
import sys
import time
import urllib.request

from cdp import VIEWER_STATE, Browser

ap = argparse.ArgumentParser()
ap.add_argument("--page", required=True)
ap.add_argument("--viewer-origin", required=True)
ap.add_argument("--cdp", type=int, required=True)
ap.add_argument("--seconds", type=float, required=True)
ap.add_argument("--controls")
ap.add_argument("--end-t", type=float)
ap.add_argument("--move-every", type=float, default=0.0)
ap.add_argument("--move-label", default="inner swing half-angle")
ap.add_argument("--json")
ap.add_argument("--screenshot")
ap.add_argument("--warmup", type=float, default=20.0)
a = ap.parse_args()


def controls():
    with urllib.request.urlopen(a.controls, timeout=5) as r:
        return json.load(r)


def to_s(t):
    # The viewer reports a duration timeline in nanoseconds.
    return None if t is None else t / 1e9


b = Browser(a.cdp)
samples, moves = [], []
try:
    b.navigate(a.page)
    t0 = time.monotonic()
    ctx, first_data, next_move, move_k = None, None, None, 0
    while time.monotonic() - t0 < a.seconds:
        time.sleep(1.0)
        asked = time.monotonic()
        if ctx is None:
            ctx = b.context_of(a.viewer_origin)
        state = b.js(VIEWER_STATE, ctx) if ctx else None
        if state is None and ctx is not None and b.find_viewer_handle(ctx):
            state = b.js(VIEWER_STATE, ctx)
        if state is None and ctx is not None:
            ctx = None  # the frame was reloaded: find its new context
        # The session's time when the viewer's answer came (a viewer whose page is busy answers late:
        # what it shows is compared with the session at that moment).
        now = time.monotonic() - t0
        answered_in = time.monotonic() - asked
        session = None
        if a.controls:
            try:
                session = controls()["sim_t_s"]
            except Exception:
                session = None
        elif a.end_t is not None:
            session = a.end_t
        shown = to_s(state.get("t")) if state else None
        rng = state.get("range") if state else None
        newest = to_s(rng["max"]) if isinstance(rng, dict) and rng.get("max") is not None else None
        frames = state.get("frames") if state else None
        fps = None
        if frames is not None and samples and samples[-1].get("frames") is not None and now > samples[-1]["wall_s"]:
            fps = round((frames - samples[-1]["frames"]) / (now - samples[-1]["wall_s"]), 1)
        lag = (session - shown) if (session is not None and shown is not None) else None
        if shown is not None and first_data is None:
            first_data = now
            next_move = now + a.warmup
        samples.append({"wall_s": round(now, 2), "session_s": session, "viewer_t_s": shown, "viewer_newest_s": newest, "lag_s": lag, "viewer_answered_in_s": round(answered_in, 2), "frames": frames, "fps": fps})
        print(f"wall {now:7.1f} s  session {session if session is None else round(session, 2)}  viewer {shown if shown is None else round(shown, 2)}  newest {newest if newest is None else round(newest, 2)}  lag {lag if lag is None else round(lag, 2)}  fps {fps}  (viewer answered in {answered_in:.2f} s)", flush=True)
        # A slider moved from the page: how long until the viewer shows data past the change.
        for m in moves:
            if m.get("seen_after_s") is None and newest is not None and shown is not None and shown >= m["session_s"]:
                m["seen_after_s"] = round(now - m["wall_s"], 2)
        if a.move_every > 0 and a.controls and next_move is not None and now >= next_move:
            next_move = now + a.move_every
            move_k += 1
            value = 300 + 30 * (move_k % 10)
            expr = f"""(() => {{
                const row = [...document.querySelectorAll('.control')].find(d => d.textContent.startsWith({json.dumps(a.move_label)}));
                if (!row) return null;
                const input = row.querySelector('input');
                input.value = {value}; input.dispatchEvent(new Event('input')); input.dispatchEvent(new Event('change'));
                return true;
            }})()"""
            if b.js(expr):
                s = controls()["sim_t_s"]
                moves.append({"wall_s": now, "session_s": s, "value": value, "seen_after_s": None})
    if a.screenshot:
        b.screenshot(a.screenshot)
finally:
    b.close()

steady = [s["lag_s"] for s in samples if s["lag_s"] is not None and first_data is not None and s["wall_s"] >= first_data + a.warmup]
summary = {"samples": len(samples), "steady_samples": len(steady)}
if steady:
    q = sorted(steady)
    summary.update({"lag_median_s": statistics.median(q), "lag_p95_s": q[min(len(q) - 1, int(0.95 * len(q)))], "lag_max_s": q[-1], "lag_last_s": samples[-1]["lag_s"]})
if moves:
    seen = [m["seen_after_s"] for m in moves if m["seen_after_s"] is not None]
    summary.update({"moves": len(moves), "moves_seen": len(seen), "move_seen_max_s": max(seen) if seen else None})
print("summary:", json.dumps(summary), flush=True)
if a.json:
    with open(a.json, "w") as f:
        json.dump({"samples": samples, "moves": moves, "summary": summary}, f, indent=1)
