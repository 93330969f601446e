//! `--figures DIR`: every time-series plot of a finished recording drawn for a report, as SVG
//! (plotters) and as PNG (that SVG rasterised by resvg with the system's fonts, so the two are one
//! drawing). Drawn from the saved `.rrd` itself ([`super::read::plots`]): the same views, titles,
//! series names and colours a reader sees in the viewer, whichever command made it. Where the
//! recording plots log10 values (the Allan plots: log10 τ on the `log10_tau_s` timeline, log10 σ as
//! values), the figure has real logarithmic axes instead. On the figures' white background a
//! colour made for the viewer's dark one (a near-white curve) is darkened, hue kept, to a 3:1
//! contrast (WCAG's for graphics); no other change.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

use super::read::{Plot, PlotSeries};
use crate::io::files::write_atomically;

/// Every length of the drawing in units of this many SVG units: plotters places on whole units,
/// so a drawing twice as fine has lines without visible steps.
const K: i32 = 2;
/// Figure size, SVG units (= the PNG's pixels).
const SIZE: (u32, u32) = (1000 * K as u32, 560 * K as u32);
/// Points of a line above which it is reduced to each bucket's first, smallest, largest and last.
const MAX_LINE_POINTS: usize = 6000;

/// What [`write`] left.
#[derive(Debug, Clone, Default)]
pub struct Written {
    /// Every file written, SVG and PNG.
    pub files: Vec<PathBuf>,
    /// Plots drawn.
    pub plots: usize,
    /// Why the PNGs lack text, if they do (no system font).
    pub warning: Option<String>,
    /// The stop flag was set before every plot was drawn: `files` are the figures finished
    /// before it (each whole; the one being drawn was not written).
    pub interrupted: bool,
}

/// Draws every time-series plot of the recording at `rrd` into `dir` (created if missing; its
/// parent must exist, as for every output folder: [`crate::io::files::create_output_dir`]) as
/// `NN-<origin>.svg` and `.png`, each file written atomically. `stop` is looked at before each
/// plot (one takes a few hundred ms): once set, the drawing ends with the figures finished so far
/// and [`Written::interrupted`].
///
/// # Errors
/// An unreadable recording, a plot that cannot be drawn, a file that cannot be written.
pub fn write(rrd: &Path, dir: &Path, stop: &AtomicBool) -> anyhow::Result<Written> {
    if stop.load(Ordering::SeqCst) {
        return Ok(Written { interrupted: true, ..Written::default() });
    }
    let plots = super::read::plots(rrd)?;
    crate::io::files::create_output_dir("--figures", dir).map_err(|e| anyhow::anyhow!("{}", e.error))?;
    let (fonts, warning) = fonts();
    let mut out = Written { warning, ..Written::default() };
    for (i, plot) in plots.iter().filter(|p| p.series.iter().any(|s| s.y.iter().any(|v| v.is_finite()))).enumerate() {
        if stop.load(Ordering::SeqCst) {
            out.interrupted = true;
            break;
        }
        let stem = format!("{:02}-{}", i + 1, slug(&plot.origin));
        let svg = svg(plot)?;
        let svg_path = dir.join(format!("{stem}.svg"));
        write_atomically(&svg_path, svg.as_bytes()).map_err(|e| anyhow::anyhow!("{e}"))?;
        let png_path = dir.join(format!("{stem}.png"));
        write_atomically(&png_path, &png(&svg, &fonts)?).map_err(|e| anyhow::anyhow!("{e}"))?;
        out.files.extend([svg_path, png_path]);
        out.plots += 1;
    }
    Ok(out)
}

/// `attitude_error_arcsec/pitch` → `attitude_error_arcsec-pitch`.
fn slug(origin: &str) -> String {
    let s: String = origin.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '-' }).collect();
    if s.is_empty() { "plot".into() } else { s }
}

/// Whether the entity holds log10 values (`…/log10_adev_degph/…`, `…_log10_<unit>`).
fn is_log10(entity: &str) -> bool {
    entity.split('/').any(|seg| seg.starts_with("log10_") || seg.contains("_log10_"))
}

