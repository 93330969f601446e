//! Reading a recording back: the text-log entries of `events`, so a user (and the tests) can list
//! what happened in a saved session — reloads, errors, the end — without opening the viewer; and
//! what it holds (its entities, the views of its layout), so a test can check that a recording has
//! what it should and that its layout shows nothing it lacks.

use std::collections::BTreeSet;
use std::io::BufReader;
use std::path::Path;

use rerun::external::re_log_encoding::DecoderApp;
use rerun::external::re_log_types::{LogMsg, StoreId, StoreKind};
use rerun::log::Chunk;

use super::TIMELINE;

/// One text-log entry: simulated time, s (None for static), level and text.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// Simulated time, s.
    pub t_s: Option<f64>,
    /// "INFO", "WARN", ...
    pub level: String,
    /// The message.
    pub text: String,
}

/// A data chunk with its store's id and its entity path (without the leading `/`).
type Tagged = (StoreId, String, Chunk);

/// The data chunks of the recording at `path` ([`opened`]).
fn chunks(path: &Path) -> anyhow::Result<impl Iterator<Item = anyhow::Result<Tagged>> + '_> {
    Ok(opened(path)?.2)
}

/// How the recording at `path` ends, and its data chunks, each with its store's kind and its entity
/// path (without the leading `/`); an unreadable file named in the error. A file whose footer is
/// damaged is refused before it is decoded (`sink::ending`), and one whose messages stop being
/// readable before its footer ends with an error that says where: Rerun's decoder stops there
/// without one. A file without a footer (cut short) gives what it holds. The flag: another process
/// holds the file's lock — a run writing it right now (its `PATH.partial`, `io::files`).
fn opened(
    path: &Path,
) -> anyhow::Result<(super::sink::Ending, bool, impl Iterator<Item = anyhow::Result<Tagged>> + '_)> {
    let damaged = |e: &dyn std::fmt::Display| anyhow::anyhow!("{}: not a readable .rrd: {e}", path.display());
    let mut file = crate::io::files::open_input(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let being_written = match file.try_lock_shared() {
        // Not held: let go at once (held while reading, it would stop a run from starting to write it).
        Ok(()) => {
            let _ = file.unlock();
            false
        }
        Err(std::fs::TryLockError::WouldBlock) => true,
        Err(std::fs::TryLockError::Error(_)) => false,
    };
    let bytes = file.metadata().map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?.len();
    let header = rerun::external::re_log_encoding::StreamHeader::ENCODED_SIZE_BYTES as u64;
    // A run writing it that has not put out its stream header yet (a live session's first
    // seconds): nothing so far, no decoder.
    let (ending, mut decoder) = if being_written && bytes < header {
        (super::sink::Ending::None { bytes }, None)
    } else {
        let ending = super::sink::ending(&mut file).map_err(|e| damaged(&e))?;
        std::io::Seek::rewind(&mut file).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        (ending, Some(DecoderApp::decode_eager(BufReader::new(file)).map_err(|e| damaged(&e))?))
    };
    let mut ended = false;
    let messages = std::iter::from_fn(move || {
        let decoder = decoder.as_mut().filter(|_| !ended)?;
        let next = decoder.next();
        if next.is_none() {
            ended = true;
            let read = decoder.num_bytes_processed();
            if let super::sink::Ending::Footer { payload_start } = ending
                && read < payload_start
            {
                return Some(Err(anyhow::anyhow!(
                    "{}: damaged: its messages stop being readable at byte {read}, before its footer at byte {payload_start}",
                    path.display()
                )));
            }
        }
        next.map(|m| m.map_err(|e| anyhow::anyhow!("{}: {e}", path.display())))
    });
    Ok((
        ending,
        being_written,
        messages.filter_map(|m| match m {
            Err(e) => Some(Err(e)),
            Ok(LogMsg::ArrowMsg(store_id, arrow_msg)) => {
                Some(Chunk::from_arrow_msg(&arrow_msg).map_err(anyhow::Error::from).map(|chunk| {
                    let entity = chunk.entity_path().to_string().trim_start_matches('/').to_owned();
                    (store_id, entity, chunk)
                }))
            }
            Ok(_) => None,
        }),
    ))
}

/// The `events` entries of the recording at `path`, in time order.
pub fn events(path: &Path) -> anyhow::Result<Vec<Event>> {
    Ok(event_log(path)?.0)
}

/// The `events` entries of the recording at `path`, in time order, and why the file is not a
/// finished recording if it is not: it ends without the footer a finished `.rrd` has (a writer
/// that stopped, a copy cut short, or a run still writing it: its lock is held), and the entries
/// are those its messages before that hold.
pub fn event_log(path: &Path) -> anyhow::Result<(Vec<Event>, Option<String>)> {
    let text_component = rerun::TextLog::descriptor_text().component;
    let level_component = rerun::TextLog::descriptor_level().component;
    let mut out = Vec::new();
    let (ending, being_written, items) = opened(path)?;
    for item in items {
        let (store_id, entity, chunk) = item?;
        if store_id.kind() != StoreKind::Recording || entity != "events" {
            continue;
        }
        let times: Vec<Option<f64>> = chunk
            .iter_component_indices(TIMELINE.into(), text_component)
            .map(|(t, _)| if t.is_static() { None } else { Some(t.as_i64() as f64 / 1e9) })
            .collect();
        let texts: Vec<String> = chunk
            .iter_component::<rerun::components::Text>(text_component)
            .map(|v| v.iter().map(|t| t.as_str().to_owned()).collect::<Vec<_>>().join("\n"))
            .collect();
        let levels: Vec<String> = chunk
            .iter_component::<rerun::components::TextLogLevel>(level_component)
            .map(|v| v.iter().map(|l| l.as_str().to_owned()).collect::<String>())
            .collect();
        for (i, text) in texts.into_iter().enumerate() {
            out.push(Event {
                t_s: times.get(i).copied().flatten(),
                level: levels.get(i).cloned().unwrap_or_default(),
                text,
            });
        }
    }
    out.sort_by(|a, b| a.t_s.unwrap_or(-1.0).total_cmp(&b.t_s.unwrap_or(-1.0)));
    let incomplete = match ending {
        super::sink::Ending::None { bytes } if being_written => Some(format!(
            "{} is still being written (another process holds its lock: a run saving it right now; {bytes} bytes so far): what follows is what it holds so far",
            path.display()
        )),
        super::sink::Ending::None { bytes } => Some(format!(
            "{} ends without the footer a finished recording has ({bytes} bytes): it was cut short, and what follows is what it holds",
            path.display()
        )),
        super::sink::Ending::Footer { .. } => None,
    };
    Ok((out, incomplete))
}

/// The labels of the 3D points at `entity` (without the leading `/`) in the recording at `path`,
/// each with its simulated time, s (None for static), in time order: what a label said when (a
/// live session relabels what a reload changed).
pub fn point_labels(path: &Path, entity: &str) -> anyhow::Result<Vec<(Option<f64>, String)>> {
    let labels = rerun::Points3D::descriptor_labels().component;
    let mut out = Vec::new();
    for item in chunks(path)? {
        let (store_id, e, chunk) = item?;
        if store_id.kind() != StoreKind::Recording || e != entity {
            continue;
        }
        let times: Vec<Option<f64>> = chunk
            .iter_component_indices(TIMELINE.into(), labels)
            .map(|(t, _)| if t.is_static() { None } else { Some(t.as_i64() as f64 / 1e9) })
            .collect();
        for (i, v) in chunk.iter_component::<rerun::components::Text>(labels).enumerate() {
            out.push((
                times.get(i).copied().flatten(),
                v.iter().map(|t| t.as_str().to_owned()).collect::<Vec<_>>().join("\n"),
            ));
        }
    }
    out.sort_by(|a, b| a.0.unwrap_or(-1.0).total_cmp(&b.0.unwrap_or(-1.0)));
    Ok(out)
}

/// The entities a recording holds and the space origins of its layout's views (paths without the
/// leading `/`).
#[derive(Debug, Clone, Default)]
pub struct Contents {
    /// Every entity with data in the recording store.
    pub entities: BTreeSet<String>,
    /// Every view's space origin in its blueprints.
    pub view_origins: BTreeSet<String>,
}

impl Contents {
    /// The view origins under which the recording has no entity (a layout pointing at nothing).
    #[must_use]
    pub fn empty_views(&self) -> Vec<String> {
        self.view_origins
            .iter()
            .filter(|o| !self.entities.iter().any(|e| e == *o || e.starts_with(&format!("{o}/"))))
            .cloned()
            .collect()
    }
}

/// What the recording at `path` holds (see [`Contents`]).
pub fn contents(path: &Path) -> anyhow::Result<Contents> {
    use rerun::external::re_sdk_types::blueprint::{archetypes::ViewBlueprint, components::ViewOrigin};
    let origin_component = ViewBlueprint::descriptor_space_origin().component;
    let mut out = Contents::default();
    for item in chunks(path)? {
        let (store_id, entity, chunk) = item?;
        match store_id.kind() {
            StoreKind::Recording => {
                out.entities.insert(entity);
            }
            StoreKind::Blueprint => {
                for origins in chunk.iter_component::<ViewOrigin>(origin_component) {
                    out.view_origins.extend(origins.iter().map(|o| o.0.0.as_str().trim_start_matches('/').to_owned()));
                }
            }
        }
    }
    Ok(out)
}

/// A time-series view of a recording's last layout and the data it shows.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotFrame {
    /// The view's title.
    pub title: String,
    /// Its space origin (without the leading `/`).
    pub origin: String,
    /// Its value range, if the layout sets one.
    pub range: Option<[f64; 2]>,
    /// Finite values at or under the origin (every time): count, smallest, largest.
    pub finite: usize,
    /// The smallest finite value.
    pub min: f64,
    /// The largest.
    pub max: f64,
    /// Values that are not finite (rows where a series has no value).
    pub non_finite: usize,
}

