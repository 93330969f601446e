//! `live`'s one owner: what the command line asks for, turned into a session with its viewer,
//! its saved file and its class page.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::app::failure::Failure;
use crate::app::outputs::RecordingName;
use crate::io::validity::{Range, check_number};
use crate::record::APPLICATION_ID;
use crate::record::sink::{self, SinkRequest};
use crate::scenario::{self, Params, presets};

/// `--speed`: simulated seconds per wall-clock second, > 0 and at most 10 000 (faster, a step's
/// drawing no longer keeps up).
pub const SPEED: Range = Range::positive(10_000.0, "× real time", "a speed");

/// `rinscope live`.
pub struct LiveRequest {
    /// The config file to run and watch; `None`: an editable copy of `scenario`.
    pub config: Option<PathBuf>,
    /// The preset (default: the default scenario) when no `config` is given.
    pub scenario: Option<String>,
    /// The sinks as asked for (`save`, viewers, `export`, `figures`).
    pub sinks: SinkRequest,
    /// Times real time (default: the scenario's `[live] speed`).
    pub speed: Option<f64>,
    /// End after this much simulated time, s.
    pub duration_s: Option<f64>,
    /// No viewer (a saved file only).
    pub no_viewer: bool,
    /// The slider panel, when stdin and stdout are a terminal.
    pub panel: bool,
    /// A compensation document (its text and where it came from): its table part written into the
    /// config's `[compensation]`, its IMU part removed from the INS's samples for the session.
    pub compensation: Option<(String, String)>,
}

/// What a live session reports.
pub struct LiveReport {
    /// The session's numbers.
    pub summary: super::LiveSummary,
    /// The saved file and its size, bytes.
    pub recording: Option<(PathBuf, u64)>,
    /// The export tables written.
    pub exported: Vec<PathBuf>,
    /// A signal ended the session.
    pub interrupted: bool,
}

