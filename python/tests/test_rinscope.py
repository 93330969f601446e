"""Tests of the Python package, run by .ci/run on the installed wheel.

Where a result can be checked against something this package did not compute, it is: the tables
against the Parquet files the `rinscope` command exports (read by pyarrow, not by rinscope), TOML
against Python's own TOML reader, the Allan deviations against NIST's published table, the Monte
Carlo statistics recomputed by pandas from the per-run errors.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import rinscope

BIN = Path(sys.executable).parent


def command(*args, cwd, check=True):
    """The `rinscope` command the package installs (the same program, run from the wheel)."""
    exe = shutil.which("rinscope", path=str(BIN)) or shutil.which("rinscope")
    p = subprocess.run([exe, *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=600)
    if check and p.returncode != 0:
        raise AssertionError(f"rinscope {' '.join(map(str, args))}: exit {p.returncode}\n{p.stderr}")
    return p


def same_tables(result, export_dir: Path):
    """Every table of `result` equals the command's `--export` Parquet file of the same name."""
    files = {f.stem: f for f in export_dir.glob("*.parquet")}
    assert files, f"no tables exported to {export_dir}"
    names = {e.strip("/").replace("/", "__").replace(".", "_") for e in result.series}
    assert names == set(files), f"tables differ: {sorted(names ^ set(files))}"
    for entity in result.series:
        name = entity.strip("/").replace("/", "__").replace(".", "_")
        want = pd.read_parquet(files[name])
        pd.testing.assert_frame_equal(result[entity].reset_index(drop=True), want.reset_index(drop=True), check_exact=True)


def raises_naming(call, says, **kwargs):
    """`call(**kwargs)` raises ValueError whose message contains every word of `says`."""
    with pytest.raises(ValueError) as e:
        call(**kwargs)
    for word in says:
        assert word in str(e.value), f"{word!r} not in: {e.value}"


def without_timing(summary: dict) -> dict:
    """A summary without what depends on the machine (wall time, memory, the file's path)."""
    drop = {"wall_time_s", "steps_per_second", "samples_per_second", "peak_rss_mb", "recording_path", "recording_bytes", "gather_s", "analysis_s"}
    return {k: v for k, v in summary.items() if k not in drop}


# --- scenarios -------------------------------------------------------------------------------------


def test_scenarios_are_the_commands_presets(tmp_path):
    listed = [line.split()[0] for line in command("scenarios", cwd=tmp_path).stdout.splitlines() if line and not line.startswith(" ")]
    presets = rinscope.scenarios()
    assert list(presets) == listed
    assert rinscope.DEFAULT_SCENARIO in presets and all(presets.values())


def test_a_preset_reads_like_its_toml():
    tomllib = pytest.importorskip("tomllib")  # Python's own TOML reader (3.11+): not rinscope's
    for name in rinscope.scenarios():
        s = rinscope.load(name)
        assert s.to_dict() == tomllib.loads(rinscope._rinscope.preset_toml(name)), name
        # What the object writes, Python's reader reads back as the same document.
        assert tomllib.loads(s.toml) == s.to_dict(), name


def test_every_preset_survives_the_dict_round_trip():
    # The library's resolved config (every default written out) of the preset's own text and of the
    # text the dict writes back are the same.
    for name in rinscope.scenarios():
        original = rinscope._rinscope.check(rinscope._rinscope.preset_toml(name))
        assert rinscope._rinscope.check(rinscope.load(name).toml) == original, name


