//! The commands: each turns its arguments into parameters and sinks, runs the orchestration in
//! `app`, prints what a user reads and maps failures to exit codes.

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

use super::{CalibrateArgs, Failure, LiveArgs, ModulationArgs, MonteCarloAction, MonteCarloArgs, RunArgs, ScenarioSource, TprArgs};
use crate::app::calibrate::{calibrate_scenario, estimated_compensation, monte_carlo_runs, monte_carlo_setup, record_outcome, CalibrationOutput};
use crate::calib::montecarlo::{self, Shard, ShardFile};
use crate::calib::MonteCarloConfig;
use crate::app::run::run_recorded;
use crate::app::terminate::stop_flag;
use crate::app::{live, modulation, reproduce, tpr};
use crate::ins::reset::sweep_text;
use crate::io::files::write_atomically;
use crate::record::sink::{self, SinkRequest};
use crate::record::APPLICATION_ID;
use crate::scenario::{self, presets, Params};

fn load(args: &RunArgs) -> Result<Params, Failure> {
    let mut params = args.source.load(presets::DEFAULT_SCENARIO)?;
    if let Some(d) = args.duration_s {
        params.set_duration(duration_flag(d)?);
    }
    Ok(params)
}

/// `--duration-s`, checked.
pub(super) fn duration_flag(d: f64) -> Result<f64, Failure> {
    scenario::check_duration(d).map_err(|e| Failure::input(format!("--duration-s {e}")))
}

/// `rinscope run`.
pub(super) fn run(args: &RunArgs) -> Result<(), Failure> {
    let params = load(args)?;
    // The summary file is checked before anything runs, so a typo costs nothing.
    check_output_dir("--summary-json", args.summary_json.as_deref())?;
    let sinks = open_sinks(args.sinks.request(default_recording(&params.meta.name))?, &format!("{}-seed{}", params.meta.name, params.meta.seed))?;
    let stop = stop_flag();
    let mut summary = match run_recorded(&params, &sinks, &stop, true) {
        Ok(s) => s,
        Err(e) => {
            sinks.abandon();
            return Err(e.into());
        }
    };
    let saved = sinks.finish()?;
    (summary.recording_path, summary.recording_bytes) = saved.recording_fields();
    summary.peak_rss_mb = crate::app::bench::peak_rss_bytes() as f64 / 1e6;
    out!("{}", summary.table());
    print_exported(&saved);
    kept(&saved)?;
    if let Some(path) = &args.summary_json {
        write_json("--summary-json", path, &summary)?;
    }
    if let Some(p) = &summary.recording_path {
        outln!("open it with:  rerun {p}     (viewer: {})", sink::VIEWER_INSTALL_HINT);
    }
    if summary.interrupted {
        return Err(Failure::interrupted("the recording is complete up to that moment"));
    }
    Ok(())
}

