"""How far behind the session the Rerun web viewer is, read in the viewer itself.

Opens PAGE in headless Chromium, finds the Rerun viewer's frame (origin VIEWER_ORIGIN; the page
itself when it is the viewer), and reads the viewer's own time cursor on `sim_time` and the range of
data it holds (through its `WebHandle`: `cdp.Browser.find_viewer_handle`) beside the session's
simulated time: `GET CONTROLS` (the class page's `sim_t_s`), or, for a finished run, END_T. With
MOVE_EVERY, a teacher moves a slider on the page every MOVE_EVERY seconds (alternately two values) and
the time until the viewer shows data past the change is measured (bracketed between two questions to
the viewer, which answers between its frames).

    latency.py --page URL --viewer-origin ORIGIN --cdp PORT --seconds N
               [--controls URL | --end-t T] [--move-every S --move-label LABEL --move-values A,B]
               [--warmup S] [--max-lag S] [--max-lag-peak S] [--max-move S] [--json OUT]
               [--screenshot OUT.png [--dark]]

Prints a line per second (with the machine's load average) and a summary; exits 1 when the
steady-state lag (after the viewer first shows data plus WARMUP) has a median over MAX_LAG, its last
ten samples a median over MAX_LAG (it did not recover), or any sample exceeds MAX_LAG_PEAK; or when a
change was not seen, the median change took longer than MAX_MOVE_MEDIAN or one longer than MAX_MOVE.
A viewer that falls behind (the defect this guards against: 52 s after two minutes) fails all of them.
One that keeps up but paints at 1.3-2.5 fps in software rendering lags by its frame period on top of
the stream's flush (0.25-0.5 s): 0.5-1.2 s here; MAX_LAG and MAX_MOVE_MEDIAN hold at 2 fps, and a
slower viewer's measured frame period beyond 0.5 s is added to them (once, and twice). The tighter TARGET_LAG_PEAK and TARGET_MOVE (what a
class should see: 1.5 s) are measured and reported, not asserted: these machines are shared, and a
neighbour's burst stalls the software renderer for seconds (a CI run saw 2.5 s for about 5 s, then
0.6 s again) — timing targets belong to benchmarks, the test to what a stall cannot explain.
"""
import argparse
import json
import os
import re
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
# A finished run plays from its start in the viewer (its time cursor is the user's): what it holds is
# measured, its newest data against END_T.
ap.add_argument("--newest", action="store_true")
ap.add_argument("--move-every", type=float, default=0.0)
ap.add_argument("--move-label", default="inner swing half-angle")
ap.add_argument("--move-values", default="450,300")
ap.add_argument("--warmup", type=float, default=10.0)
ap.add_argument("--max-lag", type=float)
ap.add_argument("--max-move", type=float)
ap.add_argument("--max-lag-peak", type=float, help="the largest lag allowed in any sample (--max-lag bounds the median)")
ap.add_argument("--max-move-median", type=float, help="the median time a change may take to show")
ap.add_argument("--target-lag-peak", type=float, help="reported: the largest lag a class should see")
ap.add_argument("--target-move", type=float, help="reported: the longest a change should take to show")
ap.add_argument("--json")
ap.add_argument("--screenshot")
ap.add_argument("--dark", action="store_true")
a = ap.parse_args()


def controls():
    with urllib.request.urlopen(a.controls, timeout=5) as r:
        return json.load(r)


def session_time():
    if a.controls:
        try:
            return controls()["sim_t_s"]
        except Exception:
            return None
    return a.end_t


b = Browser(a.cdp, dark=a.dark)
samples, moves = [], []
ctx = None


def viewer():
    """What the viewer shows: (time cursor s, newest data s, frames painted) or None."""
    global ctx
    if ctx is None:
        ctx = b.context_of(a.viewer_origin)
    state = b.js(VIEWER_STATE, ctx) if ctx else None
    if state is None and ctx is not None and b.find_viewer_handle(ctx):
        state = b.js(VIEWER_STATE, ctx)
    if state is None and ctx is not None:
        ctx = None  # the frame was reloaded: find its new context
    if not state or state.get("t") is None:
        return None
    rng = state.get("range")
    newest = rng["max"] / 1e9 if isinstance(rng, dict) and rng.get("max") is not None else None
    # The viewer reports a duration timeline in nanoseconds.
    return state["t"] / 1e9, newest, state.get("frames")


