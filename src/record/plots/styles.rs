//! The plots' styles: each series' colours, widths and legend names, logged once; which
//! algorithms' lines are shown.

use rerun::RecordingStreamResult;

use super::Plots;
use super::coning::{CONING_LOG_PATH, coning_rates};
use super::series::Quantity;
use crate::record::Stream;
use crate::record::palette::{colors, rgb, rgba};
use crate::scenario::Params;
use crate::sim::ERROR_AXES;

impl Plots {
    /// Logs every series' style (static).
    pub(crate) fn log_styles(&self, stream: &Stream) -> RecordingStreamResult<()> {
        let rec = stream.rec();
        for series in &self.series {
            let names = series.names.clone();
            let path = series.path.as_str();
            match series.what {
                Quantity::TableError(_) => {
                    // Uncompensated wide and translucent under the closed form's thin bright line, so
                    // both read where they coincide; their difference has its own plot.
                    let [u, c, f] = colors::VARIANT;
                    let n = names.len();
                    rec.log_static(
                        path,
                        &rerun::SeriesLines::new()
                            .with_colors([rgba(u, 140), rgb(c), rgb(f)].into_iter().take(n))
                            .with_names(names)
                            .with_widths([5.0, 2.0, 1.5].into_iter().take(n)),
                    )?;
                }
                // Pitch/roll/heading and east/north/up: red, green, blue.
                Quantity::ClosedForm
                | Quantity::VehicleAttitude
                | Quantity::PositionError
                | Quantity::VelocityError
                | Quantity::BodyAttitude
                | Quantity::Velocity
                | Quantity::PositionFromStart
                | Quantity::LatitudeLongitude
                | Quantity::Height => rec.log_static(
                    path,
                    &rerun::SeriesLines::new()
                        .with_colors(colors::EULER[..names.len()].iter().map(|c| rgb(*c)))
                        .with_names(names),
                )?,
                Quantity::GimbalAngles => rec.log_static(
                    path,
                    &rerun::SeriesLines::new()
                        .with_colors(colors::AXES[..names.len()].iter().map(|c| rgb(*c)))
                        .with_names(names),
                )?,
                Quantity::Swing(k) => {
                    let light = colors::AXES[k].map(|c| c / 2 + 60);
                    rec.log_static(
                        path,
                        &rerun::SeriesLines::new().with_colors([rgb(colors::AXES[k]), rgb(light)]).with_names(names),
                    )?;
                }
                // Each algorithm keeps its colour in every recording (by identity, not by position).
                Quantity::InsError(_) => {
                    let algorithms = self.ins.as_ref().map(|l| l.algorithms.as_slice()).unwrap_or_default();
                    rec.log_static(
                        path,
                        &rerun::SeriesLines::new()
                            .with_colors(algorithms.iter().map(|name| rgb(colors::algorithm(name))))
                            .with_names(names),
                    )?;
                }
                // Measured: the algorithm's colour, wide; analytic: the same colour, thin.
                Quantity::ConingLog => {
                    let algorithms = self.ins.as_ref().map(|l| l.algorithms.as_slice()).unwrap_or_default();
                    rec.log_static(
                        path,
                        &rerun::SeriesLines::new()
                            .with_colors(algorithms.iter().flat_map(|name| [rgb(colors::algorithm(name)); 2]))
                            .with_widths(algorithms.iter().flat_map(|_| [2.5, 1.0]))
                            .with_names(names),
                    )?;
                }
            }
        }
        self.log_shown_algorithms(stream)
    }

    /// Which algorithms' lines are shown (`[recording.show]`): the whole line of a hidden one, on
    /// every INS error plot and the coning plot.
    fn log_shown_algorithms(&self, stream: &Stream) -> RecordingStreamResult<()> {
        let Some(layout) = &self.ins else { return Ok(()) };
        let shown: Vec<bool> = layout.algorithms.iter().map(|a| !layout.hidden.contains(a)).collect();
        for axis in ERROR_AXES.iter().filter(|_| layout.errors && layout.algorithms.len() > 1) {
            stream.rec().log_static(
                format!("ins/attitude_error_arcsec/{axis}"),
                &rerun::SeriesLines::update_fields().with_visible_series(shown.iter().copied()),
            )?;
        }
        if layout.coning.is_some() {
            stream.rec().log_static(
                CONING_LOG_PATH,
                &rerun::SeriesLines::update_fields().with_visible_series(shown.iter().flat_map(|v| [*v; 2])),
            )?;
        }
        Ok(())
    }

    /// Live mode: new parameters from simulated time `t_s` on — the swing plots follow the true
    /// errors; pure coning's analytic lines a new cone or sample rate (from where they stand: the
    /// drift goes on at the new rate); the algorithms shown `[recording.show]`.
    pub(crate) fn reconfigure(&mut self, stream: &Stream, t_s: f64, params: &Params) -> RecordingStreamResult<()> {
        self.set_truth(params.table.truth.clone());
        let Some(layout) = self.ins.as_mut() else { return Ok(()) };
        let algorithms = params.ins.as_ref().map(crate::ins::InsParams::algorithms).unwrap_or_default();
        if let (Some(lines), Some(rates)) = (layout.coning.as_mut(), coning_rates(params, &algorithms))
            && rates != lines.rates
        {
            lines.change(t_s, rates);
        }
        let hidden: Vec<String> = layout.algorithms.iter().filter(|a| !params.recording.shows(a)).cloned().collect();
        if hidden != layout.hidden {
            layout.hidden = hidden;
            self.log_shown_algorithms(stream)?;
        }
        Ok(())
    }
}
