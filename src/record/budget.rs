//! The recording of `rinscope budget`: per channel, the largest sources' parts with the rest summed,
//! the full run and the baseline plus every part; the headline's parts stacked (each band one
//! part's size, the largest at the bottom); one tab per group (position, velocity, INS attitude,
//! table). `--export` gets every source's part, not only the plotted ones.

use rerun::RecordingStreamResult;
use rerun::blueprint::components::ContainerKind;

use super::blueprint::{self, LegendCorner, Node};
use super::palette::{colors, rgb};
use super::{APPLICATION_ID, Stream, TIMELINE};
use crate::ins::budget::{Budget, CHANNELS, POSITION};

/// Parts drawn per plot; the others are summed into one line.
const SHOWN: usize = 6;

/// The colour of the source ranked `k` (the same in every plot).
fn part_color(k: usize) -> [u8; 3] {
    let n = colors::DISTINCT.len() - 1;
    let (_, c) = colors::DISTINCT[k % n];
    let dim = if (k / n) % 2 == 1 { 0.6 } else { 1.0 };
    c.map(|x| (f64::from(x) * dim) as u8)
}

const FULL: [u8; 3] = [250, 250, 250];
const SUM: [u8; 3] = [120, 120, 120];
const OTHERS: [u8; 3] = [170, 130, 90];