values = [float(v) for v in a.move_values.split(",")]
try:
    b.navigate(a.page)
    t0 = time.monotonic()
    first_data, next_move = None, None
    # SECONDS of watching from the viewer's first data (it takes about a minute to start here).
    while (first_data is None and time.monotonic() - t0 < 240) or (first_data is not None and time.monotonic() - t0 < first_data + a.seconds):
        time.sleep(1.0)
        asked = time.monotonic()
        shown = viewer()
        # The session's time when the viewer's answer came (a viewer whose page is busy answers
        # late: what it shows is compared with the session at that moment).
        now, answered_in = time.monotonic() - t0, time.monotonic() - asked
        session = session_time()
        t, newest, frames = shown if shown else (None, None, None)
        if a.newest:
            t = newest
        lag = session - t if (session is not None and t is not None) else None
        fps = None
        if frames is not None and samples and samples[-1]["frames"] is not None:
            fps = round((frames - samples[-1]["frames"]) / (now - samples[-1]["wall_s"]), 1)
        if t is not None and first_data is None:
            first_data = now
            next_move = now + a.warmup
        samples.append({"wall_s": round(now, 2), "load1": round(os.getloadavg()[0], 2), "session_s": session, "viewer_t_s": t, "viewer_newest_s": newest, "lag_s": lag, "fps": fps, "frames": frames, "viewer_answered_in_s": round(answered_in, 2)})
        print(f"wall {now:6.1f} s  session {session if session is None else round(session, 2)}  viewer {t if t is None else round(t, 2)}  lag {lag if lag is None else round(lag, 2)}  fps {fps}  (answered in {answered_in:.2f} s)  load {os.getloadavg()[0]:.2f}", flush=True)
        # A teacher moves a slider on the page (its input and change events, as a mouse release).
        if a.move_every > 0 and a.controls and next_move is not None and now >= next_move:
            next_move = now + a.move_every
            value = values[len(moves) % len(values)]
            expr = f"""(() => {{
                const row = [...document.querySelectorAll('.control')].find(d => d.textContent.startsWith({json.dumps(a.move_label)}));
                if (!row) return null;
                const input = row.querySelector('input');
                input.value = {value}; input.dispatchEvent(new Event('input')); input.dispatchEvent(new Event('change'));
                return true;
            }})()"""
            generation = controls()["generation"]
            moved_at = time.monotonic()
            if not b.js(expr):
                print(f"latency: no control {a.move_label!r} on the page", flush=True)
                sys.exit(1)
            # The change applies in the session at its time then; it shows when the viewer shows
            # data past it.
            applied = None
            while applied is None and time.monotonic() - moved_at < 5:
                c = controls()
                m = re.search(r"reloaded at t = ([0-9.]+) s", c.get("message", ""))
                if c["generation"] > generation and m:
                    applied, applied_wall = float(m.group(1)), time.monotonic()
                else:
                    time.sleep(0.02)
            if applied is None:
                print(f"latency: the change of {a.move_label} was not applied within 5 s", flush=True)
                sys.exit(1)
            # The viewer answers a question only between its frames (0.2-0.5 s here), so the moment it
            # first showed the change is bracketed: after the last question that it answered without it
            # was asked, at or before the answer that has it. The upper end is what is checked.
            seen, seen_from, asked = None, None, time.monotonic()
            while asked - moved_at < 30:
                s = viewer()
                if s and s[0] >= applied:
                    seen = time.monotonic() - moved_at
                    break
                seen_from = asked - moved_at
                time.sleep(0.02)
                asked = time.monotonic()
            moves.append({"wall_s": round(now, 2), "value": value, "applied_at_sim_s": applied, "applied_after_s": round(applied_wall - moved_at, 2), "seen_after_s": None if seen is None else round(seen, 2), "seen_not_before_s": None if seen_from is None else round(seen_from, 2)})
            print(f"wall {now:6.1f} s  moved {a.move_label} to {value}: applied at t = {applied} ({applied_wall - moved_at:.2f} s after the release), shown after {seen_from if seen_from is None else round(seen_from, 2)}-{seen if seen is None else round(seen, 2)} s", flush=True)
    if a.screenshot:
        b.screenshot(a.screenshot)
finally:
    b.close()