/// `live`'s one owner: the config file (a preset's editable copy unless one is given), the
/// viewer's and the file's sinks, the class page, the session, the outputs completed whatever
/// happened.
///
/// # Errors
/// Bad input, a sink that cannot be opened; the session's own failure after the outputs are
/// complete.
pub fn execute(req: &LiveRequest, stop: &Arc<AtomicBool>) -> Result<LiveReport, Failure> {
    use std::io::IsTerminal;
    // --export: the session's series as tables, written when it ends (with the saved file's
    // stream if there is one, else with the viewer's).
    let export = req.sinks.export.clone();
    let path = match (&req.config, &req.scenario) {
        (Some(p), _) => p.clone(),
        (None, name) => {
            let name = name.as_deref().unwrap_or(presets::DEFAULT_SCENARIO);
            presets::load(name)?; // a clear error for an unknown name
            let (path, created) = super::ensure_preset_copy(name).map_err(|e| Failure::input(format!("{e:#}")))?;
            let sliders = if !req.panel { "" } else { ", or move the sliders" };
            errln!(
                "rinscope live: {} {} — edit it{sliders}",
                if created { "wrote" } else { "using your edited" },
                path.display()
            );
            path
        }
    };
    let params = match &req.compensation {
        Some((text, origin)) => with_compensation(&path, text, origin)?,
        None => scenario::load_file(&path)?,
    };
    if let Some(s) = req.speed {
        check_number(s, &SPEED).map_err(|e| Failure::input(format!("--speed {e}")))?;
    }
    let viewer_given =
        req.sinks.spawn || req.sinks.connect.is_some() || req.sinks.serve.is_some() || req.sinks.serve_web.is_some();
    if req.sinks.figures.is_some() && req.sinks.save.is_none() {
        return Err(Failure::input(
            "live --figures DIR draws the session's plots from its saved file when it ends: add --save FILE",
        ));
    }
    if req.no_viewer && req.sinks.save.is_none() {
        return Err(Failure::input("--no-viewer needs --save FILE (otherwise nothing would be kept)"));
    }
    // Two streams: small chunks for viewers, full-size chunks for the saved file (see super::Outputs).
    let viewer_request = SinkRequest {
        spawn: req.sinks.spawn || (!viewer_given && !req.no_viewer),
        connect: req.sinks.connect.clone(),
        serve: req.sinks.serve,
        bind: req.sinks.bind,
        // The class page takes --serve-web's port; the viewer it embeds the next one.
        serve_web: match req.sinks.serve_web {
            Some(p) => Some(p.checked_add(1).filter(|p| p.checked_add(1).is_some()).ok_or_else(|| {
                Failure::input(format!("--serve-web {p}: the class page needs this port and the next two"))
            })?),
            None => None,
        },
        // The class page serves the session so far to late viewers; the stream then keeps none.
        serve_web_history: req.sinks.serve_web,
        stop_on_failure: Some(Arc::clone(stop)),
        export: if req.sinks.save.is_none() { export.clone() } else { None },
        ..Default::default()
    };
    let recording_id = RecordingName { name: &params.meta.name, kind: Some("live"), seed: Some(params.meta.seed) }.id();
    // `--serve-web`: the session kept compact in memory for the class page's late viewers.
    let (history, history_requests) = match req.sinks.serve_web {
        Some(_) => {
            let (stream, store) = sink::open_history(APPLICATION_ID, &recording_id)?;
            let (tx, requests) = crossbeam_channel::unbounded();
            (Some(super::History { stream, store, requests }), Some(tx))
        }
        None => (None, None),
    };
    let viewer_sinks = if viewer_request.spawn
        || viewer_request.connect.is_some()
        || viewer_request.serve.is_some()
        || viewer_request.serve_web.is_some()
    {
        let implicit = !viewer_given;
        Some(sink::open(&viewer_request, APPLICATION_ID, &recording_id).map_err(|e| {
            let mut f = Failure::from(e);
            if implicit {
                f.message.push_str("\n(live opens a viewer unless told otherwise: `rinscope live --no-viewer --save session.rrd` runs without one, `--serve` streams to a viewer elsewhere)");
            }
            f
        })?)
    } else {
        None
    };
    let file_sinks = match &req.sinks.save {
        Some(p) => Some(sink::open(
            &SinkRequest {
                save: Some(p.clone()),
                stop_on_failure: Some(Arc::clone(stop)),
                export,
                figures: req.sinks.figures.clone(),
                ..Default::default()
            },
            APPLICATION_ID,
            &recording_id,
        )?),
        None => None,
    };
    for d in viewer_sinks.iter().chain(file_sinks.iter()).flat_map(|s| &s.description) {
        errln!("rinscope live: {d}");
    }
    let panel = req.panel && std::io::stdout().is_terminal() && std::io::stdin().is_terminal();
    if !panel {
        errln!("rinscope live: running; edit {} to change parameters, Ctrl-C to stop", path.display());
    }
    let status = super::new_status(&params, req.speed.unwrap_or(params.live_speed));
    // `--serve-web`: the class page, the viewer beside the sliders, on the port asked for.
    // Its viewer is the web viewer opened above (the next port), the viewer's stream the one after.
    let class_page = match (req.sinks.serve_web, viewer_sinks.as_ref().and_then(sink::OpenSinks::web_page)) {
        (Some(port), Some(_)) => {
            let ip = req.sinks.bind.unwrap_or(std::net::IpAddr::V4(std::net::Ipv4Addr::LOCALHOST));
            let token = if ip.is_loopback() {
                None
            } else {
                Some(
                    super::web::random_token()
                        .map_err(|e| Failure::run(format!("no random token for the class page: {e}")))?,
                )
            };
            let cfg = super::web::PageConfig {
                addr: std::net::SocketAddr::new(ip, port),
                host: sink::address::local_host(ip),
                config_path: path.clone(),
                token: token.clone(),
                history: history_requests.clone(),
            };
            let page = super::web::start(cfg, status.clone(), format!("{} — {}", params.meta.name, params.meta.title))
                .map_err(|e| Failure::input(format!("--serve-web: {e:#}")))?;
            errln!("rinscope live: the class page (viewer and sliders): {}", page.url);
            // Every address: 127.0.0.1 above names each reader's own machine; others open this one's.
            let network_url =
                if ip.is_unspecified() { sink::address::network_host(ip).map(|h| page.url_at(&h)) } else { None };
            match &network_url {
                Some(url) => errln!("rinscope live: from other machines: {url}"),
                None if ip.is_unspecified() => errln!(
                    "rinscope live: from other machines: that URL with this machine's address in place of {} (it has no route out and no name to print)",
                    sink::address::local_host(ip)
                ),
                None => {}
            }
            if token.is_some() {
                errln!(
                    "rinscope live: shared beyond this machine: anyone who reaches the page can watch; changing a parameter needs the token in that URL (give it only to whom may)"
                );
            }
            Some((page, network_url))
        }
        _ => None,
    };
    // The panel's title shows the URL the class opens.
    let page_url = class_page.as_ref().map(|(p, network)| network.clone().unwrap_or_else(|| p.url.clone()));
    let options = super::LiveOptions {
        config_path: path,
        speed: req.speed,
        duration_s: req.duration_s,
        panel,
        log_to_stderr: true,
        page_url,
    };
    let outputs = super::Outputs {
        viewer: viewer_sinks.as_ref().map(sink::OpenSinks::stream),
        file: file_sinks.as_ref().map(sink::OpenSinks::stream),
        history,
    };
    let result = super::run_session_with_status(&options, params, outputs, stop, &status);
    // A signal that ended the session (not one that ends the wait of a viewer left open after it).
    let interrupted = crate::app::terminate::stop_reason().is_some();
    drop(class_page);
    // Whatever happened, complete the saved file: it holds everything simulated so far.
    let mut exported = Vec::new();
    if let Some(Ok(done)) = viewer_sinks.map(sink::OpenSinks::finish) {
        exported.extend(done.exported);
    }
    let saved = match file_sinks {
        Some(f) => {
            let done = f.finish()?;
            exported.extend(done.exported);
            done.recording
        }
        None => None,
    };
    Ok(LiveReport { summary: result?, recording: saved, exported, interrupted })
}