/// `rinscope live`.
pub(super) fn live(args: &LiveArgs) -> Result<(), Failure> {
    use std::io::IsTerminal;
    // --export: the session's series as tables, written when it ends (with the saved file's
    // stream if there is one, else with the viewer's).
    let export = args.sinks.export_request()?;
    let path = match (&args.config, &args.scenario) {
        (Some(p), _) => p.clone(),
        (None, name) => {
            let name = name.as_deref().unwrap_or(presets::DEFAULT_SCENARIO);
            presets::load(name)?; // a clear error for an unknown name
            let (path, created) = live::ensure_preset_copy(name).map_err(|e| Failure::input(format!("{e:#}")))?;
            let sliders = if args.no_panel { "" } else { ", or move the sliders" };
            errln!("rinscope live: {} {} — edit it{sliders}", if created { "wrote" } else { "using your edited" }, path.display());
            path
        }
    };
    let params = scenario::load_file(&path)?;
    if let Some(s) = args.speed
        && !(s.is_finite() && s > 0.0 && s <= 10_000.0)
    {
        return Err(Failure::input(format!("--speed {s}: must be > 0 and <= 10000 (x real time)")));
    }
    if let Some(d) = args.duration_s {
        duration_flag(d)?;
    }
    let viewer_given = args.sinks.viewer_asked();
    if args.sinks.figures.is_some() && args.sinks.save.is_none() {
        return Err(Failure::input("live --figures DIR draws the session's plots from its saved file when it ends: add --save FILE"));
    }
    if args.no_viewer && args.sinks.save.is_none() {
        return Err(Failure::input("--no-viewer needs --save FILE (otherwise nothing would be kept)"));
    }
    // Two streams: small chunks for viewers, full-size chunks for the saved file (see live::Outputs).
    let viewer_request = SinkRequest {
        spawn: args.sinks.spawn || (!viewer_given && !args.no_viewer),
        connect: args.sinks.connect.clone(),
        serve: args.sinks.serve,
        bind: args.sinks.bind,
        // The class page takes --serve-web's port; the viewer it embeds the next one.
        serve_web: match args.sinks.serve_web {
            Some(p) => Some(p.checked_add(1).filter(|p| p.checked_add(1).is_some()).ok_or_else(|| Failure::input(format!("--serve-web {p}: the class page needs this port and the next two")))?),
            None => None,
        },
        // The class page serves the session so far to late viewers; the stream then keeps none.
        serve_web_history: args.sinks.serve_web,
        stop_on_failure: Some(stop_flag()),
        export: if args.sinks.save.is_none() { export.clone() } else { None },
        ..Default::default()
    };
    let recording_id = format!("{}-seed{}-live", params.meta.name, params.meta.seed);
    // `--serve-web`: the session kept compact in memory for the class page's late viewers.
    let (history, history_requests) = match args.sinks.serve_web {
        Some(_) => {
            let (stream, store) = sink::open_history(APPLICATION_ID, &recording_id)?;
            let (tx, requests) = crossbeam_channel::unbounded();
            (Some(live::History { stream, store, requests }), Some(tx))
        }
        None => (None, None),
    };
    let viewer_sinks = if viewer_request.spawn || viewer_request.connect.is_some() || viewer_request.serve.is_some() || viewer_request.serve_web.is_some() {
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
    let file_sinks = match &args.sinks.save {
        Some(p) => Some(sink::open(&SinkRequest { save: Some(p.clone()), stop_on_failure: Some(stop_flag()), export, figures: args.sinks.figures.clone(), ..Default::default() }, APPLICATION_ID, &recording_id)?),
        None => None,
    };
    for d in viewer_sinks.iter().chain(file_sinks.iter()).flat_map(|s| &s.description) {
        errln!("rinscope live: {d}");
    }
    let panel = !args.no_panel && std::io::stdout().is_terminal() && std::io::stdin().is_terminal();
    let stop = stop_flag();
    if !panel {
        errln!("rinscope live: running; edit {} to change parameters, Ctrl-C to stop", path.display());
    }
    let status = live::new_status(&params, args.speed.unwrap_or(params.live_speed));
    // `--serve-web`: the class page, the viewer beside the sliders, on the port asked for.
    // Its viewer is the web viewer opened above (the next port), the viewer's stream the one after.
    let class_page = match (args.sinks.serve_web, viewer_sinks.as_ref().and_then(sink::OpenSinks::web_page)) {
        (Some(port), Some(_)) => {
            let ip = args.sinks.bind.unwrap_or(std::net::IpAddr::V4(std::net::Ipv4Addr::LOCALHOST));
            let token = if ip.is_loopback() { None } else { Some(live::web::random_token().map_err(|e| Failure::run(format!("no random token for the class page: {e}")))?) };
            let cfg = live::web::PageConfig { addr: std::net::SocketAddr::new(ip, port), host: sink::address::local_host(ip), config_path: path.clone(), token: token.clone(), history: history_requests.clone() };
            let page = live::web::start(cfg, status.clone(), format!("{} — {}", params.meta.name, params.meta.title)).map_err(|e| Failure::input(format!("--serve-web: {e:#}")))?;
            errln!("rinscope live: the class page (viewer and sliders): {}", page.url);
            // Every address: 127.0.0.1 above names each reader's own machine; others open this one's.
            let network_url = if ip.is_unspecified() { sink::address::network_host(ip).map(|h| page.url_at(&h)) } else { None };
            match &network_url {
                Some(url) => errln!("rinscope live: from other machines: {url}"),
                None if ip.is_unspecified() => errln!("rinscope live: from other machines: that URL with this machine's address in place of {} (it has no route out and no name to print)", sink::address::local_host(ip)),
                None => {}
            }
            if token.is_some() {
                errln!("rinscope live: shared beyond this machine: anyone who reaches the page can watch; changing a parameter needs the token in that URL (give it only to whom may)");
            }
            Some((page, network_url))
        }
        _ => None,
    };
    // The panel's title shows the URL the class opens.
    let page_url = class_page.as_ref().map(|(p, network)| network.clone().unwrap_or_else(|| p.url.clone()));
    let options = live::LiveOptions { config_path: path, speed: args.speed, duration_s: args.duration_s, panel, log_to_stderr: true, page_url };
    let outputs = live::Outputs { viewer: viewer_sinks.as_ref().map(sink::OpenSinks::stream), file: file_sinks.as_ref().map(sink::OpenSinks::stream), history };
    let result = live::run_session_with_status(&options, params, outputs, &stop, &status);
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
    let summary = result?;
    outln!(
        "live session: {:.1} s simulated ({} steps), {} reloads applied, save -> applied p95 {:.1} ms",
        summary.sim_t_s,
        summary.steps,
        summary.latencies_ms.len(),
        live::p95(&summary.latencies_ms)
    );
    if let Some((p, bytes)) = saved {
        outln!("recording: {} ({:.2} MB) — open with `rerun {}`, list its events with `rinscope events {}`", p.display(), bytes as f64 / 1e6, p.display(), p.display());
    }
    print_tables(&exported);
    // Ended by a signal (not by `q` or its length): 128 + the signal, as every command.
    if interrupted {
        return Err(Failure::interrupted("the session's recording is complete up to that moment"));
    }
    Ok(())
}

/// `rinscope modulation`.
pub(super) fn modulation(args: &ModulationArgs) -> Result<(), Failure> {
    let hours = args.hours;
    if !(hours.is_finite() && hours > 0.0 && hours <= 24.0 * 30.0) {
        return Err(Failure::input(format!("--hours {hours}: must be > 0 and at most 720 h")));
    }
    let sinks = open_sinks(args.sinks.request(default_recording("rotation-modulation"))?, "rotation-modulation")?;
    let stop = stop_flag();
    let started = std::time::Instant::now();
    errln!("rinscope: simulating {hours} h three times in parallel (no rotation, continuous azimuth, 16-position)...");
    let traces = match modulation::simulate_variants(hours, &stop) {
        Ok(t) => t,
        Err(e) => {
            sinks.abandon();
            return Err(e.into());
        }
    };
    let interrupted = stop.load(Ordering::SeqCst);
    let mut table = modulation::table(&traces, started.elapsed().as_secs_f64());
    if interrupted {
        let reached = traces.iter().filter_map(|t| t.samples.last()).map(|s| s.t_s / 3600.0).fold(f64::INFINITY, f64::min);
        table = format!("INTERRUPTED after {reached:.2} of {hours} h: the numbers below are over that part only, not the run's\n{table}");
    }
    if let Err(e) = crate::record::modulation::log(&sinks.stream(), &traces, &table) {
        sinks.abandon();
        return Err(Failure::run(format!("rerun: {e}")));
    }
    let saved = sinks.finish()?;
    out!("{table}");
    print_saved(&saved)?;
    if interrupted {
        return Err(Failure::interrupted("the table and the recording cover the simulated part only"));
    }
    Ok(())
}

/// Checks an output file's path before anything runs (see [`crate::io::files::check_output_path`]).
pub(super) fn check_output_dir(flag: &str, path: Option<&std::path::Path>) -> Result<(), Failure> {
    match path {
        Some(p) => crate::io::files::check_output_path(p).map_err(|e| Failure::input(format!("{flag} {e}"))),
        None => Ok(()),
    }
}

/// The file a command saves to when no sink is asked for.
pub(super) fn default_recording(name: &str) -> PathBuf {
    PathBuf::from("recordings").join(format!("{name}.rrd"))
}

/// Opens the sinks a command asked for.
pub(super) fn open_sinks(request: SinkRequest, recording_id: &str) -> Result<sink::OpenSinks, Failure> {
    let sinks = sink::open(&request, APPLICATION_ID, recording_id)?;
    for d in &sinks.description {
        errln!("rinscope: {d}");
    }
    Ok(sinks)
}

/// Writes `value` as pretty JSON to the file given with `flag`, atomically.
pub(super) fn write_json(flag: &str, path: &std::path::Path, value: &impl serde::Serialize) -> Result<(), Failure> {
    let json = serde_json::to_string_pretty(value).map_err(|e| Failure::run(e.to_string()))?;
    write_atomically(path, json.as_bytes()).map_err(|e| Failure::output(flag, &e))
}

/// The line that tells where a saved recording is and how to open it; an error if the only
/// destination was a viewer that failed (nothing kept the data).
pub(super) fn print_saved(saved: &sink::Saved) -> Result<(), Failure> {
    if let Some((p, bytes)) = &saved.recording {
        outln!("recording: {} ({:.2} MB) — open with `rerun {}`", p.display(), *bytes as f64 / 1e6, p.display());
    }
    print_exported(saved);
    kept(saved)
}

/// An error if a viewer failed and no file kept the data.
pub(super) fn kept(saved: &sink::Saved) -> Result<(), Failure> {
    if saved.recording.is_none() && !saved.viewer_problems.is_empty() {
        return Err(Failure::run(format!("nothing kept this run's data: {} (add --save FILE)", saved.viewer_problems.join("; "))));
    }
    Ok(())
}

/// The lines that tell where the export tables and the figures are.
pub(super) fn print_exported(saved: &sink::Saved) {
    print_tables(&saved.exported);
    if let Some(f) = &saved.figures {
        let dir = f.files.first().and_then(|p| p.parent()).map_or_else(|| ".".into(), |d| d.display().to_string());
        outln!("figures: {} plots drawn to {dir} (SVG and PNG)", f.plots);
        if let Some(w) = &f.warning {
            errln!("rinscope: --figures: {w}");
        }
    }
}

/// The line that tells where the tables `written` are.
pub(super) fn print_tables(written: &[std::path::PathBuf]) {
    if let Some(first) = written.first() {
        let dir = first.parent().map_or_else(|| ".".into(), |d| d.display().to_string());
        outln!("exported {} tables to {dir} (pandas: pd.read_parquet(path); MATLAB: parquetread(path); docs/export.md)", written.len());
    }
}

/// `rinscope calibrate`.
pub(super) fn calibrate(args: &CalibrateArgs) -> Result<(), Failure> {
    if let Some(dir) = &args.log {
        return super::logs::calibrate_log(args, dir);
    }
    let params = args.source.load("jiang2017-calibration")?;
    check_output_dir("--json", args.json.as_deref())?;
    let sinks = if args.no_recording {
        None
    } else {
        let request = args.sinks.request(default_recording(&format!("{}-calibration", params.meta.name)))?;
        Some(open_sinks(request, &format!("{}-calibration-seed{}", params.meta.name, params.meta.seed))?)
    };
    let started = std::time::Instant::now();
    let stop = stop_flag();
    let outcome = match calibrate_scenario(&params, sinks.is_some(), &stop) {
        Ok(o) => o,
        Err(e) => {
            if let Some(s) = sinks {
                s.abandon();
            }
            return Err(Failure::calibration("calibrate", e, "calibrate did not finish; nothing was estimated and no recording was made"));
        }
    };
    let wall = started.elapsed().as_secs_f64();
    out!("{}", outcome.report.text());
    outln!("({wall:.2} s wall: two {:.0}-s runs simulated, filter and least squares)", params.duration_s);
    if let Some(path) = &args.json {
        let compensation = estimated_compensation(&params.table.chain, &outcome.cal, &params.calibration_known);
        write_json("--json", path, &CalibrationOutput { report: &outcome.report, estimated_compensation: compensation })?;
    }
    if let Some(sinks) = sinks {
        if let Err(e) = record_outcome(sinks.stream(), &params, &outcome, &stop) {
            sinks.abandon();
            return Err(Failure::run(format!("rerun: {e}")));
        }
        print_saved(&sinks.finish()?)?;
    }
    if stop.load(Ordering::SeqCst) {
        return Err(Failure::interrupted("the estimates above are complete; the recording's table motion stops where it was cut short"));
    }
    Ok(())
}

/// The calibration preset with `--eta-measured-sigma-arcsec` applied.
fn monte_carlo_params(source: &ScenarioSource, eta_measured_sigma_arcsec: Option<f64>) -> Result<Params, Failure> {
    let mut params = source.load("jiang2017-calibration")?;
    if let Some(s) = eta_measured_sigma_arcsec {
        params.calibration.montecarlo.set_eta_measured_sigma_arcsec(s).map_err(|e| Failure::input(format!("--eta-measured-sigma-arcsec {e}")))?;
    }
    Ok(params)
}

/// `rinscope montecarlo`.
pub(super) fn montecarlo(args: &MonteCarloArgs) -> Result<(), Failure> {
    if let Some(MonteCarloAction::Merge { files, source, eta_measured_sigma_arcsec, json }) = &args.action {
        return montecarlo_merge(files, source, *eta_measured_sigma_arcsec, json.as_deref());
    }
    let params = monte_carlo_params(&args.source, args.eta_measured_sigma_arcsec)?;
    check_output_dir("--json", args.json.as_deref())?;
    let runs = MonteCarloConfig::check_runs(args.runs.unwrap_or(params.calibration.montecarlo.runs as usize)).map_err(|e| Failure::input(format!("--runs {e}")))?;
    let shard = match &args.shard {
        Some(text) => Shard::parse(text).map_err(|e| Failure::input(format!("--shard {e}")))?,
        None => Shard::WHOLE,
    };
    let mine = shard.indices(runs as u64).len();
    let stop = stop_flag();
    let bar = indicatif::ProgressBar::new(mine as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {pos}/{len} calibrations [{bar:40}] {elapsed_precise} (eta {eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let tick = || bar.inc(1);
    let started = std::time::Instant::now();
    let result = monte_carlo_runs(&params, runs, shard, &tick, &stop);
    bar.finish_and_clear();
    let done = result.map_err(|e| Failure::calibration("montecarlo", e, "montecarlo did not finish"))?;
    let summary = montecarlo::summarize(&monte_carlo_setup(&params), runs, &done, started.elapsed().as_secs_f64());
    if shard != Shard::WHOLE {
        outln!("shard {}/{}: {} of the {runs} runs (i mod {} == {})", shard.index, shard.count, mine, shard.count, shard.index);
    }
    out!("{}", summary.text());
    if let Some(path) = &args.json {
        if shard == Shard::WHOLE {
            write_json("--json", path, &summary)?;
        } else {
            write_json("--json", path, &ShardFile { shard, summary: summary.clone(), runs: done.clone() })?;
        }
    }
    if done.len() < mine {
        return Err(Failure::interrupted(format!("after {} of {mine} runs (the statistics above are over those only)", done.len())));
    }
    Ok(())
}

/// `rinscope montecarlo merge`.
fn montecarlo_merge(files: &[PathBuf], source: &ScenarioSource, eta_measured_sigma_arcsec: Option<f64>, json: Option<&Path>) -> Result<(), Failure> {
    let params = monte_carlo_params(source, eta_measured_sigma_arcsec)?;
    check_output_dir("--json", json)?;
    let mut shards = Vec::new();
    for f in files {
        let text = read_small_file(f, "shard file")?;
        let shard: ShardFile = serde_json::from_str(&text).map_err(|e| Failure::input(format!("{}: not a shard file of `rinscope montecarlo --shard K/M --json` ({e})", f.display())))?;
        shards.push(shard);
    }
    let setup = monte_carlo_setup(&params);
    let summary = montecarlo::merge(&setup, &shards).map_err(|e| Failure::input(format!("montecarlo merge: {e}")))?;
    if let Some(first) = shards.first()
        && first.summary.setup != summary.setup
    {
        return Err(Failure::input(format!(
            "montecarlo merge: the shards ran with \"{}\", this merge with \"{}\" (give the same --scenario/--config and --eta-measured-sigma-arcsec)",
            first.summary.setup, summary.setup
        )));
    }
    out!("{}", summary.text());
    if let Some(path) = json {
        write_json("--json", path, &summary)?;
    }
    Ok(())
}

/// Reads a text file of at most 1 GB (opened by the rule for every input: a FIFO or a device is
/// refused at once).
pub(super) fn read_small_file(path: &Path, what: &str) -> Result<String, Failure> {
    use std::io::Read as _;
    let fail = |e: std::io::Error| Failure::input(format!("{what} {}: {e}", path.display()));
    let file = crate::io::files::open_input(path).map_err(fail)?;
    let len = file.metadata().map_err(fail)?.len();
    if len > 1 << 30 {
        return Err(Failure::input(format!("{what} {}: {len} bytes, more than the 1 GB such a file can be", path.display())));
    }
    let mut text = String::new();
    file.take((1 << 30) + 1).read_to_string(&mut text).map_err(fail)?;
    Ok(text)
}

/// `rinscope tpr`.
pub(super) fn tpr(args: &TprArgs) -> Result<(), Failure> {
    let params = args.source.load("zheng2016-tpr")?;
    check_output_dir("--json", args.json.as_deref())?;
    tpr::check(&params).map_err(|e| Failure::input(format!("tpr: {e}")))?;
    let sinks = open_sinks(args.sinks.request(default_recording(&params.meta.name))?, &format!("{}-seed{}", params.meta.name, params.meta.seed))?;
    let stop = stop_flag();
    errln!("rinscope: navigating {:.1} h (forking at the second fix)...", params.duration_s / 3600.0);
    let result = match tpr::compare_resets(&params, 60.0, &stop) {
        Ok(r) => r,
        Err(e) => {
            sinks.abandon();
            return Err(Failure::input(format!("tpr: {e}")));
        }
    };
    let text = result.text();
    if let Err(e) = crate::record::tpr::log(&sinks.stream(), &params, &result, &text) {
        sinks.abandon();
        return Err(Failure::run(format!("rerun: {e}")));
    }
    let saved = sinks.finish()?;
    out!("{text}");
    if let Some(path) = &args.json {
        write_json("--json", path, &result)?;
    }
    print_saved(&saved)?;
    if !result.complete {
        return Err(Failure::interrupted("the recording holds what was simulated until then"));
    }
    if let Some(n) = args.seeds {
        errln!("rinscope: {n} seeds from {} in parallel...", params.meta.seed);
        let started = std::time::Instant::now();
        let rows = tpr::sweep(&params, n, &stop).map_err(|e| Failure::input(format!("tpr: {e}")))?;
        if stop.load(Ordering::SeqCst) {
            return Err(Failure::interrupted("the seed sweep did not finish"));
        }
        out!("{}", sweep_text(&rows));
        outln!("  {n} runs of {:.1} h in {:.1} s", params.duration_s / 3600.0, started.elapsed().as_secs_f64());
    }
    Ok(())
}

/// `rinscope events`.
pub(super) fn events(file: &Path) -> Result<(), Failure> {
    let events = crate::record::read::events(file).map_err(|e| Failure::input(format!("{e:#}")))?;
    for e in events {
        match e.t_s {
            Some(t) => outln!("{t:>10.3} s  {:<5} {}", e.level, e.text),
            None => outln!("{:>12}  {:<5} {}", "static", e.level, e.text),
        }
    }
    Ok(())
}

/// `rinscope scenarios`.
pub(super) fn list_scenarios() {
    for (name, _) in presets::PRESETS {
        match presets::load(name) {
            Ok(p) => {
                let mark = if *name == presets::DEFAULT_SCENARIO { " (default)" } else { "" };
                outln!("{name}{mark}\n    {}", p.meta.title);
            }
            Err(e) => outln!("{name}\n    BROKEN: {e}"),
        }
    }
}

/// `rinscope check-config`.
pub(super) fn check_config(file: &Path) -> Result<(), Failure> {
    let p = scenario::load_file(file)?;
    let axes: Vec<String> = p.table.chain.axes().iter().map(|a| a.name.clone()).collect();
    outln!(
        "{}: ok — scenario \"{}\", {} s at {} Hz ({} steps), axes {:?}, seed {}",
        file.display(),
        p.meta.name,
        p.duration_s,
        p.step_hz,
        p.timeline().instants(),
        axes,
        p.meta.seed
    );
    Ok(())
}

/// `rinscope reproduce`.
pub(super) fn reproduce(markdown: Option<&Path>) -> Result<(), Failure> {
    let table = reproduce::run_all()?;
    out!("{}", table.text());
    if let Some(path) = markdown {
        write_atomically(path, table.markdown().as_bytes()).map_err(|e| Failure::output("--markdown", &e))?;
    }
    if table.all_agree() {
        Ok(())
    } else {
        Err(Failure::run("some reproductions fall outside their tolerance (see the table)"))
    }
}

/// `bench`.
pub(super) fn bench(steps: u64, json: Option<&std::path::Path>, only: &[String]) -> Result<(), Failure> {
    check_output_dir("--json", json)?;
    let stop = stop_flag();
    let figures = match crate::app::bench::run_benchmarks(steps, only, &stop) {
        Ok(f) => f,
        Err(_) if stop.load(std::sync::atomic::Ordering::SeqCst) => return Err(Failure::interrupted("the figures printed so far are not a whole benchmark; none written")),
        Err(e) => return Err(Failure::from(e)),
    };
    if let Some(path) = json {
        write_json("--json", path, &figures)?;
    }
    Ok(())
}

/// `bench --peer allantools`.
pub(super) fn bench_allantools(python: &std::path::Path, rounds: usize, samples: u64, json: Option<&std::path::Path>) -> Result<(), Failure> {
    use crate::app::bench::allantools;
    check_output_dir("--json", json)?;
    let stop = stop_flag();
    let reports = match allantools::compare(python, samples, rounds, &stop) {
        Ok(r) => r,
        Err(_) if stop.load(std::sync::atomic::Ordering::SeqCst) => return Err(Failure::interrupted("the comparison did not finish; nothing written")),
        Err(e) => return Err(Failure::run(format!("{e:#}"))),
    };
    out!("{}", allantools::text(&reports, samples));
    if let Some(path) = json {
        write_json("--json", path, &reports)?;
    }
    Ok(())
}

/// `bench --peer pyins`.
pub(super) fn bench_peer(python: PathBuf, rounds: usize, samples: u64, json: Option<&std::path::Path>) -> Result<(), Failure> {
    use crate::app::bench::peer;
    check_output_dir("--json", json)?;
    let stop = stop_flag();
    let reports = match peer::compare(&peer::PeerOptions { python, rounds, samples }, &stop) {
        Ok(r) => r,
        Err(_) if stop.load(std::sync::atomic::Ordering::SeqCst) => return Err(Failure::interrupted("the comparison did not finish; nothing written")),
        Err(e) => return Err(Failure::run(format!("{e:#}"))),
    };
    out!("{}", peer::text(&reports));
    if let Some(path) = json {
        write_json("--json", path, &reports)?;
    }
    Ok(())
}