/// How a plot's axes read: the data mapped to what the figure shows.
struct Axes {
    log_x: bool,
    log_y: bool,
    /// The time axis in hours (a long run), else in its own seconds.
    hours: bool,
    x_label: String,
    y_label: String,
    /// Each series the sum of those before it and one more (the budget's stacked headline): the
    /// bands between them are filled, each in its series' colour.
    stacked: bool,
}

impl Axes {
    /// A recorded time as the figure's x: 10^t on a log10-τ timeline, hours on a long run.
    fn x_of(&self, t: f64) -> f64 {
        if self.log_x {
            10f64.powf(t)
        } else if self.hours {
            t / 3600.0
        } else {
            t
        }
    }

    /// A recorded value as the figure's y: 10^v where the recording holds log10 values.
    fn y_of(&self, v: f64) -> f64 {
        if self.log_y { 10f64.powf(v) } else { v }
    }
}

fn axes(plot: &Plot) -> Axes {
    let log_x = plot.series.iter().all(|s| s.timeline == super::allan::LOG10_TAU_TIMELINE);
    let log_y = plot.series.iter().all(|s| is_log10(&s.entity));
    let span = plot
        .series
        .iter()
        .flat_map(|s| s.t.iter())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| (a.min(*t), b.max(*t)));
    let hours = !log_x && span.1 - span.0 > 3.0 * 3600.0;
    let x_label = if log_x {
        "τ (s)".into()
    } else if hours {
        "time (h)".into()
    } else {
        "time (s)".into()
    };
    let unit = readable(
        plot.series
            .iter()
            .find_map(|s| super::export::unit_of(&s.entity))
            .or_else(|| super::export::unit_of(&plot.origin))
            .unwrap_or(""),
    );
    let stacked = !log_y && plot.origin.starts_with(super::budget::STACKED);
    Axes { log_x, log_y, hours, x_label, y_label: unit, stacked }
}

/// A unit suffix as a reader writes it: `deg_per_sqrt_h` → `°/√h`, `mps2` → `m/s²`.
fn readable(suffix: &str) -> String {
    let s = suffix
        .replace("_per_", "/")
        .replace("sqrt_", "√")
        .replace("mps2", "m/s²")
        .replace("mps", "m/s")
        .replace("ug", "µg");
    if s.starts_with("arc") { s } else { s.replace("deg", "°") }
}

/// The recording's title of a plot drawn on real logarithmic axes: its log10 words dropped.
/// (`radial position error, log10 of metres (1 = 10 m, …)` → `radial position error (m)`;
/// `log10 ADEV [log10 °/h]` → `ADEV [°/h]`).
fn title_of(plot: &Plot, a: &Axes) -> String {
    if !(a.log_x || a.log_y) {
        return plot.title.clone();
    }
    if let Some(i) = plot.title.find(", log10 of ") {
        return format!("{} ({})", &plot.title[..i], a.y_label);
    }
    // The viewer's note on its time axis (which reads log10 τ as seconds) is not the figure's.
    let title = plot.title.split(" — the axis's").next().unwrap_or(&plot.title);
    title.replace("[log10 ", "[").replace("log10 ", "")
}