/// The session's parameters with a compensation document in force: its table part written into
/// the config's `[compensation]` keys (one atomic write; the file stays the one place a session's
/// table compensation is read from, so the sliders, the editor and "calibrate now" go on from it),
/// its IMU part held by the INS for the whole session (like `[imu]`, it cannot change while the
/// INS integrates in its frame). Checked against the scenario before anything is written.
fn with_compensation(path: &std::path::Path, text: &str, origin: &str) -> Result<Params, Failure> {
    let mut checked = scenario::load_file(path)?;
    let notes = scenario::compensation::apply_to_scenario(&mut checked, text, origin)?;
    let keys = scenario::compensation::table_keys(text, origin)?;
    if !keys.is_empty() {
        let writes: Vec<_> = keys
            .iter()
            .map(|(k, v)| {
                let value = match v {
                    toml::Value::Float(x) => super::edit::float(*x),
                    toml::Value::Integer(i) => toml_edit::Value::from(*i),
                    toml::Value::Boolean(b) => toml_edit::Value::from(*b),
                    other => toml_edit::Value::from(other.to_string()),
                };
                (super::edit::KeyPath::parse(k), value)
            })
            .collect();
        super::edit::set_many_in_file(path, &writes).map_err(|e| Failure::input(format!("--compensation: {e}")))?;
        errln!(
            "rinscope live: {origin}'s table compensation written into {}'s [compensation] ({} keys)",
            path.display(),
            keys.len()
        );
    }
    let mut params = scenario::load_file(path)?;
    if let (Some(ins), Some(checked)) = (params.ins.as_mut(), checked.ins.as_ref()) {
        ins.imu_compensation = checked.imu_compensation;
    }
    for n in notes {
        errln!("rinscope live: {n}");
    }
    Ok(params)
}
