//! A live session's recorders (`rinscope live`): what each feeds (viewers as it runs, the class
//! page's history for late viewers, the saved file), and what a reload changes in a recording.

use rerun::RecordingStreamResult;

use super::{Recorder, Stream, error_path};
use crate::scenario::Params;
use crate::sim::ERROR_AXES;

/// What a live session's recorder feeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LiveOutput {
    /// Viewers watching as it runs: small chunks sent at a wall-clock cadence
    /// ([`Recorder::flush_series_held`]); the layout is sent once, each plot's value axis left to
    /// the viewer, which fits it to the data as they arrive (error plots held at symmetric ranges
    /// by two invisible points, `plots/extents.rs`).
    Viewer,
    /// The session so far for viewers that open it late (the class page's `/history.rrd`):
    /// full-size chunks, flushed when asked for, and what a viewer watching from the start has
    /// (the same layout and frame points).
    History,
    /// A saved file: full-size chunks like a run's, and at the end the layout again, every plot
    /// framed on its data.
    File,
}

impl LiveOutput {
    /// Whether viewers see it as it comes (the layout sent once, plots fitted by the viewer).
    pub(super) fn watched(self) -> bool {
        matches!(self, Self::Viewer | Self::History)
    }
}

impl Recorder {
    /// A recorder for live mode feeding `output`: everything that a reload can change is logged
    /// on the timeline.
    pub fn new_live(stream: Stream, params: &Params, output: LiveOutput) -> RecordingStreamResult<Self> {
        Self::build(stream, params, Some(output), None, None)
    }

    /// True for a live session's recorder.
    #[must_use]
    pub fn is_live(&self) -> bool {
        self.live.is_some()
    }

    /// Live mode: new parameters apply from simulated time `t_s` on (buffered rows go out first,
    /// but to a viewer's stream with the first new ones).
    pub fn reconfigure(&mut self, t_s: f64, params: &Params) -> RecordingStreamResult<()> {
        // A viewer's stream sends its buffered rows with the first rows of the new parameters (the
        // reload's flush, `app::live::RELOAD_FLUSH` later): a chunk per entity, not two — the
        // buffered rows are values already, and a viewer ingests a few dozen chunks a second.
        if self.live != Some(LiveOutput::Viewer) {
            self.flush_now()?;
        }
        // The 3D view's title names each class's drawing factor: the layout follows a change of it.
        let refactored =
            self.table.as_mut().is_some_and(|t| t.set_truth(&params.table.truth, params.recording.exaggeration));
        let old = self.live_params.replace(Box::new(params.clone()));
        let new_factor = old.as_ref().is_some_and(|p| p.recording.exaggeration != params.recording.exaggeration);
        let retitle = refactored || new_factor;
        // The table's drawn errors depend on its truth and the drawing factor alone: a reload that
        // changes neither (a cone, a speed, an algorithm shown) leaves them be — a viewer's stream
        // carries a chunk per entity sent, and a reload's burst is what a slow viewer waits through.
        let redraw_table = new_factor || old.as_ref().is_none_or(|p| p.table.truth != params.table.truth);
        // Pure coning: the drawn cone and its label follow a new cone.
        let alpha = |p: &Params| p.table.vehicle.pure_coning().map_or(0.0, |c| c.half_angle_rad);
        if let Some(gizmo) = self.cone.as_mut()
            && old.as_ref().is_none_or(|p| alpha(p) != alpha(params))
        {
            gizmo.reshape(self.stream.rec(), alpha(params), t_s)?;
        }
        self.plots.reconfigure(&self.stream, t_s, params)?;
        if let (Some(scene), Some(series)) = (self.ins.as_mut(), self.plots.ins.as_ref()) {
            scene.set_hidden(&series.hidden);
        }
        if retitle {
            self.send_blueprint(params, self.custom.clone())?;
        }
        // Where the parameters changed, on every error plot (at 0: the plots' range is not known).
        let unit = self.error_unit();
        for axis in ERROR_AXES {
            self.stream.mark_events(&error_path(unit, axis), "reloads", "config reloaded", &[t_s], 0.0)?;
            if self.ins_errors() {
                self.stream.mark_events(
                    &format!("ins/attitude_error_arcsec/{axis}"),
                    "reloads",
                    "config reloaded",
                    &[t_s],
                    0.0,
                )?;
            }
        }
        self.log_errors(params, self.geometry_at(t_s), redraw_table)
    }

    /// Sends the buffered time-series rows to viewers watching live: a series whose rows all
    /// repeat the last row it sent (a table error that is zero, a vehicle at rest) sends nothing
    /// for up to `hold`, then its newest row only — the same line, drawn flat to the same end, with
    /// a chunk every `hold` instead of every flush (a web viewer ingests a few dozen chunks a
    /// second). Every row is sent when the stream also exports its tables. The plots' open
    /// buckets go out too (a live session's rows are about a bucket each: waiting for the next
    /// would delay every row by one).
    pub fn flush_series_held(&mut self, hold: std::time::Duration) -> RecordingStreamResult<()> {
        self.plots.close_buckets();
        self.flush_series_with(Some(hold))
    }

    /// Sends the buffered scene frames to viewers watching live: the INS trace's computed axes
    /// only where they moved by more than the eye sees (their exact newest pose goes out with the
    /// next full flush, [`Recorder::flush_now`]).
    pub fn flush_scene_held(&mut self) -> RecordingStreamResult<()> {
        self.flush_scene_with(false)
    }

    /// The chunks of scene frames and plot rows this recorder has sent so far (the live viewers'
    /// cadence keeps their rate; a plot's occasional frame points are not counted).
    #[must_use]
    pub fn chunks_sent(&self) -> u64 {
        self.chunks_sent
    }
}
