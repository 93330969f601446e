"""What a call returns: the summary as a dict and every recorded series as a pandas DataFrame."""
from __future__ import annotations

import json as _json
from collections.abc import Mapping
from pathlib import Path
from typing import Iterator


class Tables(Mapping):
    """Every table of a result by entity path (``"attitude_error_arcsec/heading"``), also by its
    export name (``"attitude_error_arcsec__heading"``): a pandas DataFrame with the columns
    ``rinscope ... --export`` writes (``t_s`` first, the unit in each column's name). They arrive
    as Arrow IPC streams in memory and become DataFrames the first time they are read."""

    def __init__(self, streams: list, frames: dict | None = None):
        # (entity, export name, Arrow IPC stream) from the library; DataFrames made here (their
        # entity is their name).
        self._streams = {entity: stream for entity, _, stream in streams}
        self._names = {name: entity for entity, name, _ in streams}
        self._frames: dict = dict(frames or {})
        for key in self._frames:
            self._streams.setdefault(key, None)

    def _key(self, key: str) -> str:
        if key in self._streams:
            return key
        if key in self._names:
            return self._names[key]
        raise KeyError(f"{key!r}: no such table; the tables are: {', '.join(self._streams)}")

    def arrow(self, key: str):
        """The table as a pyarrow Table (no pandas)."""
        import pyarrow as pa

        entity = self._key(key)
        if self._streams[entity] is None:
            return pa.Table.from_pandas(self._frames[entity], preserve_index=False)
        return pa.ipc.open_stream(self._streams[entity]).read_all()

    def __getitem__(self, key: str):
        entity = self._key(key)
        if entity not in self._frames:
            self._frames[entity] = self.arrow(entity).to_pandas(split_blocks=True)
        return self._frames[entity]

    def __iter__(self) -> Iterator[str]:
        return iter(self._streams)

    def __len__(self) -> int:
        return len(self._streams)

    def __repr__(self) -> str:
        return f"<rinscope tables: {', '.join(self._streams)}>"


class Result:
    """A run's (or replay's, calibration's, analysis') outcome.

    - ``summary``: a dict, what the command's ``--summary-json`` / ``--json`` writes;
    - ``series``: every table by entity path, as pandas DataFrames (``result["ins/position_error_m"]``
      is short for ``result.series[...]``);
    - ``recording``: the saved ``.rrd`` (``save=...``), or None; ``show()`` puts it in a notebook.
    """

    def __init__(self, kind: str, summary: dict, series: Tables, recording: str | None):
        self.kind = kind
        self.summary = summary
        self.series = series
        self.recording = Path(recording) if recording else None

    def __getitem__(self, key: str):
        return self.series[key]

    def show(self, width: int | str = "auto", height: int | str = 640, theme: str = "dark"):
        """Shows the saved recording inline in a Jupyter notebook with Rerun's notebook viewer
        (``pip install "rerun-sdk[notebook]==0.36.3"``); returns the viewer widget.

        The widget loads the viewer from app.rerun.io; offline, set the environment variable
        ``RERUN_NOTEBOOK_ASSET=serve-local`` before the first call (the kernel then serves it)."""
        if self.recording is None:
            raise ValueError("this result has no recording: run it with save=\"x.rrd\" to view it")
        from rerun.notebook import Viewer

        viewer = Viewer(width=width, height=height, use_global_recording=False, theme=theme)
        # The widget takes an .rrd stream as bytes: what rr.notebook_show sends from a live
        # recording, here the whole saved file.
        viewer._viewer.send_rrd(self.recording.read_bytes())
        return viewer

    def __repr__(self) -> str:
        rec = f", recording {self.recording}" if self.recording else ""
        return f"<rinscope {self.kind} result: {len(self.series)} tables{rec}>"


def result(kind: str, out: tuple, recording_key: str | None = None, save=None) -> Result:
    summary_json, tables = out
    summary = _json.loads(summary_json)
    recording = summary.get(recording_key) if recording_key else (str(save) if save else None)
    return Result(kind, summary, Tables(tables), recording)
