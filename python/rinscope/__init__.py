"""rinscope from Python: see the errors of a rotational inertial navigation system.

The Rust library computes everything; this package converts. Scenarios in (``load``), results
out: a summary dict and every recorded series as a pandas DataFrame, in memory::

    import rinscope
    s = rinscope.load("jiang2017-dual-axis")
    s.table.inner.swing_half_angle_arcsec = 450
    r = rinscope.run(s, duration_s=600, save="x.rrd")
    r.summary["attitude_error_arcsec"]["heading"]["uncompensated"]["peak"]
    r["attitude_error_arcsec/heading"]          # a DataFrame: t_s, one column per series
    r.show()                                    # the recording, inline in a notebook

Ctrl-C (a notebook's interrupt) stops a call cleanly: the work finishes what it has (a saved
recording ends complete up to that moment) and KeyboardInterrupt is raised. The ``rinscope``
command installed with the package is the command-line program itself.
"""
from __future__ import annotations

import json as _json
import os
from pathlib import Path
from typing import Any

from . import _rinscope
from ._result import Result, Tables, result as _result
from ._scenario import Scenario, Section

__all__ = ["scenarios", "load", "check", "run", "replay", "calibrate", "allan", "montecarlo", "sweep", "budget", "schemes", "design", "selfcal", "verify_recording", "Scenario", "Section", "Result", "Tables", "DEFAULT_SCENARIO", "__version__"]

__version__ = _rinscope.VERSION
DEFAULT_SCENARIO = _rinscope.DEFAULT_SCENARIO


def scenarios() -> dict:
    """The presets: {name: title}, in the order ``rinscope scenarios`` lists them."""
    return dict(_rinscope.scenarios())


def load(source: str | os.PathLike | Scenario = DEFAULT_SCENARIO) -> Scenario:
    """A scenario: a preset's name (``rinscope.scenarios()``), a ``.toml`` file, or a Scenario (copied).
    A file is validated as ``rinscope check-config`` validates it (ValueError naming the key)."""
    if isinstance(source, Scenario):
        return source.copy()
    text = str(source)
    if text in _rinscope.PRESETS:
        return Scenario(_rinscope.preset_toml(text), f"preset {text}")
    path = Path(text)
    if path.is_file():
        return Scenario(path.read_text(encoding="utf-8"), str(path))
    if path.suffix == ".toml" or os.sep in text:
        raise FileNotFoundError(f"{text}: no such scenario file")
    raise ValueError(f"{text!r} is neither a preset nor a file; the presets are: {', '.join(_rinscope.PRESETS)}")


def check(source: str | os.PathLike | Scenario) -> Scenario:
    """Validates a scenario (as ``load``) and returns it with every default written out."""
    return load(source).resolved()


def _toml(scenario: Any, default: str) -> str:
    # A Scenario is valid (every write was checked): its text as it is, without a second check.
    if isinstance(scenario, Scenario):
        return scenario.toml
    return load(default if scenario is None else scenario).toml


def _path(p):
    return None if p is None else str(Path(p))


def _compensation_text(compensation: Any) -> str | None:
    """A compensation document as text: a ``calibrate``/``selfcal`` Result, its summary dict, or a path."""
    if isinstance(compensation, Result):
        compensation = compensation.summary
    if isinstance(compensation, dict):
        return _json.dumps(compensation)
    if compensation is not None:
        return Path(compensation).read_text(encoding="utf-8")
    return None


def run(scenario: Any = None, duration_s: float | None = None, save: str | os.PathLike | None = None,
        compensation: Any = None) -> Result:
    """Simulates a scenario (a Scenario, a preset's name or a file; default: the default preset)
    for ``duration_s`` (default: its own), saving the recording to ``save`` if given, compensated
    with ``compensation`` (a ``selfcal``/``calibrate`` Result, its summary dict, or the path of
    their ``--json``: the table's part and the IMU's, as ``rinscope run --compensation``).
    ``summary`` is ``rinscope run --summary-json``'s; ``series`` every recorded series."""
    toml = _toml(scenario, DEFAULT_SCENARIO)
    return _result("run", _rinscope.run(toml, duration_s, _path(save), _compensation_text(compensation)), "recording_path")


