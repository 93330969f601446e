//! The recording of `rinscope schemes`: each scheme's horizontal position error (linear and log10)
//! and heading error over time, for the first seed, overlaid, with the comparison's table.

use rerun::RecordingStreamResult;
use rerun::blueprint::components::ContainerKind;

use super::blueprint::{self, LegendCorner, Node};
use super::palette::{colors, rgb};
use super::{APPLICATION_ID, Stream, TIMELINE};
use crate::ins::budget::{INS_HEADING, POSITION, Trace};

const RADIAL: &str = "schemes/radial_position_error_m";
const RADIAL_LOG: &str = "schemes/radial_position_error_log10_m";
const HEADING: &str = "schemes/heading_error_arcsec";

/// Logs the first `n` rows of each scheme's `traces` (sampled at the same instants) under `labels`,
/// with `table` (and `preface` before it) as the document.
pub fn log(
    stream: &Stream,
    labels: &[String],
    traces: &[&Trace],
    n: usize,
    table: &str,
    preface: Option<&str>,
) -> RecordingStreamResult<()> {
    let rec = stream.rec();
    rec.send_recording_name("rinscope: rotation schemes side by side")?;
    let doc = format!(
        "{}# Rotation schemes side by side\n\nThe same IMU and table with each scheme in turn (assets/schemes/, or a user's \
         `[scheme]`), every scheme on the same seeds: the table is over every seed, the plots are the first seed's. \
         docs/schemes.md explains the built-in sequences.\n\n```\n{table}```\n",
        preface.map_or_else(String::new, |p| format!("{p}\n\n"))
    );
    rec.log_static("docs/schemes", &rerun::TextDocument::from_markdown(doc))?;
    let line_colors: Vec<rerun::Color> =
        (0..labels.len()).map(|k| rgb(colors::DISTINCT[k % colors::DISTINCT.len()].1)).collect();
    let times: Vec<f64> = traces.first().map(|t| t.t_s[..n].to_vec()).unwrap_or_default();
    let column = |f: &dyn Fn(&Trace, usize) -> f64| -> Vec<f64> {
        let mut v = Vec::with_capacity(n * traces.len());
        for i in 0..n {
            v.extend(traces.iter().map(|t| f(t, i)));
        }
        v
    };
    let radial = |t: &Trace, i: usize| t.values[i][POSITION[0]].hypot(t.values[i][POSITION[1]]);
    for (path, values) in [
        (RADIAL, column(&radial)),
        (RADIAL_LOG, column(&|t, i| if radial(t, i) > 0.0 { radial(t, i).log10() } else { f64::NAN })),
        (HEADING, column(&|t, i| t.values[i][INS_HEADING])),
    ] {
        rec.log_static(path, &rerun::SeriesLines::new().with_colors(line_colors.clone()).with_names(labels.to_vec()))?;
        stream.send_series(path, labels, &times, values, labels.len())?;
    }
    let plot = |name: &str, origin: &str| blueprint::whole_run_plot(name, origin, Some(LegendCorner::LeftTop));
    let root = Node::container(
        ContainerKind::Horizontal,
        vec![
            Node::container(
                ContainerKind::Vertical,
                vec![
                    plot("horizontal position error, log10 of metres (1 = 10 m, 3 = 1 km)", RADIAL_LOG),
                    plot("horizontal position error (m)", RADIAL),
                    plot("heading error (arcsec)", HEADING),
                ],
                &[],
            ),
            Node::view("TextDocument", "the comparison", "docs/schemes"),
        ],
        &[1.6, 1.0],
    );
    let span = times.last().copied().unwrap_or(1.0).max(1.0);
    blueprint::send(
        rec,
        APPLICATION_ID,
        &root,
        &blueprint::Playback { timeline: TIMELINE, speed: span / 60.0, follow: true },
    )
}