/// Logs budget `b` (`names`: its parts' sources' names; `rank`: the parts' order, largest first;
/// `channels`: those to draw) with `table` (the report's short table) as its document.
pub fn log(
    stream: &Stream,
    b: &Budget,
    names: &[String],
    rank: &[usize],
    channels: &[usize],
    table: &str,
) -> RecordingStreamResult<()> {
    let rec = stream.rec();
    rec.send_recording_name("rinscope: error budget")?;
    let doc = format!(
        "# Error budget\n\nEach source's part is the run with that source alone (the same random draws as the full run) \
         less the run without any source (the *baseline*: the algorithm's own error). The baseline plus every part, \
         against the full run, leaves the non-linear remainder (a bias turned by a swinging shaft, a quantizer \
         acting on the sum): it is second order, a quarter when every source is halved. Each plot draws the \
         {SHOWN} largest parts of its quantity, the others summed; `--export` has every part. docs/budget.md \
         explains.\n\n```\n{table}```\n"
    );
    rec.log_static("docs/budget", &rerun::TextDocument::from_markdown(doc))?;
    let n = b.t_s.len();
    let color_of = |k: usize| rank.iter().position(|&r| r == k).map_or(OTHERS, part_color);
    let mut tabs: Vec<(String, Vec<Node>)> = Vec::new();
    for &c in channels {
        let path = format!("budget/{}", CHANNELS[c].key());
        // Every part to the export; the plot takes the largest of this quantity.
        let mut all: Vec<String> = names.to_vec();
        all.extend(["full run".to_owned(), "baseline + Σ parts".to_owned(), "baseline".to_owned()]);
        let mut values = Vec::with_capacity(n * all.len());
        for i in 0..n {
            values.extend(b.parts.iter().map(|(_, p)| p.values[i][c]));
            values.extend([b.full.values[i][c], b.sum.values[i][c], b.baseline.values[i][c]]);
        }
        stream.export_series(&path, &all, &b.t_s, &values);
        let mut order: Vec<usize> = (0..b.parts.len()).collect();
        order.sort_by(|x, y| b.parts[*y].1.metrics(c).peak.total_cmp(&b.parts[*x].1.metrics(c).peak));
        let (shown, rest) = order.split_at(order.len().min(SHOWN));
        let mut lines: Vec<String> = shown.iter().map(|&k| names[k].clone()).collect();
        let mut line_colors: Vec<rerun::Color> = shown.iter().map(|&k| rgb(color_of(k))).collect();
        if !rest.is_empty() {
            lines.push(format!("the other {} sources", rest.len()));
            line_colors.push(rgb(OTHERS));
        }
        lines.extend(["full run".to_owned(), "baseline + Σ parts".to_owned()]);
        line_colors.extend([rgb(FULL), rgb(SUM)]);
        rec.log_static(path.as_str(), &rerun::SeriesLines::new().with_colors(line_colors).with_names(lines.clone()))?;
        let mut values = Vec::with_capacity(n * lines.len());
        for i in 0..n {
            values.extend(shown.iter().map(|&k| b.parts[k].1.values[i][c]));
            if !rest.is_empty() {
                values.push(rest.iter().map(|&k| b.parts[k].1.values[i][c]).sum());
            }
            values.extend([b.full.values[i][c], b.sum.values[i][c]]);
        }
        stream.plot_series(&path, &b.t_s, values, lines.len())?;
        let ch = &CHANNELS[c];
        let view = plot(&format!("{} {} ({}): the largest parts", ch.group, ch.component, ch.unit), &path);
        let tab = match ch.group {
            "table, uncompensated" | "table, compensated" => "table".to_owned(),
            g => g.to_owned(),
        };
        match tabs.iter_mut().find(|(t, _)| *t == tab) {
            Some((_, v)) => v.push(view),
            None => tabs.push((tab, vec![view])),
        }
    }
    // The headline stacked: the parts' sizes added up, the largest at the bottom.
    let navigating = channels.contains(&POSITION[0]);
    if let Some(h) = Budget::headline(channels) {
        let size = |k: usize, i: usize| {
            let v = &b.parts[k].1.values[i];
            if navigating { v[POSITION[0]].hypot(v[POSITION[1]]) } else { v[h].abs() }
        };
        let (shown, rest) = rank.split_at(rank.len().min(SHOWN));
        let path = if navigating {
            "budget/stacked/radial_position_m".to_owned()
        } else {
            format!("budget/stacked/{}", CHANNELS[h].key())
        };
        let mut lines: Vec<String> = shown.iter().map(|&k| names[k].clone()).collect();
        let mut line_colors: Vec<rerun::Color> = shown.iter().map(|&k| rgb(color_of(k))).collect();
        if !rest.is_empty() {
            lines.push(format!("+ the other {} sources", rest.len()));
            line_colors.push(rgb(OTHERS));
        }
        rec.log_static(path.as_str(), &rerun::SeriesLines::new().with_colors(line_colors).with_names(lines.clone()))?;
        let mut values = Vec::with_capacity(n * lines.len());
        for i in 0..n {
            let mut acc = 0.0;
            for &k in shown {
                acc += size(k, i);
                values.push(acc);
            }
            if !rest.is_empty() {
                values.push(acc + rest.iter().map(|&k| size(k, i)).sum::<f64>());
            }
        }
        stream.plot_series(&path, &b.t_s, values, lines.len())?;
        let label = if navigating {
            "horizontal position error: each band one part's size, the largest at the bottom (m)".to_owned()
        } else {
            let ch = &CHANNELS[h];
            format!("{} {}: each band one part's size, the largest at the bottom ({})", ch.group, ch.component, ch.unit)
        };
        let tab = if navigating { "position" } else { CHANNELS[h].group };
        let tab = if tab.starts_with("table") { "table" } else { tab };
        if let Some((_, v)) = tabs.iter_mut().find(|(t, _)| t == tab) {
            v.insert(0, plot(&label, &path));
        }
    }
    let tabs: Vec<Node> = tabs
        .into_iter()
        .map(|(name, views)| Node::named_container(ContainerKind::Vertical, &name, views, &[]))
        .collect();
    let root = Node::container(
        ContainerKind::Horizontal,
        vec![Node::container(ContainerKind::Tabs, tabs, &[]), Node::view("TextDocument", "the budget", "docs/budget")],
        &[2.0, 1.0],
    );
    let span = b.t_s.last().copied().unwrap_or(1.0).max(1.0);
    blueprint::send(
        rec,
        APPLICATION_ID,
        &root,
        &blueprint::Playback { timeline: TIMELINE, speed: span / 60.0, follow: true },
    )
}

fn plot(name: &str, origin: &str) -> Node {
    blueprint::whole_run_plot(name, origin, Some(LegendCorner::LeftTop))
}
