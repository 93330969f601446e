//! Reading a recording back: the text-log entries of `events`, so a user (and the tests) can list
//! what happened in a saved session — reloads, errors, the end — without opening the viewer.

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
    let file = std::fs::File::open(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
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
