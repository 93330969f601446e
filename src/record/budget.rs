//! The recording of `rinscope budget`: per channel, the largest sources' parts with the rest summed,
//! the full run and the baseline plus every part; the headline's parts stacked (each band one
//! part's size, the largest at the bottom); one tab per group (position, velocity, INS attitude,
//! table). `--export` gets every source's part, not only the plotted ones. Beside them the table in
//! 3D, the element whose part is largest at the time cursor drawn thick in that part's colour.

use rerun::RecordingStreamResult;
use rerun::blueprint::components::ContainerKind;

use nalgebra::Vector3;

use super::blueprint::{self, LegendCorner, Node};
use super::palette::{colors, p3, rgb};
use super::scene::{ChainPaths, TableScene, ring, ring_radius};
use super::{APPLICATION_ID, Stream, TIMELINE};
use crate::ins::budget::{Budget, CHANNELS, ImuTerm, POSITION, Source, TableTerm};
use crate::scenario::Params;

/// Where the stacked headline goes (`--figures` fills its bands).
pub(crate) const STACKED: &str = "budget/stacked";

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
    params: &Params,
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
        let size = |k: usize, i: usize| b.size(k, h, i);
        let (shown, rest) = rank.split_at(rank.len().min(SHOWN));
        let path = if navigating {
            format!("{STACKED}/radial_position_m")
        } else {
            format!("{STACKED}/{}", CHANNELS[h].key())
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
        // The headline's tab first, the stacked plot on top: what the recording opens on.
        if let Some(i) = tabs.iter().position(|(t, _)| t == tab) {
            let mut headline = tabs.remove(i);
            headline.1.insert(0, plot(&label, &path));
            tabs.insert(0, headline);
        }
    }
    let tabs: Vec<Node> = tabs
        .into_iter()
        .map(|(name, views)| Node::named_container(ContainerKind::Vertical, &name, views, &[]))
        .collect();
    let doc = Node::view("TextDocument", "the budget", "docs/budget");
    let side = match Budget::headline(channels) {
        Some(h) => {
            let scene = log_scene(stream, params, b, names, h, &color_of)?;
            Node::container(ContainerKind::Vertical, vec![scene, doc], &[3.0, 2.0])
        }
        None => doc,
    };
    let root = Node::container(
        ContainerKind::Horizontal,
        vec![Node::container(ContainerKind::Tabs, tabs, &[]), side],
        &[3.0, 2.0],
    );
    let span = b.t_s.last().copied().unwrap_or(1.0).max(1.0);
    blueprint::send(
        rec,
        APPLICATION_ID,
        &root,
        &blueprint::Playback { timeline: TIMELINE, speed: span / 60.0, follow: true },
    )
}

/// What the 3D scene highlights for a source: the element it belongs to.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Element {
    /// One sensor axis of the IMU (a bias or scale factor of that axis).
    SensorAxis(usize),
    /// The IMU as a whole (its misalignment, noise, mounting).
    Imu,
    /// A gimbal: its ring and axis (the axis's swing, non-orthogonality, encoder).
    Gimbal(usize),
    /// The table's base (its installation).
    Base,
    /// The vehicle (the INS's initial alignment).
    Vehicle,
}

impl Element {
    fn of(s: &Source) -> Self {
        match *s {
            Source::Imu(ImuTerm::Bias(_, k) | ImuTerm::Scale(_, k)) => Self::SensorAxis(k),
            Source::Imu(_) | Source::Table(TableTerm::ImuMount) => Self::Imu,
            Source::Table(TableTerm::Installation) => Self::Base,
            Source::Table(_) => s.table_axis().map_or(Self::Base, Self::Gimbal),
            Source::Alignment => Self::Vehicle,
        }
    }

    /// Its highlight's entity: under the element's own frame, so that it turns with it.
    fn path(self, paths: &ChainPaths) -> String {
        let parent = match self {
            Self::SensorAxis(_) | Self::Imu => &paths.imu,
            Self::Gimbal(k) => &paths.gimbals[k],
            Self::Base => &paths.base,
            Self::Vehicle => &paths.vehicle,
        };
        format!("{parent}/dominant")
    }
}

/// Thicker than anything else in the scene (rings 0.02, sensor axes 0.015).
const HIGHLIGHT_RADIUS: f32 = 0.04;