/// Every time-series view of the last layout the recording at `path` carries, with the range of
/// the data under it: a test checks that each plot's data lie inside its visible range.
pub fn plot_frames(path: &Path) -> anyhow::Result<Vec<PlotFrame>> {
    Ok(plots(path)?
        .into_iter()
        .map(|p| {
            let mut f = PlotFrame {
                title: p.title,
                origin: p.origin,
                range: p.range,
                finite: 0,
                min: f64::INFINITY,
                max: f64::NEG_INFINITY,
                non_finite: 0,
            };
            for v in p.series.iter().flat_map(|s| s.y.iter()) {
                if v.is_finite() {
                    (f.finite, f.min, f.max) = (f.finite + 1, f.min.min(*v), f.max.max(*v));
                } else {
                    f.non_finite += 1;
                }
            }
            f
        })
        .collect())
}

/// A time-series view of a recording's last layout with its data: what `--figures` draws.
#[derive(Debug, Clone, PartialEq)]
pub struct Plot {
    /// The view's title.
    pub title: String,
    /// Its space origin (without the leading `/`).
    pub origin: String,
    /// Its value range, if the layout sets one.
    pub range: Option<[f64; 2]>,
    /// Its time range (s on its timeline), if the layout sets one.
    pub time_range: Option<[f64; 2]>,
    /// Every series at or under the origin, in entity order.
    pub series: Vec<PlotSeries>,
}