/// A series' points as the figure plots them (log10 values undone, hours), in segments split at
/// missing values, long lines reduced to each bucket's extremes.
fn points(s: &PlotSeries, a: &Axes, x_window: Option<(f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for (t, y) in s.t.iter().zip(&s.y) {
        let (x, y) = (a.x_of(*t), a.y_of(*y));
        let inside = x_window.is_none_or(|(lo, hi)| x >= lo && x <= hi);
        if x.is_finite() && y.is_finite() && inside && (!a.log_y || y > 0.0) {
            if let Some(last) = segments.last_mut() {
                last.push((x, y));
            }
        } else if segments.last().is_some_and(|l| !l.is_empty()) {
            segments.push(Vec::new());
        }
    }
    segments.retain(|s| !s.is_empty());
    segments
        .into_iter()
        .map(|seg| if seg.len() > MAX_LINE_POINTS { reduce(&seg, MAX_LINE_POINTS / 4) } else { seg })
        .collect()
}

/// Each of `buckets` consecutive pieces of `seg` as its first, smallest, largest and last point
/// (in time order): the line's envelope survives, a 10⁶-point run stays a small SVG.
fn reduce(seg: &[(f64, f64)], buckets: usize) -> Vec<(f64, f64)> {
    let size = seg.len().div_ceil(buckets);
    let mut out = Vec::with_capacity(4 * buckets);
    for piece in seg.chunks(size) {
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in piece.iter().enumerate() {
            if p.1 < piece[lo].1 {
                lo = i;
            }
            if p.1 > piece[hi].1 {
                hi = i;
            }
        }
        let mut idx = vec![0, lo, hi, piece.len() - 1];
        idx.sort_unstable();
        idx.dedup();
        out.extend(idx.into_iter().map(|i| piece[i]));
    }
    out
}

/// A series' colour on the figure: [`on_white`], with the recording's transparency (a wide
/// translucent line under thin ones stays one).
fn color(s: &PlotSeries) -> RGBAColor {
    on_white([s.color[0], s.color[1], s.color[2]]).mix(f64::from(s.color[3]) / 255.0)
}

/// The parts of the line `seg` inside the box `xr` × `yr` (straight in the axes' own scale, linear
/// or logarithmic), each piece ending where it crosses the box (Liang–Barsky per step).
fn clip(seg: &[(f64, f64)], xr: (f64, f64), yr: (f64, f64), a: &Axes) -> Vec<Vec<(f64, f64)>> {
    let fx = |v: f64| if a.log_x { v.log10() } else { v };
    let fy = |v: f64| if a.log_y { v.log10() } else { v };
    let (gx, gy) = (|v: f64| if a.log_x { 10f64.powf(v) } else { v }, |v: f64| if a.log_y { 10f64.powf(v) } else { v });
    let (x0, x1, y0, y1) = (fx(xr.0), fx(xr.1), fy(yr.0), fy(yr.1));
    let inside = |p: (f64, f64)| p.0 >= x0 && p.0 <= x1 && p.1 >= y0 && p.1 <= y1;
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    let pts: Vec<(f64, f64)> = seg.iter().map(|p| (fx(p.0), fy(p.1))).collect();
    if pts.len() == 1 && inside(pts[0]) {
        return vec![seg.to_vec()];
    }
    for w in pts.windows(2) {
        let (p, q) = (w[0], w[1]);
        let (dx, dy) = (q.0 - p.0, q.1 - p.1);
        let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
        let mut visible = true;
        for (num, den) in [(p.0 - x0, -dx), (x1 - p.0, dx), (p.1 - y0, -dy), (y1 - p.1, dy)] {
            if den == 0.0 {
                if num < 0.0 {
                    visible = false;
                }
            } else {
                let t = num / den;
                if den < 0.0 { t0 = t0.max(t) } else { t1 = t1.min(t) }
            }
        }
        if !visible || t0 > t1 {
            if !current.is_empty() {
                out.push(std::mem::take(&mut current));
            }
            continue;
        }
        let at = |t: f64| (gx(p.0 + t * dx), gy(p.1 + t * dy));
        if current.is_empty() || t0 > 0.0 {
            if !current.is_empty() {
                out.push(std::mem::take(&mut current));
            }
            current.push(at(t0));
        }
        current.push(at(t1));
        if t1 < 1.0 {
            out.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

/// `rgb` darkened (hue kept) until its contrast against white is at least 3:1.
fn on_white(rgb: [u8; 3]) -> RGBColor {
    let mut c = rgb.map(|v| f64::from(v) / 255.0);
    while 1.05 / (super::palette::luminance_of(c) + 0.05) < 3.0 {
        c = c.map(|v| v * 0.95);
    }
    let [r, g, b] = c.map(|v| (v * 255.0).round() as u8);
    RGBColor(r, g, b)
}

/// Tick labels: short, in the plain or scientific form that fits.
fn tick(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        let e = a.log10().floor();
        let m = v / 10f64.powf(e);
        if (m.abs() - 1.0).abs() < 1e-9 {
            format!("{}1e{e}", if v < 0.0 { "-" } else { "" })
        } else {
            format!("{m:.2}e{e}").replace(".00e", "e")
        }
    }
}

/// The value range shown: the layout's, else the data's with a margin (log axes: whole decades
/// around the data).
fn range(data: (f64, f64), layout: Option<(f64, f64)>, log: bool) -> (f64, f64) {
    if let Some((a, b)) = layout.filter(|(a, b)| b > a && (!log || *a > 0.0)) {
        return (a, b);
    }
    let (lo, hi) = if data.0.is_finite() { data } else { (0.0, 1.0) };
    if log {
        // Six decades at most below the top: a series that starts at zero would otherwise
        // stretch the axis to its first rounding-level value.
        let hi = hi.max(f64::MIN_POSITIVE);
        let lo = lo.max(hi * 1e-6);
        return (10f64.powf(lo.log10().floor()), 10f64.powf((hi.log10() - 1e-9).ceil().max(lo.log10().floor() + 1.0)));
    }
    let pad = ((hi - lo) * 0.05).max(1e-12 * lo.abs().max(hi.abs())).max(1e-12);
    (lo - pad, hi + pad)
}

/// Each series with its line as the figure draws it, in pieces.
type Drawn<'a> = Vec<(&'a PlotSeries, Vec<Vec<(f64, f64)>>)>;

/// The plot as an SVG document.
fn svg(plot: &Plot) -> anyhow::Result<String> {
    let a = axes(plot);
    let x_window = plot.time_range.map(|r| (a.x_of(r[0]), a.x_of(r[1])));
    let drawn: Drawn<'_> = plot.series.iter().map(|s| (s, points(s, &a, x_window))).collect();
    let extent = |f: &dyn Fn(&(f64, f64)) -> f64| {
        drawn
            .iter()
            .flat_map(|(_, segs)| segs.iter().flatten())
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
    };
    let xr = range(extent(&|p| p.0), x_window, a.log_x);
    let layout_y = plot.range.map(|r| (a.y_of(r[0]), a.y_of(r[1])));
    let yr = range(extent(&|p| p.1), layout_y, a.log_y);
    // What leaves the visible box is cut at its edge, not drawn along it.
    let drawn: Drawn<'_> =
        drawn.into_iter().map(|(s, segs)| (s, segs.iter().flat_map(|seg| clip(seg, xr, yr, &a)).collect())).collect();
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(draw_error)?;
        let full = title_of(plot, &a);
        let (title, key) = match full.split_once(" — ") {
            Some((t, k)) => (t, Some(k)),
            None => (full.as_str(), None),
        };
        root.draw_text(title, &("sans-serif", 19 * K).into_font().color(&BLACK), (16 * K, 10 * K))
            .map_err(draw_error)?;
        if let Some(k) = key {
            root.draw_text(k, &("sans-serif", 13 * K).into_font().color(&RGBColor(80, 80, 80)), (16 * K, 34 * K))
                .map_err(draw_error)?;
        }
        let body = root.margin(K * if key.is_some() { 54 } else { 38 }, 8 * K, 8 * K, 12 * K);
        let mut legend: Vec<(String, RGBAColor, bool)> = Vec::new();
        for (s, _) in &drawn {
            if !s.name.is_empty() && !legend.iter().any(|(n, ..)| *n == s.name) {
                legend.push((s.name.clone(), color(s), s.line));
            }
        }
        let (chart_area, legend_area) = if legend.len() > 1 {
            let (l, r) = body.split_horizontally(SIZE.0 * 76 / 100);
            (l, Some(r))
        } else {
            (body.clone(), None)
        };
        match (a.log_x, a.log_y) {
            (false, false) => chart(&chart_area, xr.0..xr.1, yr.0..yr.1, &a, &drawn)?,
            (true, false) => chart(&chart_area, (xr.0..xr.1).log_scale(), yr.0..yr.1, &a, &drawn)?,
            (false, true) => chart(&chart_area, xr.0..xr.1, (yr.0..yr.1).log_scale(), &a, &drawn)?,
            (true, true) => chart(&chart_area, (xr.0..xr.1).log_scale(), (yr.0..yr.1).log_scale(), &a, &drawn)?,
        }
        if let Some(area) = legend_area {
            let font = ("sans-serif", 13 * K).into_font().color(&BLACK);
            for (i, (name, color, line)) in legend.iter().enumerate() {
                let y = K * (30 + 20 * i as i32);
                if *line {
                    area.draw(&PathElement::new(vec![(10 * K, y), (34 * K, y)], color.stroke_width(3 * K as u32)))
                        .map_err(draw_error)?;
                } else {
                    area.draw(&Circle::new((22 * K, y), 4 * K, color.filled())).map_err(draw_error)?;
                }
                area.draw_text(name, &font, (42 * K, y - 8 * K)).map_err(draw_error)?;
            }
        }
        root.present().map_err(draw_error)?;
    }
    Ok(out)
}

fn draw_error<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow::anyhow!("drawing a figure: {e:?}")
}