steady = [s["lag_s"] for s in samples if s["lag_s"] is not None and first_data is not None and s["wall_s"] >= first_data + a.warmup]
# The bounds are the stream's flush plus the viewer's own frames: MAX_LAG is the stream's flush
# (0.5 s) and one frame at 2 fps, MAX_MOVE_MEDIAN that lag and one more frame. A viewer painting
# slower than 2 fps (software rendering on a slow hour: 1.3-1.6 fps) shows the newest data a frame
# period after it ingests it, which no stream can shorten: its measured frame period beyond 0.5 s
# is added, once to the lag and twice to a change. At 2 fps or faster the bounds are MAX_LAG and
# MAX_MOVE_MEDIAN as given. A viewer that falls behind still fails them: its lag grows, its frame
# period does not.
steady_fps = [s["fps"] for s in samples if s["fps"] and first_data is not None and s["wall_s"] >= first_data + a.warmup]
slow_frame_s = max(0.0, 1.0 / statistics.median(steady_fps) - 0.5) if steady_fps else 0.0
max_lag = a.max_lag + slow_frame_s if a.max_lag is not None else None
max_move_median = a.max_move_median + 2 * slow_frame_s if a.max_move_median is not None else None
summary = {"samples": len(samples), "steady_samples": len(steady), "first_data_wall_s": first_data}
if steady:
    q = sorted(steady)
    summary.update({"lag_median_s": round(statistics.median(q), 3), "lag_p95_s": round(q[min(len(q) - 1, int(0.95 * len(q)))], 3), "lag_max_s": round(q[-1], 3), "lag_last_s": samples[-1]["lag_s"]})
fps = [s["fps"] for s in samples if s["fps"] is not None]
if fps:
    summary["viewer_fps_median"] = statistics.median(fps)
seen = []
if moves:
    seen = [m["seen_after_s"] for m in moves if m["seen_after_s"] is not None]
    summary.update({"moves": len(moves), "moves_seen": len(seen), "move_seen_median_s": round(statistics.median(seen), 2) if seen else None, "move_seen_max_s": max(seen) if seen else None})
if slow_frame_s > 0:
    summary["slow_frame_s"] = round(slow_frame_s, 3)
    summary["max_lag_s"] = None if max_lag is None else round(max_lag, 3)
    summary["max_move_median_s"] = None if max_move_median is None else round(max_move_median, 3)
print("summary:", json.dumps(summary), flush=True)
if a.json:
    with open(a.json, "w") as f:
        json.dump({"samples": samples, "moves": moves, "summary": summary}, f, indent=1)
failed = []
if max_lag is not None and (not steady or summary["lag_median_s"] > max_lag):
    failed.append(f"the viewer's median lag was {summary.get('lag_median_s')} s (at most {max_lag:.2f} s)")
if max_lag is not None and steady and statistics.median(steady[-10:]) > max_lag:
    failed.append(f"the viewer did not recover: its last ten samples' median lag was {statistics.median(steady[-10:]):.2f} s (at most {max_lag:.2f} s)")
if a.max_lag_peak is not None and (not steady or max(steady) > a.max_lag_peak):
    failed.append(f"the viewer's lag reached {max(steady) if steady else 'no data'} s (at most {a.max_lag_peak} s)")
if moves and len(seen) < len(moves):
    failed.append(f"{len(moves) - len(seen)} of {len(moves)} changes never showed")
if max_move_median is not None and seen and statistics.median(seen) > max_move_median:
    failed.append(f"a change showed after {statistics.median(seen):.2f} s in the median (at most {max_move_median:.2f} s)")
if a.max_move is not None and seen and max(seen) > a.max_move:
    failed.append(f"a change showed after {max(seen)} s (at most {a.max_move} s)")
missed = []
if a.target_lag_peak is not None and steady and max(steady) > a.target_lag_peak:
    missed.append(f"lag peak {max(steady):.2f} s > {a.target_lag_peak} s")
if a.target_move is not None and seen and max(seen) > a.target_move:
    missed.append(f"a change shown after {max(seen)} s > {a.target_move} s")
if missed or failed:
    # Where it happened: the samples around the worst lag, with the machine's load then.
    worst = max(range(len(samples)), key=lambda i: samples[i]["lag_s"] if samples[i]["lag_s"] is not None else -1e9)
    for s in samples[max(0, worst - 4):worst + 5]:
        print("around the peak:", json.dumps(s), flush=True)
if missed:
    print("latency: targets missed on this run (reported, not asserted):", "; ".join(missed), flush=True)
elif a.target_lag_peak is not None or a.target_move is not None:
    print("latency: targets met (lag peak, every change shown)", flush=True)
if failed:
    print("latency: FAILED:", "; ".join(failed), flush=True)
    sys.exit(1)