def test_keys_read_and_write_as_items_and_attributes(tmp_path):
    s = rinscope.load("jiang2017-dual-axis")
    inner = s.turntable.axis["inner"]
    assert inner.swing_half_angle_arcsec == s["turntable"]["axis"][1]["swing_half_angle_arcsec"] == 300.0
    inner.swing_half_angle_arcsec = 450
    assert s["turntable"]["axis"]["inner"]["swing_half_angle_arcsec"] == 450
    s["simulation"]["duration_s"] = 30.0
    s.scheme.rate["outer"].rate_deg_per_s = -5.0
    assert s.scheme.rate[0].rate_deg_per_s == -5.0
    s.turntable.axis["inner"].swing_half_angle_arcsec = np.arange(10)[4] * 100  # a numpy integer is a number
    assert s.turntable.axis["inner"].swing_half_angle_arcsec == 400 and "400" in s.toml
    s.recording.error_unit = "arcsec"
    del s.recording.error_unit  # back to the default
    assert "error_unit" not in s.recording
    with pytest.raises(ValueError, match="error_unit"):
        s.recording.error_unit = None
    s.turntable.axis["inner"].swing_half_angle_arcsec = 450
    s.simulation.update(duration_s=20.0, step_hz=100.0)
    assert (s.simulation.duration_s, s.simulation.step_hz) == (20.0, 100.0)
    path = s.save(tmp_path / "mine.toml")
    # The command validates and runs the file the object wrote.
    assert command("check-config", path, cwd=tmp_path).returncode == 0
    again = rinscope.load(path)
    assert again.turntable.axis["inner"].swing_half_angle_arcsec == 450 and again.to_dict() == s.to_dict()
    assert rinscope.load(s) is not s and rinscope.load(s).to_dict() == s.to_dict()
    assert rinscope.check(path).to_dict() == s.resolved().to_dict()
    resolved = s.resolved()
    assert "scene_hz" not in s.recording and resolved.recording.scene_hz > 0  # a default written out


@pytest.mark.parametrize(
    "section, key, value, says",
    [
        (("simulation",), "step_hzz", 5, ["step_hzz", "did you mean `step_hz`"]),
        (("turntable", "axis", "inner"), "swing_half_angle_arcsec", -3, ["swing_half_angle_arcsec", "-3", "arcsec", "out of range"]),
        (("turntable", "axis", "inner"), "swing_half_angle_arcsec", float("nan"), ["swing_half_angle_arcsec", "nan", "not a finite number"]),
        (("simulation",), "duration_s", "ten", ["duration_s", "ten"]),
        (("site",), "latitude_deg", 95.0, ["latitude_deg", "95"]),
    ],
)
def test_a_bad_write_raises_with_the_key_and_changes_nothing(section, key, value, says):
    s = rinscope.load("jiang2017-dual-axis")
    before = s.toml
    target = s
    for k in section:
        target = target[k]
    raises_naming(lambda: target.__setitem__(key, value), says)
    assert s.toml == before


def test_saving_a_scenario_over_a_fifo_or_into_a_missing_folder_is_refused(tmp_path):
    s = rinscope.load()
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match="FIFO"):
        s.save(fifo)
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)  # still there, not replaced by a file
    with pytest.raises(OSError, match="does not exist"):
        s.save(tmp_path / "missing" / "s.toml")
    good = s.save(tmp_path / "s.toml")
    assert rinscope.load(good).to_dict() == s.to_dict() and not list(tmp_path.glob("*.partial"))


def test_a_bad_file_or_name_is_refused_with_its_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(rinscope._rinscope.preset_toml("jiang2017-dual-axis").replace("step_hz = 200.0", "step_hzz = 200.0"))
    with pytest.raises(ValueError, match="step_hzz"):
        rinscope.load(bad)
    with pytest.raises(ValueError, match="jiang2017-dual-axis"):  # the list of presets
        rinscope.load("jiang2017-dual-axes")
    with pytest.raises(FileNotFoundError):
        rinscope.load(tmp_path / "missing.toml")
    with pytest.raises(AttributeError, match="step_hz"):
        rinscope.load().simulation.step_hzz


# --- run ---------------------------------------------------------------------------------------------