def replay(log_dir: str | os.PathLike, save: str | os.PathLike | None = None, compensation: Any = None) -> Result:
    """Replays a log set (a folder with ``log.toml``), with its table's compensation or
    ``compensation``: a ``calibrate`` or ``selfcal`` Result, its summary dict, or the path of their ``--json``."""
    return _result("replay", _rinscope.replay(str(log_dir), _path(save), _compensation_text(compensation)), "recording_path")


def calibrate(scenario: Any = None, log_dir: str | os.PathLike | None = None, save: str | os.PathLike | None = None) -> Result:
    """Calibrates a table: of a scenario (default: jiang2017-calibration) or of a log set
    (``log_dir``). ``summary`` is ``calibrate --json``'s (with ``estimated_compensation``, which
    ``replay(..., compensation=result)`` takes); ``series`` the recording's series."""
    toml = None if log_dir is not None and scenario is None else _toml(scenario, "jiang2017-calibration")
    return _result("calibrate", _rinscope.calibrate(toml, _path(log_dir), _path(save)), None, save)


def allan(data: Any, rate_hz: float | None = None, time_s: Any = None, spec: str | dict = "frequency",
          taus: str | int = "octave", estimators: str = "oadev", ci_sigma: float = 1.0, decimate: int = 1,
          save: str | os.PathLike | None = None) -> Result:
    """The Allan analysis (IEEE 952 fit for inertial columns) of arrays: a 1-D array (one column),
    a 2-D array (one column per column), a pandas Series or DataFrame, or a dict of arrays;
    sampled at ``rate_hz`` or at the times ``time_s`` (s, even to 1 %). ``spec`` says what the
    values are, as ``allan --column`` does after the column's name: ``"KIND[:UNIT]"`` for every
    column or a dict per column — ``"rate:deg/h"`` (a gyro), ``"rate:m/s^2"``, ``"increment:rad"``,
    ``"phase:ns"``, ``"frequency"`` (a clock's fractional frequency, the default).
    ``summary`` is ``allan --json``'s; ``series`` the curves and fits (``allan --export``'s tables)."""
    import numpy as np

    columns = _columns(data)
    specs, buffers = [], []
    for name, values in columns.items():
        kind = spec.get(name) if isinstance(spec, dict) else spec
        if kind is None:
            raise ValueError(f"allan: column {name!r} has no spec (give spec={{{name!r}: 'KIND[:UNIT]'}})")
        specs.append(f"{name}:{kind}")
        buffers.append(np.ascontiguousarray(values, dtype="<f8").tobytes())
    times = None if time_s is None else np.ascontiguousarray(np.asarray(time_s), dtype="<f8").tobytes()
    out = _rinscope.allan(specs, buffers, rate_hz, times, str(taus), estimators, ci_sigma, decimate, _path(save))
    return _result("allan", out, None, save)


def _columns(data: Any) -> dict:
    """Named 1-D columns of whatever array-like the user has."""
    import numpy as np

    try:
        import pandas as pd
    except ImportError:  # pandas is a dependency; this only keeps numpy-only use possible
        pd = None
    if pd is not None and isinstance(data, pd.DataFrame):
        return {str(c): data[c].to_numpy() for c in data.columns}
    if pd is not None and isinstance(data, pd.Series):
        return {str(data.name) if data.name is not None else "x": data.to_numpy()}
    if isinstance(data, dict):
        return {str(k): np.asarray(v) for k, v in data.items()}
    a = np.asarray(data)
    if a.ndim == 1:
        return {"x": a}
    if a.ndim == 2:
        return {str(i): a[:, i] for i in range(a.shape[1])}
    raise ValueError(f"allan: data of shape {a.shape}: give one column (1-D) or one per column (2-D)")