/// The chart of `drawn` in `area` on the axes `x`, `y` (linear or logarithmic).
fn chart<X, Y>(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    x: X,
    y: Y,
    a: &Axes,
    drawn: &Drawn<'_>,
) -> anyhow::Result<()>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut c = ChartBuilder::on(area)
        .x_label_area_size(40 * K)
        .y_label_area_size(70 * K)
        .build_cartesian_2d(x, y)
        .map_err(draw_error)?;
    c.configure_mesh()
        .x_desc(a.x_label.as_str())
        .y_desc(a.y_label.as_str())
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 13 * K))
        .axis_desc_style(("sans-serif", 14 * K))
        .light_line_style(RGBColor(244, 244, 244))
        .bold_line_style(RGBColor(210, 210, 210))
        .draw()
        .map_err(draw_error)?;
    if a.stacked {
        // Each band from the series below (the axis for the first) up to its own line.
        let mut below: Vec<(f64, f64)> = Vec::new();
        for (s, segs) in drawn {
            let upper: Vec<(f64, f64)> = segs.iter().flatten().copied().collect();
            let (Some(first), Some(last)) = (upper.first(), upper.last()) else { continue };
            let mut band = upper.clone();
            if below.is_empty() {
                band.extend([(last.0, 0.0), (first.0, 0.0)]);
            } else {
                band.extend(below.iter().rev().copied());
            }
            c.draw_series(std::iter::once(Polygon::new(band, color(s).mix(0.45).filled()))).map_err(draw_error)?;
            below = upper;
        }
    }
    for (s, segs) in drawn {
        let color = color(s);
        let width = (s.width * K as f32).round().clamp(1.0, 12.0) as u32;
        for seg in segs {
            if s.line && s.markers.as_deref() != Some("down") {
                c.draw_series(LineSeries::new(seg.iter().copied(), color.stroke_width(width))).map_err(draw_error)?;
            }
            match s.markers.as_deref() {
                Some("down") => {
                    c.draw_series(seg.iter().map(|p| {
                        EmptyElement::at(*p)
                            + Polygon::new(vec![(-6 * K, -10 * K), (6 * K, -10 * K), (0, 0)], color.filled())
                    }))
                    .map_err(draw_error)?;
                }
                Some(_) => {
                    c.draw_series(seg.iter().map(|p| Circle::new(*p, 2 * K, color.filled()))).map_err(draw_error)?;
                }
                None => {}
            }
        }
    }
    Ok(())
}

