//! `--figures DIR`: every plot of a recording as SVG and PNG, with real logarithmic axes where the
//! viewer plots log10 values. Golden numbers: NIST SP 1065 (Riley 2008) p. 108, the 1000-point
//! NBS14 set's overlapping ADEV at τ = 1, 10, 100 s — the figure's marker positions must place
//! them on logarithmic axes (equal pixels per decade of τ, pixel heights in the ratio of the
//! published values' logarithms), which no linear drawing of the recording's log10 values could
//! fake without drawing the axes as the viewer does.

// The io tests' helpers (the NBS14 set); test helpers unwrap.
#[allow(dead_code, clippy::unwrap_used)]
#[path = "io/common.rs"]
mod writers;

mod common;
use common::{rinscope, scratch};
use std::path::{Path, PathBuf};

/// SP 1065 p. 108: OADEV at τ = 1, 10, 100 s.
const OADEV: [f64; 3] = [2.922319e-01, 9.159953e-02, 3.241343e-02];

fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("figures dir")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    v.sort();
    v
}

/// The (cx, cy) of every `<circle` in an SVG (the markers of the measured curve).
fn circles(svg: &str) -> Vec<(f64, f64)> {
    let attr = |tag: &str, name: &str| -> Option<f64> {
        let i = tag.find(&format!(" {name}=\""))? + name.len() + 3;
        tag[i..].split('"').next()?.parse().ok()
    };
    svg.split("<circle").skip(1).filter_map(|t| Some((attr(t, "cx")?, attr(t, "cy")?))).collect()
}

#[test]
fn allan_figures_have_logarithmic_axes_that_place_the_published_values() {
    let dir = scratch("allan");
    let csv = dir.join("nbs14.csv");
    let body: String = writers::nbs14_1000().iter().map(|y| format!("{y}\n")).collect();
    std::fs::write(&csv, format!("y\n{body}")).expect("csv");
    let figs = dir.join("figs");
    let o = rinscope()
        .args(["allan", "--series"])
        .arg(&csv)
        .args(["--column", "y:frequency", "--rate-hz", "1", "--estimator", "oadev", "--taus", "decade", "--save"])
        .arg(dir.join("a.rrd"))
        .arg("--figures")
        .arg(&figs)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("figures: 1 plots drawn"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let svgs = files(&figs, "svg");
    assert_eq!(svgs.len(), 1);
    let svg = std::fs::read_to_string(&svgs[0]).expect("svg");
    assert!(svg.contains("OADEV") && svg.contains("τ (s)"), "legend and axis named");
    assert!(!svg.contains("log10"), "a figure on logarithmic axes speaks of no log10 values");
    let mut pts = circles(&svg);
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(pts.len() >= 3, "markers at τ = 1, 10, 100: {pts:?}");
    let [p1, p10, p100] = [pts[0], pts[1], pts[2]];
    // Equal pixels per decade of τ (plotters places on whole units: 1 unit in ~400).
    let (d1, d2) = (p10.0 - p1.0, p100.0 - p10.0);
    assert!(d1 > 100.0 && (d1 - d2).abs() <= 2.0, "decades of τ {d1} and {d2} units wide");
    // Heights in the ratio of log10(σ1/σ10) to log10(σ10/σ100) (SVG y grows downwards).
    let want = (OADEV[0] / OADEV[1]).log10() / (OADEV[1] / OADEV[2]).log10();
    let got = (p10.1 - p1.1) / (p100.1 - p10.1);
    assert!((got - want).abs() / want < 0.02, "height ratio {got}, published values' {want}");
    // The PNG is the same drawing: 2000 × 1120, not blank.
    let png = files(&figs, "png");
    assert_eq!(png.len(), 1);
    let decoder = png::Decoder::new(std::fs::File::open(&png[0]).expect("png"));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("frame");
    assert_eq!((info.width, info.height), (2000, 1120));
    let channels = info.line_size / info.width as usize;
    let dark = buf.chunks(channels).filter(|p| p[0] < 100 && p[1] < 100 && p[2] < 100).count();
    assert!(dark > 2000, "text and axes drawn: {dark} dark pixels");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_run_draws_every_plot_of_its_layout_and_a_bad_folder_costs_nothing() {
    let dir = scratch("run");
    let rec = dir.join("r.rrd");
    let figs = dir.join("figs");
    let o = rinscope()
        .args(["run", "--duration-s", "20", "--save"])
        .arg(&rec)
        .arg("--figures")
        .arg(&figs)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let with_data =
        rinscope::record::read::plot_frames(&rec).expect("readable").iter().filter(|f| f.finite > 0).count();
    assert!(with_data >= 4);
    assert_eq!(files(&figs, "svg").len(), with_data, "one figure per plot with data");
    assert_eq!(files(&figs, "png").len(), with_data);
    // A folder that is a file: refused before anything runs, no recording made.
    let blocker = dir.join("file");
    std::fs::write(&blocker, "x").expect("file");
    let rec2 = dir.join("r2.rrd");
    let o = rinscope()
        .args(["run", "--duration-s", "20", "--save"])
        .arg(&rec2)
        .arg("--figures")
        .arg(&blocker)
        .output()
        .expect("run");
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--figures"), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!rec2.exists(), "nothing saved for a refused run");
    std::fs::remove_dir_all(&dir).ok();
}
