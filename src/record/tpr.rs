//! The recording of `rinscope tpr`: azimuth and radial position errors of the conventional reset and
//! of TPR overlaid, the fixes marked, the comparison with Zheng et al. 2016 as a document.

use rerun::RecordingStreamResult;
use rerun::blueprint::components::ContainerKind;

use super::blueprint::{self, Node};
use super::palette::rgb;
use super::{APPLICATION_ID, Stream, TIMELINE};
use crate::ins::reset::{BRANCH_NAMES, BRANCHES, PAPER_RADIAL_M, TprResult};
use crate::scenario::Params;

const COLORS: [[u8; 3]; BRANCHES] = [[230, 76, 60], [46, 170, 90], [70, 130, 230]];

/// Logs the comparison.
pub fn log(stream: &Stream, params: &Params, r: &TprResult, table: &str) -> RecordingStreamResult<()> {
    let rec = stream.rec();
    rec.send_recording_name(format!("rinscope: {}", params.meta.name))?;
    rec.send_property(
        "rinscope",
        &rerun::AnyValues::default()
            .with_component::<rerun::components::Text>("scenario", [params.meta.name.clone()])
            .with_component::<rerun::components::Text>("seed", [params.meta.seed.to_string()]),
    )?;
    let doc = format!(
        "# {}\n\n*{}*\n\n{}\n\n```\n{}```\n\nZheng et al. 2016 (Fig. 9): radial error after the resets below {} m with TPR, above {} m \
         conventionally. docs/tpr.md derives the estimator in rinscope's signs.\n",
        params.meta.name,
        params.meta.title,
        params.meta.description.trim(),
        table,
        PAPER_RADIAL_M.0,
        PAPER_RADIAL_M.1
    );
    rec.log_static("docs/tpr", &rerun::TextDocument::from_markdown(doc))?;
    rec.log_static(
        "docs/config",
        &rerun::TextDocument::from_markdown(format!("```toml\n{}\n```\n", params.resolved_toml)),
    )?;
    let colors: Vec<rerun::Color> = COLORS.iter().map(|c| rgb(*c)).collect();
    let paths = ["tpr/heading_error_arcsec", "tpr/radial_position_error_m", "tpr/east_error_m", "tpr/north_error_m"];
    for path in paths {
        rec.log_static(path, &rerun::SeriesLines::new().with_colors(colors.clone()).with_names(BRANCH_NAMES))?;
    }
    let times: Vec<f64> = r.samples.iter().map(|s| s.t_s).collect();
    let columns: [Vec<f64>; 4] = [
        r.samples.iter().flat_map(|s| s.heading_arcsec).collect(),
        r.samples.iter().flat_map(|s| s.radial_m).collect(),
        r.samples.iter().flat_map(|s| s.east_north_m[0]).collect(),
        r.samples.iter().flat_map(|s| s.east_north_m[1]).collect(),
    ];
    let names = BRANCH_NAMES.map(String::from);
    let fix_label = format!(
        "position fixes ({})",
        r.fixes_s.iter().map(|t| format!("{:.0} h", t / 3600.0)).collect::<Vec<_>>().join(", ")
    );
    for (path, values) in paths.iter().zip(columns) {
        let top = values.iter().copied().filter(|v| v.is_finite()).fold(0.0_f64, f64::max);
        stream.send_series(path, &names, &times, values, BRANCHES)?;
        stream.mark_events(path, "fixes", &fix_label, &r.fixes_s, top)?;
    }
    for (k, t) in r.fixes_s.iter().enumerate() {
        rec.set_duration_secs(TIMELINE, *t);
        let what = if k == 0 {
            "first position fix: the position is reset".to_owned()
        } else {
            format!(
                "second fix: every branch resets the position; TPR corrects the heading by {:+.2}″, TPR + level by {:+.2}″ (the heading error was {:+.2}″)",
                -r.tpr_heading_estimate_arcsec, -r.level_heading_estimate_arcsec, r.heading_at_second_fix_arcsec
            )
        };
        rec.log("events", &rerun::TextLog::new(what).with_level("INFO"))?;
    }
    // Legends would sit over the data: the first title gives the colours.
    let plot = |name: &str, origin: &str| blueprint::whole_run_plot(name, origin, None);
    let key = format!("red {} · green {} · blue {} · ▼ fixes", BRANCH_NAMES[0], BRANCH_NAMES[1], BRANCH_NAMES[2]);
    let root = Node::container(
        ContainerKind::Horizontal,
        vec![
            Node::container(
                ContainerKind::Vertical,
                vec![
                    plot(&format!("azimuth (heading) error (″) — {key}"), "tpr/heading_error_arcsec"),
                    plot("radial position error (m)", "tpr/radial_position_error_m"),
                ],
                &[],
            ),
            Node::container(
                ContainerKind::Vertical,
                vec![
                    Node::container(
                        ContainerKind::Tabs,
                        vec![
                            Node::view("TextDocument", "about", "docs/tpr"),
                            Node::view("TextDocument", "config", "docs/config"),
                            Node::view("TextLog", "events", "events"),
                        ],
                        &[],
                    ),
                    plot("east error (m)", "tpr/east_error_m"),
                    plot("north error (m)", "tpr/north_error_m"),
                ],
                // The about tab holds the verdict table: give it the room to show it.
                &[2.2, 1.0, 1.0],
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