def montecarlo(scenario: Any = None, runs: int | None = None, eta_measured_sigma_arcsec: float | None = None) -> Result:
    """Monte Carlo of the calibration (default scenario: jiang2017-calibration): ``runs``
    calibrations on every core. ``summary`` is ``montecarlo --json``'s; ``series["runs"]`` each
    run's estimation errors, one row per run and a column per estimator and parameter ("kf inner α",
    "nls inner α", "nls_sigma inner α": the least squares' own 1σ); ``series["rows"]`` the
    summary's table (mean, std, ... of each estimator's errors per parameter, with the paper's)."""
    import pandas as pd

    summary = _json.loads(_rinscope.montecarlo(_toml(scenario, "jiang2017-calibration"), runs, eta_measured_sigma_arcsec))
    labels = [row["label"] for row in summary["rows"]]
    per_run = pd.DataFrame(
        [{"run": run["index"], **{f"{est} {label}": v for est in ("kf", "nls", "nls_sigma") for label, v in zip(labels, run[est])}} for run in summary.pop("runs")]
    )
    rows = pd.json_normalize(summary["rows"], sep="_")
    return Result("montecarlo", summary, Tables([], {"runs": per_run, "rows": rows}), None)


def sweep(scenario: Any = None, vary: dict | None = None, seeds: int = 1, duration_s: float | None = None,
          threads: int | None = None) -> Result:
    """A scenario over a grid, in parallel on every core (``rinscope sweep``): ``vary`` maps scenario
    keys to their values (``{"turntable.axis[1].swing_half_angle_arcsec": [0, 300, 600]}``; several
    keys: every combination), ``seeds`` consecutive seeds from the scenario's at every point, every
    point a whole run without a recording. ``summary`` is ``sweep --json``'s; ``series["points"]``
    one row per run: the varied values, the seed, and every RMS and peak of its summary
    (``uncompensated heading rms_arcsec``, ``ins two-sample heading peak_arcsec``, ``peak_radial_m``)."""
    import pandas as pd

    pairs = [(str(k), [float(x) for x in v]) for k, v in (vary or {}).items()]
    summary = _json.loads(_rinscope.sweep(_toml(scenario, DEFAULT_SCENARIO), pairs, seeds, duration_s, threads))
    rows = []
    for p in summary["points"]:
        row = {k: v for k, v in p["values"]}
        row["seed"] = p["seed"]
        s = p["summary"]
        for variant, axes in s.get("attitude_error_arcsec", {}).items():
            for axis, stat in axes.items():
                for name, v in stat.items():
                    row[f"{variant} {axis} {name}"] = v
        for alg, axes in (s.get("ins_attitude_error_arcsec") or {}).items():
            for axis, stat in axes.items():
                for name, v in stat.items():
                    row[f"ins {alg} {axis} {name}"] = v
        nav = s.get("navigation") or {}
        for name in ("peak_radial_m", "final_radial_m"):
            if name in nav:
                row[name] = nav[name]
        rows.append(row)
    return Result("sweep", summary, Tables([], {"points": pd.DataFrame(rows)}), None)


def budget(scenario: Any = None, hours: float | None = None, sample_s: float | None = None,
           threads: int | None = None, save: str | os.PathLike | None = None) -> Result:
    """The error budget (``rinscope budget``, docs/budget.md): the scenario (default
    ``budget-dual-axis-16``) with each error source alone, with none and with all, in parallel.
    ``summary`` is ``budget --json``'s (per source: every channel's value at the end, peak and RMS;
    the remainder's share); ``series["budget/position_east_m"]`` and the other channels: one column
    per source's part, the full run, the baseline and their sum."""
    out = _rinscope.budget(_toml(scenario, "budget-dual-axis-16"), hours, sample_s, threads, _path(save))
    return _result("budget", out, None, save)


