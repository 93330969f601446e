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

/// The data chunks of the recording at `path`, each with its store's kind and its entity path
/// (without the leading `/`); an unreadable file named in the error.
fn chunks(path: &Path) -> anyhow::Result<impl Iterator<Item = anyhow::Result<(StoreId, String, Chunk)>> + '_> {
    let file = crate::io::files::open_input(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let decoder = DecoderApp::decode_eager(BufReader::new(file)).map_err(|e| anyhow::anyhow!("{}: not a readable .rrd: {e}", path.display()))?;
    Ok(decoder.filter_map(move |m| match m {
        Err(e) => Some(Err(anyhow::anyhow!("{}: {e}", path.display()))),
        Ok(LogMsg::ArrowMsg(store_id, arrow_msg)) => Some(Chunk::from_arrow_msg(&arrow_msg).map_err(anyhow::Error::from).map(|chunk| {
            let entity = chunk.entity_path().to_string().trim_start_matches('/').to_owned();
            (store_id, entity, chunk)
        })),
        Ok(_) => None,
    }))
}

/// The `events` entries of the recording at `path`, in time order.
pub fn events(path: &Path) -> anyhow::Result<Vec<Event>> {
    let text_component = rerun::TextLog::descriptor_text().component;
    let level_component = rerun::TextLog::descriptor_level().component;
    let mut out = Vec::new();
    for item in chunks(path)? {
        let (store_id, entity, chunk) = item?;
        if store_id.kind() != StoreKind::Recording || entity != "events" {
            continue;
        }
        let times: Vec<Option<f64>> = chunk
            .iter_component_indices(TIMELINE.into(), text_component)
            .map(|(t, _)| if t.is_static() { None } else { Some(t.as_i64() as f64 / 1e9) })
            .collect();
        let texts: Vec<String> = chunk.iter_component::<rerun::components::Text>(text_component).map(|v| v.iter().map(|t| t.as_str().to_owned()).collect::<Vec<_>>().join("\n")).collect();
        let levels: Vec<String> =
            chunk.iter_component::<rerun::components::TextLogLevel>(level_component).map(|v| v.iter().map(|l| l.as_str().to_owned()).collect::<String>()).collect();
        for (i, text) in texts.into_iter().enumerate() {
            out.push(Event { t_s: times.get(i).copied().flatten(), level: levels.get(i).cloned().unwrap_or_default(), text });
        }
    }
    out.sort_by(|a, b| a.t_s.unwrap_or(-1.0).total_cmp(&b.t_s.unwrap_or(-1.0)));
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
        self.view_origins.iter().filter(|o| !self.entities.iter().any(|e| e == *o || e.starts_with(&format!("{o}/")))).cloned().collect()
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
    use rerun::external::re_sdk_types::blueprint::archetypes::{ScalarAxis, ViewBlueprint};
    use rerun::external::re_sdk_types::blueprint::components::{ViewClass, ViewOrigin};
    use std::collections::BTreeMap;
    let scalar = rerun::Scalars::descriptor_scalars().component;
    let (origin_c, class_c, name_c) = (ViewBlueprint::descriptor_space_origin().component, ViewBlueprint::descriptor_class_identifier().component, ViewBlueprint::descriptor_display_name().component);
    let range_c = ScalarAxis::descriptor_range().component;
    // Per entity: finite count, min, max, non-finite count.
    let mut data: BTreeMap<String, (usize, f64, f64, usize)> = BTreeMap::new();
    // Per blueprint store, in order: view entity → (class, title, origin, range).
    type Views = BTreeMap<String, (String, String, String, Option<[f64; 2]>)>;
    let mut layouts: Vec<(String, Views)> = Vec::new();
    for item in chunks(path)? {
        let (store_id, entity, chunk) = item?;
        match store_id.kind() {
            StoreKind::Recording => {
                for values in chunk.iter_component::<rerun::components::Scalar>(scalar) {
                    let d = data.entry(entity.clone()).or_insert((0, f64::INFINITY, f64::NEG_INFINITY, 0));
                    for v in values.iter().map(|s| s.0.0) {
                        if v.is_finite() {
                            *d = (d.0 + 1, d.1.min(v), d.2.max(v), d.3);
                        } else {
                            d.3 += 1;
                        }
                    }
                }
            }
            StoreKind::Blueprint => {
                let key = format!("{store_id:?}");
                if layouts.last().is_none_or(|(k, _)| *k != key) {
                    layouts.retain(|(k, _)| *k != key);
                    layouts.push((key, BTreeMap::new()));
                }
                let Some((_, views)) = layouts.last_mut() else { continue };
                let (view, property) = match entity.strip_suffix("/ScalarAxis") {
                    Some(v) => (v.to_owned(), true),
                    None => (entity.clone(), false),
                };
                let e = views.entry(view).or_insert_with(|| (String::new(), String::new(), String::new(), None));
                if property {
                    for r in chunk.iter_component::<rerun::components::Range1D>(range_c) {
                        if let Some(r) = r.first() {
                            e.3 = Some(r.0.0);
                        }
                    }
                } else {
                    for c in chunk.iter_component::<ViewClass>(class_c) {
                        e.0 = c.first().map(|c| c.0.0.as_str().to_owned()).unwrap_or_default();
                    }
                    for n in chunk.iter_component::<rerun::components::Name>(name_c) {
                        e.1 = n.first().map(|n| n.as_str().to_owned()).unwrap_or_default();
                    }
                    for o in chunk.iter_component::<ViewOrigin>(origin_c) {
                        e.2 = o.first().map(|o| o.0.0.as_str().trim_start_matches('/').to_owned()).unwrap_or_default();
                    }
                }
            }
        }
    }
    let Some((_, views)) = layouts.pop() else { return Ok(Vec::new()) };
    Ok(views
        .into_values()
        .filter(|(class, ..)| class == "TimeSeries")
        .map(|(_, title, origin, range)| {
            let mut f = PlotFrame { title, origin: origin.clone(), range, finite: 0, min: f64::INFINITY, max: f64::NEG_INFINITY, non_finite: 0 };
            for (_, d) in data.iter().filter(|(e, _)| **e == origin || e.strip_prefix(origin.as_str()).is_some_and(|r| r.starts_with('/'))) {
                (f.finite, f.min, f.max, f.non_finite) = (f.finite + d.0, f.min.min(d.1), f.max.max(d.2), f.non_finite + d.3);
            }
            f
        })
        .collect())
}