/// One line (or set of markers) of a plot.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotSeries {
    /// The entity it comes from (without the leading `/`).
    pub entity: String,
    /// Its name (the legend's), empty if the recording gives none.
    pub name: String,
    /// Its colour, RGBA.
    pub color: [u8; 4],
    /// Its line width, points (UI points, as the viewer draws it).
    pub width: f32,
    /// Drawn as a line.
    pub line: bool,
    /// Drawn as markers; `Some("down")` for ▼ event markers.
    pub markers: Option<String>,
    /// The timeline its times are on.
    pub timeline: String,
    /// Times, s of the timeline.
    pub t: Vec<f64>,
    /// Values (NaN where a row has none).
    pub y: Vec<f64>,
}

/// How an entity's series are drawn (its static `SeriesLines` / `SeriesPoints`).
#[derive(Default, Clone)]
struct Style {
    names: Vec<String>,
    colors: Vec<[u8; 4]>,
    widths: Vec<f32>,
    line: bool,
    points: bool,
    marker: Option<String>,
}

/// Every time-series view of the last layout the recording at `path` carries, with its data.
pub fn plots(path: &Path) -> anyhow::Result<Vec<Plot>> {
    use rerun::external::re_sdk_types::blueprint::archetypes::{ScalarAxis, TimeAxis, ViewBlueprint};
    use rerun::external::re_sdk_types::blueprint::components::{ViewClass, ViewOrigin};
    use rerun::external::re_sdk_types::datatypes::TimeRangeBoundary;
    use std::collections::BTreeMap;
    let scalar = rerun::Scalars::descriptor_scalars().component;
    let (l_names, l_colors, l_widths) = (
        rerun::SeriesLines::descriptor_names().component,
        rerun::SeriesLines::descriptor_colors().component,
        rerun::SeriesLines::descriptor_widths().component,
    );
    let (p_names, p_colors, p_markers) = (
        rerun::SeriesPoints::descriptor_names().component,
        rerun::SeriesPoints::descriptor_colors().component,
        rerun::SeriesPoints::descriptor_markers().component,
    );
    let (origin_c, class_c, name_c) = (
        ViewBlueprint::descriptor_space_origin().component,
        ViewBlueprint::descriptor_class_identifier().component,
        ViewBlueprint::descriptor_display_name().component,
    );
    let (range_c, time_c) = (ScalarAxis::descriptor_range().component, TimeAxis::descriptor_view_range().component);
    // Per entity: its style, and its rows (timeline, t, values).
    let mut styles: BTreeMap<String, Style> = BTreeMap::new();
    let mut rows: BTreeMap<String, Vec<(String, f64, Vec<f64>)>> = BTreeMap::new();
    /// Per view entity: class, title, origin, value range, time range.
    #[derive(Default)]
    struct View {
        class: String,
        title: String,
        origin: String,
        range: Option<[f64; 2]>,
        time_range: Option<[f64; 2]>,
    }
    let mut layouts: Vec<(String, BTreeMap<String, View>)> = Vec::new();
    let secs = |t: i64| t as f64 / 1e9;
    for item in chunks(path)? {
        let (store_id, entity, chunk) = item?;
        match store_id.kind() {
            StoreKind::Recording => {
                let texts = |c| {
                    chunk
                        .iter_component::<rerun::components::Name>(c)
                        .flat_map(|v| v.iter().map(|n| n.as_str().to_owned()).collect::<Vec<_>>())
                        .collect::<Vec<_>>()
                };
                let colors = |c| {
                    chunk
                        .iter_component::<rerun::components::Color>(c)
                        .flat_map(|v| v.iter().map(|c| c.to_array()).collect::<Vec<_>>())
                        .collect::<Vec<_>>()
                };
                let (ln, lc, pn, pc) = (texts(l_names), colors(l_colors), texts(p_names), colors(p_colors));
                let widths: Vec<f32> = chunk
                    .iter_component::<rerun::components::StrokeWidth>(l_widths)
                    .flat_map(|v| v.iter().map(|w| w.0.0).collect::<Vec<_>>())
                    .collect();
                let markers: Vec<String> = chunk
                    .iter_component::<rerun::components::MarkerShape>(p_markers)
                    .flat_map(|v| v.iter().map(|m| format!("{m:?}").to_lowercase()).collect::<Vec<_>>())
                    .collect();
                let has_lines = !ln.is_empty() || !lc.is_empty() || !widths.is_empty();
                let has_points = !pn.is_empty() || !pc.is_empty() || !markers.is_empty();
                if has_lines || has_points {
                    let s = styles.entry(entity.clone()).or_default();
                    if has_lines {
                        s.line = true;
                        if !ln.is_empty() {
                            s.names = ln;
                        }
                        if !lc.is_empty() {
                            s.colors = lc;
                        }
                        s.widths = widths;
                    }
                    if has_points {
                        s.points = true;
                        if s.names.is_empty() {
                            s.names = pn;
                        }
                        if s.colors.is_empty() {
                            s.colors = pc;
                        }
                        s.marker = markers.into_iter().next().or(s.marker.take());
                    }
                }
                let Some(timeline) = [super::TIMELINE, super::allan::LOG10_TAU_TIMELINE]
                    .into_iter()
                    .find(|t| chunk.timelines().contains_key(&(*t).into()))
                else {
                    continue;
                };
                let times: Vec<f64> =
                    chunk.iter_component_indices(timeline.into(), scalar).map(|(t, _)| secs(t.as_i64())).collect();
                let e = rows.entry(entity).or_default();
                for (t, values) in times.into_iter().zip(chunk.iter_component::<rerun::components::Scalar>(scalar)) {
                    e.push((timeline.to_owned(), t, values.iter().map(|s| s.0.0).collect()));
                }
            }
            StoreKind::Blueprint => {
                let key = format!("{store_id:?}");
                if layouts.last().is_none_or(|(k, _)| *k != key) {
                    layouts.retain(|(k, _)| *k != key);
                    layouts.push((key, BTreeMap::new()));
                }
                let Some((_, views)) = layouts.last_mut() else { continue };
                let (view, property) = match entity.rsplit_once('/') {
                    Some((v, p @ ("ScalarAxis" | "TimeAxis"))) => (v.to_owned(), Some(p)),
                    _ => (entity.clone(), None),
                };
                let e = views.entry(view).or_default();
                match property {
                    Some("ScalarAxis") => {
                        if let Some(r) = chunk
                            .iter_component::<rerun::components::Range1D>(range_c)
                            .filter_map(|r| r.first().copied())
                            .last()
                        {
                            e.range = Some(r.0.0);
                        }
                    }
                    Some(_) => {
                        use rerun::external::re_sdk_types::blueprint::components::TimeRange;
                        if let Some(r) =
                            chunk.iter_component::<TimeRange>(time_c).filter_map(|r| r.first().cloned()).last()
                            && let (TimeRangeBoundary::Absolute(a), TimeRangeBoundary::Absolute(b)) =
                                (r.0.start, r.0.end)
                        {
                            e.time_range = Some([secs(a.0), secs(b.0)]);
                        }
                    }
                    None => {
                        for c in chunk.iter_component::<ViewClass>(class_c) {
                            e.class = c.first().map(|c| c.0.0.as_str().to_owned()).unwrap_or_default();
                        }
                        for n in chunk.iter_component::<rerun::components::Name>(name_c) {
                            e.title = n.first().map(|n| n.as_str().to_owned()).unwrap_or_default();
                        }
                        for o in chunk.iter_component::<ViewOrigin>(origin_c) {
                            e.origin = o
                                .first()
                                .map(|o| o.0.0.as_str().trim_start_matches('/').to_owned())
                                .unwrap_or_default();
                        }
                    }
                }
            }
        }
    }
    for r in rows.values_mut() {
        r.sort_by(|a, b| a.1.total_cmp(&b.1));
    }
    let Some((_, views)) = layouts.pop() else { return Ok(Vec::new()) };
    let under = |e: &str, origin: &str| e == origin || e.strip_prefix(origin).is_some_and(|r| r.starts_with('/'));
    Ok(views
        .into_values()
        .filter(|v| v.class == "TimeSeries")
        .map(|v| {
            let mut series = Vec::new();
            for (entity, r) in rows.iter().filter(|(e, _)| under(e, &v.origin)) {
                let style = styles.get(entity).cloned().unwrap_or_default();
                let width = r.iter().map(|(_, _, vals)| vals.len()).max().unwrap_or(0);
                for k in 0..width {
                    series.push(PlotSeries {
                        entity: entity.clone(),
                        name: style.names.get(k).cloned().unwrap_or_default(),
                        color: style.colors.get(k).copied().unwrap_or([200, 200, 200, 255]),
                        width: style.widths.get(k).copied().unwrap_or(1.5),
                        line: style.line || !style.points,
                        markers: style.points.then(|| style.marker.clone().unwrap_or_else(|| "circle".into())),
                        timeline: r.first().map(|x| x.0.clone()).unwrap_or_default(),
                        t: r.iter().map(|x| x.1).collect(),
                        y: r.iter().map(|x| x.2.get(k).copied().unwrap_or(f64::NAN)).collect(),
                    });
                }
            }
            Plot { title: v.title, origin: v.origin, range: v.range, time_range: v.time_range, series }
        })
        .collect())
}