/// The system's fonts, the sans-serif family set to one that is there; a warning if none is.
fn fonts() -> (resvg::usvg::Options<'static>, Option<String>) {
    let mut opt = resvg::usvg::Options::default();
    let db = opt.fontdb_mut();
    db.load_system_fonts();
    let families: Vec<String> = db.faces().flat_map(|f| f.families.iter().map(|(n, _)| n.clone())).collect();
    let warning = if families.is_empty() {
        Some("no system font found: the PNG figures have no text (the SVGs do); install one, e.g. Debian's fonts-dejavu-core".to_owned())
    } else {
        None
    };
    if let Some(f) = ["DejaVu Sans", "Liberation Sans", "Noto Sans", "Arial", "Helvetica"]
        .iter()
        .find(|f| families.iter().any(|n| n == *f))
        .map(|f| (*f).to_owned())
        .or_else(|| families.first().cloned())
    {
        db.set_sans_serif_family(f);
    }
    (opt, warning)
}

/// The SVG rasterised to PNG bytes.
fn png(svg: &str, opt: &resvg::usvg::Options<'_>) -> anyhow::Result<Vec<u8>> {
    let tree = resvg::usvg::Tree::from_str(svg, opt).map_err(|e| anyhow::anyhow!("the figure's SVG: {e}"))?;
    let size = tree.size().to_int_size();
    let mut pixmap =
        resvg::tiny_skia::Pixmap::new(size.width(), size.height()).ok_or_else(|| anyhow::anyhow!("figure size"))?;
    resvg::render(&tree, resvg::tiny_skia::Transform::identity(), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| anyhow::anyhow!("PNG: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn darkened_colours_reach_three_to_one_against_white_and_dark_ones_are_kept() {
        let contrast = |c: RGBColor| 1.05 / (crate::record::palette::luminance([c.0, c.1, c.2]) + 0.05);
        // WCAG 2's definition; white on white is 1:1, black on white 21:1.
        assert!(contrast(on_white([235, 235, 235])) >= 3.0);
        assert!(contrast(on_white([235, 235, 235])) < 3.3, "darkened no further than needed");
        let blue = on_white([40, 60, 200]);
        assert_eq!((blue.0, blue.1, blue.2), (40, 60, 200));
    }

    #[test]
    fn long_lines_keep_their_extremes() {
        let seg: Vec<(f64, f64)> = (0..100_000)
            .map(|i| (f64::from(i), if i == 77_777 { 50.0 } else { (f64::from(i) * 0.01).sin() }))
            .collect();
        let r = reduce(&seg, 1000);
        assert!(r.len() <= 4000);
        assert!(r.iter().any(|p| p.1 == 50.0), "the spike survives");
        assert!(r.windows(2).all(|w| w[0].0 < w[1].0), "in time order");
    }

    #[test]
    fn lines_are_cut_at_the_box_not_drawn_along_it() {
        let a = Axes {
            log_x: false,
            log_y: false,
            hours: false,
            x_label: String::new(),
            y_label: String::new(),
            stacked: false,
        };
        // Up from inside through the top edge, back down: two pieces ending and starting on y = 1.
        let pieces = clip(&[(0.0, 0.0), (1.0, 2.0), (2.0, 0.0)], (0.0, 2.0), (-1.0, 1.0), &a);
        assert_eq!(pieces, vec![vec![(0.0, 0.0), (0.5, 1.0)], vec![(1.5, 1.0), (2.0, 0.0)]]);
        // On a log axis the crossing is found in log10: 1 → 100 crosses 10 half way.
        let l = Axes { log_y: true, ..a };
        let pieces = clip(&[(0.0, 1.0), (1.0, 100.0)], (0.0, 1.0), (0.1, 10.0), &l);
        assert!((pieces[0][1].0 - 0.5).abs() < 1e-12 && (pieces[0][1].1 - 10.0).abs() < 1e-9);
    }

    #[test]
    fn units_read_as_written() {
        assert_eq!(readable("deg_per_h"), "°/h");
        assert_eq!(readable("deg_per_sqrt_h"), "°/√h");
        assert_eq!(readable("arcsec"), "arcsec");
        assert_eq!(readable("mps2"), "m/s²");
    }

    #[test]
    fn log_ranges_are_whole_decades_around_the_data() {
        assert_eq!(range((0.02, 3.0), None, true), (0.01, 10.0));
        assert_eq!(range((1.0, 10.0), None, true), (1.0, 10.0));
        assert_eq!(range((0.0, 1.0), Some((-2.0, 2.0)), false), (-2.0, 2.0));
    }
}
