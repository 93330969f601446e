//! Reading a recording back: the text-log entries of `events`, so a user (and the tests) can list
//! what happened in a saved session — reloads, errors, the end — without opening the viewer; and
//! what it holds (its entities, the views of its layout), so a test can check that a recording has
//! what it should and that its layout shows nothing it lacks.

use std::collections::BTreeSet;
use std::io::BufReader;
use std::path::Path;

use rerun::external::re_log_encoding::DecoderApp;
use rerun::external::re_log_types::{LogMsg, StoreKind};
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

/// The `events` entries of the recording at `path`, in time order.
pub fn events(path: &Path) -> anyhow::Result<Vec<Event>> {
    let file = crate::io::files::open_input(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let decoder = DecoderApp::decode_eager(BufReader::new(file)).map_err(|e| anyhow::anyhow!("{}: not a readable .rrd: {e}", path.display()))?;
    let text_component = rerun::TextLog::descriptor_text().component;
    let level_component = rerun::TextLog::descriptor_level().component;
    let mut out = Vec::new();
    for msg in decoder {
        let msg = msg.map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let LogMsg::ArrowMsg(store_id, arrow_msg) = msg else { continue };
        if store_id.kind() != StoreKind::Recording {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(&arrow_msg)?;
        if chunk.entity_path().to_string() != "/events" {
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
    let file = crate::io::files::open_input(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let decoder = DecoderApp::decode_eager(BufReader::new(file)).map_err(|e| anyhow::anyhow!("{}: not a readable .rrd: {e}", path.display()))?;
    let origin_component = ViewBlueprint::descriptor_space_origin().component;
    let mut out = Contents::default();
    for msg in decoder {
        let msg = msg.map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let LogMsg::ArrowMsg(store_id, arrow_msg) = msg else { continue };
        let chunk = Chunk::from_arrow_msg(&arrow_msg)?;
        let entity = chunk.entity_path().to_string().trim_start_matches('/').to_owned();
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