/// The table at the budget's instants, and the element whose part of headline `h` is largest at
/// each instant drawn over it in that part's colour (the stacked plot's), named: the viewer shows
/// the one that dominates at the time cursor. Returns the 3D view.
fn log_scene(
    stream: &Stream,
    params: &Params,
    b: &Budget,
    names: &[String],
    h: usize,
    color_of: &dyn Fn(usize) -> [u8; 3],
) -> RecordingStreamResult<Node> {
    let rec = stream.rec();
    rec.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
    let mut scene = TableScene::new(params);
    scene.log_static(stream)?;
    scene.log_errors(stream, params, None)?;
    let model = params.table_model();
    let mut state = crate::sim::DemodState::default();
    for &t in &b.t_s {
        scene.push(&crate::sim::step(&model, &mut state, t));
    }
    scene.flush(stream, &b.t_s)?;
    let axes = params.table.chain.axes();
    let mut shown: Option<(usize, String)> = None;
    for (i, &t) in b.t_s.iter().enumerate() {
        let Some(k) = b.dominant(h, i) else { continue };
        if shown.as_ref().is_some_and(|(was, _)| *was == k) {
            continue;
        }
        let element = Element::of(&b.parts[k].0);
        let path = element.path(&scene.paths);
        if let Some((_, was)) = &shown
            && *was != path
        {
            stream.clear(Some(t), was.as_str())?;
        }
        let color = rgb(color_of(k));
        let label = format!("largest now: {}", names[k]);
        let (strips, at): (Vec<Vec<[f32; 3]>>, Vector3<f64>) = match element {
            Element::SensorAxis(a) => {
                let tip = Vector3::ith(a, 0.62);
                (vec![vec![[0.0; 3], p3(tip)]], tip * 1.15)
            }
            Element::Imu => (box_edges([0.27, 0.27, 0.21]), Vector3::new(0.3, -0.3, 0.3)),
            Element::Gimbal(a) => {
                let (radius, g) = (ring_radius(a, axes.len()), &axes[a]);
                let mut strips = ring(axes, a, radius);
                strips.push(vec![p3(-g.axis * radius * 1.3), p3(g.axis * radius * 1.3)]);
                (strips, g.axis * radius * 1.35)
            }
            Element::Base => {
                let g = axes[0].axis;
                (vec![vec![p3(-g * 1.3), p3(g * 1.3)]], g * 1.35)
            }
            Element::Vehicle => {
                let o = Vector3::new(0.0, 0.0, -1.3);
                let ends = [Vector3::new(0.5, 0.0, 0.0), Vector3::new(0.0, 0.9, 0.0), Vector3::new(0.0, 0.0, 0.4)];
                (ends.iter().map(|e| vec![p3(o), p3(o + e)]).collect(), o + Vector3::new(0.55, 0.0, 0.1))
            }
        };
        stream.put(
            Some(t),
            path.as_str(),
            &rerun::LineStrips3D::new(strips).with_colors([color]).with_radii([HIGHLIGHT_RADIUS]),
        )?;
        stream.put(
            Some(t),
            format!("{path}/label"),
            &rerun::Points3D::new([p3(at)])
                .with_labels([label])
                .with_colors([super::palette::label(color_of(k))])
                .with_radii([0.002]),
        )?;
        shown = Some((k, path));
    }
    let what = if h == POSITION[0] { "horizontal position error".to_owned() } else { CHANNELS[h].component.to_owned() };
    Ok(Node::view("3D", format!("3D: thick, in its colour — the largest part of the {what} now"), "world")
        .with_property("EyeControls3D", &blueprint::eye([2.6, -1.1, 0.95], [0.0, 0.1, -0.2])))
}

/// The twelve edges of a box of half sizes `h` about the origin.
fn box_edges(h: [f32; 3]) -> Vec<Vec<[f32; 3]>> {
    let corner = |i: usize| std::array::from_fn(|a| if i >> a & 1 == 1 { h[a] } else { -h[a] });
    let mut edges = Vec::new();
    for i in 0..8 {
        for a in 0..3 {
            if i >> a & 1 == 0 {
                edges.push(vec![corner(i), corner(i | 1 << a)]);
            }
        }
    }
    edges
}

fn plot(name: &str, origin: &str) -> Node {
    blueprint::whole_run_plot(name, origin, Some(LegendCorner::LeftTop))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ins::budget::Triad;

    #[test]
    fn each_source_lights_the_element_it_belongs_to() {
        let paths = ChainPaths::new(&["outer".to_owned(), "inner".to_owned()]);
        let at = |s: Source| Element::of(&s).path(&paths);
        assert_eq!(at(Source::Imu(ImuTerm::Bias(Triad::Gyro, 2))), format!("{}/dominant", paths.imu));
        assert_eq!(Element::of(&Source::Imu(ImuTerm::Scale(Triad::Accel, 1))), Element::SensorAxis(1));
        assert_eq!(Element::of(&Source::Imu(ImuTerm::Misalignment(Triad::Gyro))), Element::Imu);
        assert_eq!(at(Source::Table(TableTerm::Swing(1))), format!("{}/dominant", paths.gimbals[1]));
        assert_eq!(Element::of(&Source::Table(TableTerm::EncoderNoise(0))), Element::Gimbal(0));
        assert_eq!(at(Source::Table(TableTerm::Installation)), format!("{}/dominant", paths.base));
        assert_eq!(at(Source::Alignment), format!("{}/dominant", paths.vehicle));
    }

    #[test]
    fn a_box_has_twelve_edges_each_along_one_axis() {
        let edges = box_edges([1.0, 2.0, 3.0]);
        assert_eq!(edges.len(), 12);
        for e in &edges {
            let changed = (0..3).filter(|&a| e[0][a] != e[1][a]).count();
            assert_eq!(changed, 1, "{e:?}");
        }
    }
}