def schemes(scenario: Any = None, schemes: list | tuple = (), hours: float | None = None, seeds: int = 4,
            budget: bool = False, modulable_only: bool = False, threads: int | None = None,
            save: str | os.PathLike | None = None) -> Result:
    """Rotation schemes side by side (``rinscope schemes``, docs/schemes.md): each scheme (a built-in's
    name, ``none``, ``single-axis-4``, ``continuous``, ``dual-axis-8/16/32/64``, or a file with a
    ``[scheme]``; none given: every built-in) replaces the scenario's (default ``budget-dual-axis-16``)
    and runs on the same ``seeds``. ``summary`` is ``schemes --json``'s (per scheme: position at 24 h and
    at the end, peak heading, median and range over the seeds; degrees turned; cable wrap; with
    ``budget=True`` the sources it leaves largest; ``modulable_only=True``: no noise, no alignment
    error, as ``--modulable-only``); the series are the recording's."""
    names = [str(s) for s in ([schemes] if isinstance(schemes, (str, os.PathLike)) else schemes)]
    out = _rinscope.schemes(_toml(scenario, "budget-dual-axis-16"), names, hours, seeds, budget, modulable_only, threads,
                            _path(save))
    return _result("schemes", out, None, save)


def design(scenario: Any = None, hours: float | None = None, axes: list | tuple = (), moves: list | tuple = (8, 16, 32),
           angles_deg: list | tuple = (180.0,), rates_deg_per_s: list | tuple = (), dwells_s: list | tuple = (),
           max_wrap_deg: float = 360.0, candidates: int = 1000, refine: int = 300, confirm: int = 4, seeds: int = 4,
           threads: int | None = None, save: str | os.PathLike | None = None) -> Result:
    """The rotation-scheme designer (``rinscope design``, docs/schemes.md): ``candidates`` indexing
    sequences drawn under the constraints (the axes that may move, moves per period, move angles,
    rates and dwells — empty: the scenario's —, the cable's wrap), ``refine`` local moves from each of
    the model's 8 best, ranked with the built-ins by the averaged error model, the best ``confirm`` simulated beside the built-ins on ``seeds`` seeds.
    ``summary`` is ``design --json``'s: ``best`` (the designed scheme's label), ``ratio`` (the best
    built-in's position error ÷ the design's), ``ranked`` (each with its model terms, exact row and
    ``scheme``, a ``[scheme]`` TOML text to run with ``schemes``)."""
    out = _rinscope.design(_toml(scenario, "budget-dual-axis-16"), hours, list(axes), [int(m) for m in moves],
                           [float(a) for a in angles_deg], [float(r) for r in rates_deg_per_s],
                           [float(d) for d in dwells_s], max_wrap_deg, candidates, refine, confirm, seeds, threads,
                           _path(save))
    return _result("design", out, None, save)


def selfcal(scenario: Any = None, sequence: str = "dual-axis-29", monte_carlo: int | None = None, navigate_hours: float = 24.0,
            save: str | os.PathLike | None = None) -> Result:
    """Self-calibrates a scenario's IMU on its own gimbals (default scenario: selfcal-nav-grade;
    ``rinscope selfcal``): ``sequence`` "dual-axis-29", "positions-19", "azimuth-only" or
    "scenario" (its own indexed [scheme]); ``monte_carlo`` runs over random IMUs (1σ against
    spread); ``navigate_hours`` of free-inertial comparison (none / estimated / true compensation;
    0 skips it, 24 h take about 10 s). ``summary`` is ``selfcal --json``'s (21 parameters in SI:
    ``parameters``, ``estimate``, ``sigma``, ``truth``, the plan under ``observability``) with the
    printed table under ``"table"``; ``series`` the recording's (σ histories, estimate − truth)."""
    out = _rinscope.selfcal(_toml(scenario, "selfcal-nav-grade"), sequence, monte_carlo, navigate_hours, _path(save))
    return _result("selfcal", out, None, save)


def verify_recording(path: str | os.PathLike) -> None:
    """Raises ValueError unless the ``.rrd`` at ``path`` is complete (header, footer, checksum)."""
    _rinscope.verify_recording(str(path))
