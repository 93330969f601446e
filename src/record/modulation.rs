//! The recording of `rinscope modulation`: the three variants' position and heading errors overlaid.

use rerun::RecordingStreamResult;
use rerun::blueprint::components::ContainerKind;

use super::blueprint::{self, Node};
use super::palette::rgb;
use super::{APPLICATION_ID, Stream, TIMELINE};
use crate::ins::trace::{NavSample, NavTrace};

const COLORS: [[u8; 3]; 3] = [[230, 76, 60], [240, 180, 40], [46, 170, 90]];
/// The colours' names, for the plot titles that stand in for legends.
const COLOR_NAMES: [&str; 3] = ["red", "yellow", "green"];
/// The radial error as log10 of metres: 27 m beside 30 km, each readable.
const LOG_PATH: &str = "modulation/radial_position_error_log10_m";

/// Logs the traces (sampled at the same instants) with their explanation and a layout.
pub fn log(stream: &Stream, traces: &[NavTrace], table: &str) -> RecordingStreamResult<()> {
    let rec = stream.rec();
    rec.send_recording_name("rinscope: rotation modulation")?;
    let names: Vec<String> = traces.iter().map(|t| t.label.clone()).collect();
    let doc = format!(
        "# Rotation modulation\n\nOne IMU with constant biases (gyros 0.01°/h, accelerometers 50 µg on every axis) on a static \
         vehicle at 40° N navigates with the table at rest, turning continuously about the azimuth axis at 10°/s, and \
         running the 16-position sequence (docs/schemes.md). The presets are `rotation-modulation-none`, `-continuous` \
         and `-16-position`.\n\n- Without rotation the biases integrate: Schuler (84 min) and Earth-rate (24 h) oscillations \
         on a growing position error.\n- Azimuth rotation averages the horizontal sensors' biases out, not the vertical \
         gyro's: the heading error remains and drives the position error.\n- The 16-position sequence turns every sensor \
         over: what is left is small.\n\n```\n{table}```\n"
    );
    rec.log_static("docs/modulation", &rerun::TextDocument::from_markdown(doc))?;
    let colors: Vec<rerun::Color> = COLORS.iter().map(|c| rgb(*c)).collect();
    for path in [
        "modulation/radial_position_error_m",
        LOG_PATH,
        "modulation/east_error_m",
        "modulation/north_error_m",
        "modulation/heading_error_arcsec",
    ] {
        rec.log_static(path, &rerun::SeriesLines::new().with_colors(colors.clone()).with_names(names.clone()))?;
    }
    let n = traces.iter().map(|t| t.samples.len()).min().unwrap_or(0);
    let times: Vec<f64> = traces.first().map(|t| t.samples[..n].iter().map(|s| s.t_s).collect()).unwrap_or_default();
    let column = |f: &dyn Fn(&NavSample) -> f64| -> Vec<f64> {
        let mut v = Vec::with_capacity(n * traces.len());
        for i in 0..n {
            for t in traces {
                v.push(f(&t.samples[i]));
            }
        }
        v
    };
    let width = traces.len();
    for (path, values) in [
        ("modulation/radial_position_error_m", column(&|s| s.position_m[2])),
        (LOG_PATH, column(&|s| if s.position_m[2] > 0.0 { s.position_m[2].log10() } else { f64::NAN })),
        ("modulation/east_error_m", column(&|s| s.position_m[0])),
        ("modulation/north_error_m", column(&|s| s.position_m[1])),
        ("modulation/heading_error_arcsec", column(&|s| s.heading_arcsec)),
    ] {
        stream.send_series(path, &names, &times, values, width)?;
    }
    // Legends would sit over the data: the first title gives the colours.
    let key = names.iter().zip(COLOR_NAMES).map(|(n, c)| format!("{c} {n}")).collect::<Vec<_>>().join(" · ");
    let plot = |name: &str, origin: &str| blueprint::whole_run_plot(name, origin, None);
    let root = Node::container(
        ContainerKind::Horizontal,
        vec![
            Node::container(
                ContainerKind::Vertical,
                vec![
                    plot(&format!("radial position error (m) — {key}"), "modulation/radial_position_error_m"),
                    plot("radial position error, log10 of metres (1 = 10 m, 4 = 10 km)", LOG_PATH),
                    plot("heading error (arcsec)", "modulation/heading_error_arcsec"),
                ],
                &[],
            ),
            Node::container(
                ContainerKind::Vertical,
                vec![
                    Node::view("TextDocument", "about", "docs/modulation"),
                    plot("east error (m)", "modulation/east_error_m"),
                    plot("north error (m)", "modulation/north_error_m"),
                ],
                &[1.2, 1.0, 1.0],
            ),
        ],
        &[1.4, 1.0],
    );
    blueprint::send(
        rec,
        APPLICATION_ID,
        &root,
        &blueprint::Playback { timeline: TIMELINE, speed: 3600.0, follow: true },
    )
}