def test_run_gives_the_commands_summary_and_tables(tmp_path):
    r = rinscope.run("jiang2017-dual-axis", duration_s=60, save=tmp_path / "py.rrd")
    rinscope.verify_recording(tmp_path / "py.rrd")
    assert r.recording == tmp_path / "py.rrd" and r.summary["recording_path"] == str(tmp_path / "py.rrd")
    command("run", "--scenario", "jiang2017-dual-axis", "--duration-s", 60, "--save", "cli.rrd", "--export", "tables", "--summary-json", "s.json", cwd=tmp_path)
    assert without_timing(r.summary) == without_timing(json.loads((tmp_path / "s.json").read_text()))
    same_tables(r, tmp_path / "tables")
    heading = r["attitude_error_arcmin/heading"]
    assert heading.columns[0] == "t_s" and heading.t_s.iloc[-1] == pytest.approx(60.0)
    # The summary's peak is the table's (the table is the series at the recording's rate).
    peak = r.summary["attitude_error_arcsec"]["uncompensated"]["heading"]["peak_arcsec"]
    assert heading["uncompensated_arcmin"].abs().max() * 60 == pytest.approx(peak, rel=0.02)


def test_run_without_a_recording_and_a_scenario_object():
    s = rinscope.load("jiang2017-dual-axis")
    s.turntable.axis["inner"].swing_half_angle_arcsec = 0.0
    s.turntable.axis["outer"].swing_half_angle_arcsec = 0.0
    s.turntable.axis["inner"].non_orthogonality_arcsec = 0.0
    r = rinscope.run(s, duration_s=10)
    assert r.recording is None and "recording_path" not in r.summary or r.summary["recording_path"] is None
    # No table error: the uncompensated attitude error is zero to rounding.
    assert r["attitude_error_arcsec/heading"].iloc[:, 1:].abs().max().max() < 1e-6


def test_runs_in_threads_are_the_runs_one_after_the_other():
    from concurrent.futures import ThreadPoolExecutor

    base = rinscope.load("jiang2017-dual-axis")

    def peak(alpha):
        s = base.copy()
        s.turntable.axis["inner"].swing_half_angle_arcsec = alpha
        r = rinscope.run(s, duration_s=120)
        return r.summary["attitude_error_arcsec"]["uncompensated"]["heading"]["peak_arcsec"], r["attitude_error_arcmin/heading"]

    alphas = [0.0, 300.0, 600.0, 900.0]
    serial = [peak(a) for a in alphas]
    with ThreadPoolExecutor(4) as ex:
        parallel = list(ex.map(peak, alphas))
    for (p1, t1), (p2, t2) in zip(serial, parallel):
        assert p1 == p2
        pd.testing.assert_frame_equal(t1, t2, check_exact=True)
    assert len({p for p, _ in serial}) == len(alphas)  # the sweep changed something


@pytest.mark.parametrize("duration_s", [-1.0, 0.0, float("nan"), 1e9])
def test_run_refuses_a_bad_duration(duration_s):
    with pytest.raises(ValueError, match="duration_s"):
        rinscope.run(duration_s=duration_s)


def test_ctrl_c_stops_a_run_cleanly(tmp_path):
    script = tmp_path / "long.py"
    script.write_text(
        "import rinscope, sys\n"
        "try:\n"
        "    rinscope.run(duration_s=2_000_000, save='long.rrd')\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True); sys.exit(130)\n"
        "print('finished')\n"
    )
    # SIGINT at its default, so that Python installs its handler (a shell's background job ignores it).
    p = subprocess.Popen([sys.executable, str(script)], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.time() + 60
    while not (tmp_path / "long.rrd.partial").exists() and time.time() < deadline and p.poll() is None:
        time.sleep(0.05)
    time.sleep(1.0)
    sent = time.time()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 130 and "interrupted" in out, (p.returncode, out, err)
    assert time.time() - sent < 10, "the run did not stop promptly"
    rinscope.verify_recording(tmp_path / "long.rrd")  # complete up to that moment
    assert not (tmp_path / "long.rrd.partial").exists()


def test_a_notebooks_interrupt_stops_a_run_and_the_kernel_lives_on(tmp_path):
    # A real Jupyter kernel (ipykernel) driven by jupyter_client, interrupted as a notebook's
    # "interrupt the kernel" button does it (km.interrupt_kernel: SIGINT to the kernel).
    jupyter_client = pytest.importorskip("jupyter_client")
    pytest.importorskip("ipykernel")
    km, kc = jupyter_client.manager.start_new_kernel(kernel_name="python3", cwd=str(tmp_path))
    try:
        msg_id = kc.execute("import rinscope\nr = rinscope.run(duration_s=2_000_000, save='nb.rrd')")
        deadline = time.time() + 60
        while not (tmp_path / "nb.rrd.partial").exists() and time.time() < deadline:
            time.sleep(0.05)
        time.sleep(1.0)
        sent = time.time()
        km.interrupt_kernel()
        while True:
            reply = kc.get_shell_msg(timeout=60)
            if reply["parent_header"].get("msg_id") == msg_id:
                break
        assert reply["content"]["status"] == "error" and reply["content"]["ename"] == "KeyboardInterrupt", reply["content"]
        assert time.time() - sent < 10
        rinscope.verify_recording(tmp_path / "nb.rrd")  # complete up to that moment
        # The kernel goes on: the next cell runs.
        after = kc.execute_interactive("r = rinscope.run(duration_s=5)\nassert not r.summary['interrupted']", timeout=60)
        assert after["content"]["status"] == "ok", after["content"]
    finally:
        kc.stop_channels()
        km.shutdown_kernel(now=True)


# --- replay and calibrate ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def logset(tmp_path_factory):
    d = tmp_path_factory.mktemp("logs")
    command("export-log", "--scenario", "jiang2017-calibration", "--out", "set", "--format", "parquet", cwd=d)
    return d / "set"


def test_replay_gives_the_commands_summary_and_tables(logset, tmp_path):
    r = rinscope.replay(logset, save=tmp_path / "r.rrd")
    rinscope.verify_recording(tmp_path / "r.rrd")
    command("replay", logset, "--save", "cli.rrd", "--export", "tables", "--summary-json", "s.json", cwd=tmp_path)
    want = json.loads((tmp_path / "s.json").read_text())
    assert without_timing(r.summary) == without_timing(want)
    same_tables(r, tmp_path / "tables")


def test_replay_refuses_a_missing_log_set(tmp_path):
    with pytest.raises(ValueError, match="nowhere"):
        rinscope.replay(tmp_path / "nowhere")


def test_calibrate_gives_the_commands_report(tmp_path, logset):
    c = rinscope.calibrate(save=tmp_path / "c.rrd")
    rinscope.verify_recording(tmp_path / "c.rrd")
    command("calibrate", "--json", "c.json", "--no-recording", cwd=tmp_path)
    want = json.loads((tmp_path / "c.json").read_text())
    assert c.summary["estimated_compensation"] == want["estimated_compensation"]
    assert c.summary["state"] == want["state"]
    assert "calibration/error_arcsec/heading" in c.series
    # From a log set, and its estimates fed to a replay.
    cl = rinscope.calibrate(log_dir=logset)
    command("calibrate", "--log", logset, "--json", "cl.json", "--no-recording", cwd=tmp_path)
    assert cl.summary["estimated_compensation"] == json.loads((tmp_path / "cl.json").read_text())["estimated_compensation"]
    r = rinscope.replay(logset, compensation=cl)
    command("replay", logset, "--compensation", "cl.json", "--summary-json", "rs.json", "--save", "rs.rrd", cwd=tmp_path)
    assert r.summary["attitude_error_arcsec"] == json.loads((tmp_path / "rs.json").read_text())["attitude_error_arcsec"]


# --- allan ------------------------------------------------------------------------------------------


def nbs14_1000():
    """NIST SP 1065 p. 107: n0 = 1234567890, n(i+1) = 16807 n(i) mod (2^31 - 1), y = n / (2^31 - 1)."""
    n, y = 1234567890, []
    for _ in range(1000):
        y.append(n / 2147483647.0)
        n = 16807 * n % 2147483647
    return np.array(y)


def test_allan_reproduces_nists_published_deviations():
    # NIST SP 1065 p. 108 (Riley), the 1000-point NBS14 set at tau = 1, 10, 100 s, printed to 7 digits.
    published = {
        "adev": [2.922319e-01, 9.965736e-02, 3.897804e-02],
        "oadev": [2.922319e-01, 9.159953e-02, 3.241343e-02],
        "mdev": [2.922319e-01, 6.172376e-02, 2.170921e-02],
        "hdev": [2.943883e-01, 1.052754e-01, 3.910860e-02],
        "ohdev": [2.943883e-01, 9.581083e-02, 3.237638e-02],
    }
    a = rinscope.allan(pd.Series(nbs14_1000(), name="nbs14"), rate_hz=1.0, spec="frequency", taus="decade", estimators=",".join(published))
    for est, devs in published.items():
        table = a.series[f"allan/clock_nbs14_{est}"]
        for tau, want in zip([1.0, 10.0, 100.0], devs):
            got = table.loc[table.tau_s == tau, "dev_frac"].iloc[0]
            assert got == pytest.approx(want, rel=2e-6), (est, tau)


def test_allan_of_a_gyro_array_fits_the_angle_random_walk():
    # White rate noise of N = 0.01 deg/sqrt(h) at 100 Hz: sigma per sample = N * sqrt(rate) (IEEE 952).
    rate_hz, n_deg_sqrt_h = 100.0, 0.01
    sigma_deg_h = n_deg_sqrt_h * 60.0 * math.sqrt(rate_hz)  # deg/h per sample
    x = np.random.default_rng(7).normal(0.0, sigma_deg_h, size=(360_000, 1))
    a = rinscope.allan(x, rate_hz=rate_hz, spec="rate:deg/h")
    n = a.summary["gyro"][0]["fitted"]["n_deg_per_sqrt_h"]
    # Within 4 of the fit's own 1-sigma of the N the data were drawn with (two-sided).
    assert n["significant"] and abs(n["value"] - n_deg_sqrt_h) < 4 * n["sigma"], n
    assert n["sigma"] < 0.01 * n_deg_sqrt_h
    fit = a.series["allan/gyro_fit"]
    assert fit["n_deg_per_sqrt_h"].iloc[0] == n["value"]
    assert a.series["allan/gyro_0"].columns[0] == "tau_s"


@pytest.mark.parametrize(
    "kwargs, says",
    [
        (dict(data=[1.0, float("nan"), 2.0] * 10, rate_hz=1.0), ["x", "sample 1", "NaN"]),
        (dict(data=[1.0, 2.0] * 10), ["rate_hz", "time_s"]),
        (dict(data={"gyro": [1.0, 2.0] * 10}, rate_hz=1.0, spec="rate"), ["gyro", "unit"]),
        (dict(data={"gyro": [1.0, 2.0] * 10}, rate_hz=1.0, spec="rate:ns"), ["gyro", "ns"]),
        (dict(data=[1.0, 2.0] * 10, rate_hz=-5.0), ["rate_hz", "-5"]),
        (dict(data=[1.0, 2.0] * 10, time_s=[0, 1, 2, 3, 4, 5, 6, 7, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20]), ["time_s", "step"]),
        (dict(data=[1.0, 2.0] * 10, rate_hz=1.0, taus="sometimes"), ["taus", "sometimes"]),
        (dict(data=[1.0, 2.0] * 10, rate_hz=1.0, estimators="adev,xdev"), ["xdev"]),
    ],
)
def test_allan_refuses_bad_input_by_name(kwargs, says):
    raises_naming(rinscope.allan, says, **kwargs)


def test_allan_of_arrays_is_the_commands_allan_of_the_file(tmp_path):
    # The same gyro samples written by pandas as CSV and analysed by `rinscope allan --series`: the
    # command reads the file, the package takes the arrays; the tables agree to the CSV's digits.
    rng = np.random.default_rng(3)
    df = pd.DataFrame({"t": np.arange(20_000) * 0.01, "gz": rng.normal(0.0, 6.0, 20_000) + 0.5})
    df.to_csv(tmp_path / "gyro.csv", index=False, float_format="%.17g")
    command("allan", "--series", "gyro.csv", "--column", "gz:rate:deg/h", "--time-column", "t", "--estimator", "oadev,mdev",
            "--export", "tables", "--no-recording", cwd=tmp_path)
    a = rinscope.allan(df[["gz"]], time_s=df.t, spec="rate:deg/h", estimators="oadev,mdev")
    files = {f.stem: f for f in (tmp_path / "tables").glob("*.parquet")}
    assert {e.replace("/", "__") for e in a.series} == set(files)
    for entity in a.series:
        pd.testing.assert_frame_equal(a[entity], pd.read_parquet(files[entity.replace("/", "__")]), rtol=1e-12)


def test_allan_with_times_equals_allan_with_a_rate():
    y = nbs14_1000()
    by_rate = rinscope.allan(y, rate_hz=2.0)
    by_time = rinscope.allan(y, time_s=np.arange(1000) * 0.5)
    pd.testing.assert_frame_equal(by_rate.series["allan/clock_x_oadev"], by_time.series["allan/clock_x_oadev"])


# --- montecarlo ------------------------------------------------------------------------------------


def test_montecarlo_statistics_are_those_of_its_runs():
    m = rinscope.montecarlo(runs=12)
    runs, rows = m["runs"], m.summary["rows"]
    assert len(runs) == 12 and m.summary["rows"]
    for row in rows:
        for est in ("kf", "nls"):
            col = runs[f"{est} {row['label']}"]
            # pandas' mean and sample std (ddof = 1) of the per-run errors: an independent computation.
            assert col.mean() == pytest.approx(row[est]["mean"], rel=1e-9, abs=1e-12)
            assert col.std() == pytest.approx(row[est]["std"], rel=1e-9, abs=1e-12)
            assert col.abs().max() == pytest.approx(row[est]["max_abs"], rel=1e-12)


def test_montecarlo_refuses_zero_runs():
    with pytest.raises(ValueError, match="runs 0"):
        rinscope.montecarlo(runs=0)


# --- sweep -----------------------------------------------------------------------------------------


def test_sweep_points_are_the_runs_of_their_scenarios():
    key = "turntable.axis[1].swing_half_angle_arcsec"
    r = rinscope.sweep(vary={key: [0, 600]}, duration_s=60, threads=2)
    points = r["points"]
    assert list(points[key]) == [0.0, 600.0] and r.summary["threads"] == 2
    for value, row in zip((0, 600), points.to_dict("records")):
        s = rinscope.load("jiang2017-dual-axis")
        s.turntable.axis["inner"].swing_half_angle_arcsec = value
        alone = rinscope.run(s, duration_s=60)
        want = alone.summary["attitude_error_arcsec"]["uncompensated"]["heading"]["rms_arcsec"]
        assert row["uncompensated heading rms_arcsec"] == want


def test_sweep_refuses_a_key_the_scenario_cannot_take():
    with pytest.raises(ValueError, match="swing_half_angle_arcsex"):
        rinscope.sweep(vary={"turntable.axis[1].swing_half_angle_arcsex": [1]}, duration_s=10)


# --- budget ----------------------------------------------------------------------------------------


def test_budget_gives_the_commands_document_and_every_part(tmp_path):
    # Python and the command line: one owner, the same numbers; the series add up as the summary says.
    r = rinscope.budget(hours=0.25, save=tmp_path / "b.rrd")
    rinscope.verify_recording(tmp_path / "b.rrd")
    command("budget", "--hours", 0.25, "--json", "b.json", "--save", "c.rrd", cwd=tmp_path)
    want = json.loads((tmp_path / "b.json").read_text())
    for got, row in zip(r.summary["rows"], want["rows"]):
        assert got["source"] == row["source"] and got["channels"] == row["channels"], row["source"]
    east = r["budget/position_east_m"]
    parts = [c for c in east.columns if c not in ("t_s", "full_run_m", "baseline_plus_parts_m", "baseline_m")]
    assert len(parts) == len(r.summary["rows"]) - 4
    total = east[parts].sum(axis=1) + east["baseline_m"]
    assert (total - east["baseline_plus_parts_m"]).abs().max() < 1e-9
    remainder = (east["full_run_m"] - east["baseline_plus_parts_m"]).abs().max()
    row = next(x for x in r.summary["rows"] if x["kind"] == "remainder")
    assert abs(remainder - row["channels"]["position_east_m"]["peak"]) < 1e-12


def test_schemes_give_the_commands_document(tmp_path):
    # Python and the command line: one owner (app::schemes), the same rows on the same seeds; a user's
    # scheme file (written here, in the documented [scheme] format) runs beside a built-in; a name that
    # is neither is refused with the built-ins named.
    (tmp_path / "two.toml").write_text(
        "[scheme]\nkind = \"indexed\"\nrepeat = true\n"
        "[[scheme.step]]\naxis = \"inner\"\nangle_deg = 180.0\nrate_deg_per_s = 10.0\ndwell_s = 300.0\n"
        "[[scheme.step]]\naxis = \"inner\"\nangle_deg = -180.0\nrate_deg_per_s = 10.0\ndwell_s = 300.0\n")
    names = ["none", "dual-axis-16", str(tmp_path / "two.toml")]
    r = rinscope.schemes(schemes=names, hours=0.5, seeds=2, save=tmp_path / "s.rrd")
    rinscope.verify_recording(tmp_path / "s.rrd")
    command("schemes", "--schemes", ",".join(names), "--hours", 0.5, "--seeds", 2, "--json", "s.json",
            "--save", "c.rrd", cwd=tmp_path)
    want = json.loads((tmp_path / "s.json").read_text())
    assert [row["scheme"] for row in r.summary["rows"]] == names
    assert r.summary["rows"] == want["rows"] and r.summary["seeds"] == want["seeds"]
    two = r.summary["rows"][2]
    assert dict(two["turned_deg"])["inner"] > 0 and dict(two["wrap_deg"])["inner"] == pytest.approx(180, abs=1e-6)
    with pytest.raises(ValueError, match="neither a built-in scheme .*dual-axis-64"):
        rinscope.schemes(schemes=["dual-axis-17"], hours=0.1)


def test_design_gives_the_commands_document_and_a_scheme_that_runs(tmp_path):
    # Python and the command line: one owner (app::design), the same ranking and numbers on the same
    # seed; the designed [scheme] (TOML text) runs in `schemes` and gives the exact row it was ranked by.
    kw = dict(hours=2, moves=[4, 8], candidates=40, confirm=2, seeds=1)
    r = rinscope.design(**kw)
    command("design", "--hours", 2, "--moves", "4,8", "--candidates", 40, "--confirm", 2, "--seeds", 1,
            "--json", "d.json", "--save", "d.rrd", "--save-scheme", "best.toml", cwd=tmp_path)
    want = json.loads((tmp_path / "d.json").read_text())
    for key in ("best", "best_built_in", "ratio", "drawn", "distinct"):
        assert r.summary[key] == want[key], key
    assert [x["label"] for x in r.summary["ranked"]] == [x["label"] for x in want["ranked"]]
    best = next(x for x in want["ranked"] if x["label"] == want["best"])
    assert (tmp_path / "best.toml").read_text().endswith(best["scheme"])
    again = rinscope.schemes(schemes=[str(tmp_path / "best.toml")], hours=2, seeds=1, modulable_only=True)
    assert again.summary["rows"][0]["position_end_m"] == best["exact"]["position_end_m"]


# --- selfcal ---------------------------------------------------------------------------------------


def test_selfcal_gives_the_commands_document(tmp_path):
    r = rinscope.selfcal(navigate_hours=0, save=tmp_path / "s.rrd")
    rinscope.verify_recording(tmp_path / "s.rrd")
    command("selfcal", "--navigate-hours", 0, "--no-recording", "--json", "s.json", cwd=tmp_path)
    want = json.loads((tmp_path / "s.json").read_text())
    for key in ("sequence", "parameters", "truth", "estimate", "sigma", "observability"):
        assert r.summary[key] == want[key], key
    assert "Kg_xx" in r.summary["table"]
    err = r["selfcal/error/Kg_xx_ppm"]
    assert err.columns[0] == "t_s" and len(err) > 100


def test_run_takes_the_selfcal_compensation_as_the_command_does(tmp_path):
    # The whole compensation document selfcal writes (the table's part and the IMU's), applied in
    # the loop by Python and by `run --compensation`: the same summary.
    doc = {"estimated_imu_compensation": {"frame": "accelerometer triad", "gyro_bias_deg_per_h": [0.01, -0.01, 0.005],
                                          "gyro_gain_ppm": [[10, 0, 0], [0, -5, 0], [0, 0, 3]], "accel_bias_ug": [50, -7, 30],
                                          "accel_gain_ppm": [[-7, 0, 0], [0, 37, 0], [0, 0, -11]]},
           "estimated_compensation": {"axis": {"inner": {"encoder_scale_ppm": -20.0}}}}
    (tmp_path / "c.json").write_text(json.dumps(doc))
    r = rinscope.run("selfcal-nav-grade", duration_s=30, compensation=doc)
    command("run", "--scenario", "selfcal-nav-grade", "--duration-s", 30, "--compensation", "c.json", "--save", "r.rrd",
            "--summary-json", "s.json", cwd=tmp_path)
    want = json.loads((tmp_path / "s.json").read_text())
    assert r.summary["ins_attitude_error_arcsec"] == want["ins_attitude_error_arcsec"]
    plain = rinscope.run("selfcal-nav-grade", duration_s=30)
    assert plain.summary["ins_attitude_error_arcsec"] != r.summary["ins_attitude_error_arcsec"]
    doc["estimated_imu_compensation"]["accel_bias_ug"][1] = 1e9
    raises_naming(rinscope.run, ["accel_bias_ug[1]"], scenario="selfcal-nav-grade", duration_s=30, compensation=doc)


@pytest.mark.parametrize("kwargs, says", [(dict(sequence="dual-axis-30"), ["dual-axis-30", "positions-19"]), (dict(navigate_hours=-1), ["navigate_hours", "-1"]), (dict(monte_carlo=0), ["monte_carlo", "0"])])
def test_selfcal_refuses_bad_input_by_name(kwargs, says):
    raises_naming(rinscope.selfcal, says, **kwargs)


# --- the command and the viewer --------------------------------------------------------------------------


def test_the_command_is_rinscopes(tmp_path):
    assert "rinscope" in command("--help", cwd=tmp_path).stdout
    bad = tmp_path / "bad.toml"
    bad.write_text("[scenario]\nname = \"x\"\ntitle = \"x\"\n[simulation]\nstep_hzz = 5\n")
    p = command("check-config", bad, cwd=tmp_path, check=False)
    assert p.returncode == 2 and "step_hzz" in p.stderr


def test_show_needs_a_recording_and_gives_rerun_s_notebook_viewer(tmp_path):
    with pytest.raises(ValueError, match="save="):
        rinscope.run(duration_s=5).show()
    pytest.importorskip("rerun_notebook")
    viewer = rinscope.run(duration_s=5, save=tmp_path / "v.rrd").show()
    assert type(viewer).__module__ == "rerun.notebook"
