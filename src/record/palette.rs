//! One palette for every recording, and the small conversions Rerun's types need.

use nalgebra::Vector3;

/// Display colours, one place.
pub(crate) mod colors {

    pub const VARIANT: [[u8; 3]; 3] = [[230, 76, 60], [46, 170, 90], [70, 130, 240]];
    pub const AXES: [[u8; 3]; 3] = [[240, 160, 40], [200, 90, 230], [60, 200, 200]];
    /// The names of [`AXES`] (the key of the swing cones says which cone is which).
    pub const AXIS_COLOR_NAMES: [&str; 3] = ["orange", "purple", "cyan"];
    pub const EULER: [[u8; 3]; 3] = [[230, 90, 90], [90, 200, 90], [90, 140, 240]];
    pub const NOMINAL: [u8; 3] = [150, 150, 150];
    /// Event markers on the plots (position fixes, moves, live reloads): a grey that reads on the
    /// native viewer's dark theme and on the browser's light one.
    pub const EVENT: [u8; 3] = [160, 160, 160];
    pub const SENSOR: [[u8; 3]; 3] = [[235, 50, 50], [50, 200, 50], [60, 110, 255]];
    /// Up to nine lines sharing a plot, with the names a key gives them: any two at least 24 apart
    /// in CIEDE2000 (orange and yellow, the closest pair of the colours before, were 13; 2.3 is a
    /// just-noticeable difference). The first three are [`SENSOR`]'s x, y, z.
    pub const DISTINCT: [(&str, [u8; 3]); 9] = [
        ("red", SENSOR[0]),
        ("green", SENSOR[1]),
        ("blue", SENSOR[2]),
        ("orange", [255, 150, 30]),
        ("yellow", [240, 230, 60]),
        ("cyan", [40, 220, 230]),
        ("magenta", [230, 70, 230]),
        ("pink", [255, 170, 200]),
        ("white", [235, 235, 235]),
    ];
    /// In the order of `Algorithm::ALL` (single-sample, two-sample, two-sample-p1, -p2, three-sample).
    pub const ALGORITHMS: [[u8; 3]; 5] = [[250, 200, 60], [230, 76, 60], [46, 170, 90], [70, 130, 240], [200, 90, 230]];

    /// The name of that colour, for plot titles that stand in for a legend.
    pub fn algorithm_colour_name(name: &str) -> &'static str {
        const NAMES: [&str; 5] = ["yellow", "red", "green", "blue", "purple"];
        crate::ins::coning::Algorithm::ALL.iter().position(|a| a.name() == name).map_or("grey", |k| NAMES[k])
    }

    /// The colour of the coning algorithm named `name`, the same in every recording.
    pub fn algorithm(name: &str) -> [u8; 3] {
        crate::ins::coning::Algorithm::ALL
            .iter()
            .position(|a| a.name() == name)
            .map_or([200, 200, 200], |k| ALGORITHMS[k])
    }
}

/// A point or vector as Rerun's f32 triple.
pub(crate) fn p3(v: Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

pub(crate) fn rgb(c: [u8; 3]) -> rerun::Color {
    rerun::Color::from_rgb(c[0], c[1], c[2])
}

pub(crate) fn rgba(c: [u8; 3], a: u8) -> rerun::Color {
    rerun::Color::from_unmultiplied_rgba(c[0], c[1], c[2], a)
}

pub(crate) fn albedo(c: [u8; 3], a: u8) -> rerun::datatypes::Rgba32 {
    rerun::datatypes::Rgba32::from_unmultiplied_rgba(c[0], c[1], c[2], a)
}

/// WCAG 2 relative luminance of an sRGB colour.
pub(crate) fn luminance(c: [u8; 3]) -> f64 {
    luminance_of(c.map(|v| f64::from(v) / 255.0))
}

/// WCAG 2 relative luminance of an sRGB colour with channels in [0, 1].
pub(crate) fn luminance_of(c: [f64; 3]) -> f64 {
    let lin = |v: f64| if v <= 0.040_45 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) };
    0.2126 * lin(c[0]) + 0.7152 * lin(c[1]) + 0.0722 * lin(c[2])
}

/// The luminance a 3D label's text is drawn at: the viewer draws a label in its colour on a
/// translucent box of the theme's (measured in both themes on the scene's floor: luminance 0.70 in
/// the light theme, 0.03 in the dark); the contrast against both is largest, 3.0:1 each, where
/// (0.70 + 0.05)/(L + 0.05) = (L + 0.05)/(0.03 + 0.05), L ≈ 0.195.
const LABEL_LUMINANCE: f64 = 0.195;

/// A 3D label's colour: `c`'s hue, half its saturation (a label must not be its arrow's colour),
/// at [`LABEL_LUMINANCE`]: legible on the light theme and on the dark one.
pub(crate) fn label(c: [u8; 3]) -> rerun::Color {
    let grey = (f64::from(c[0]) + f64::from(c[1]) + f64::from(c[2])) / 3.0;
    let mut x = c.map(|v| (f64::from(v) + grey) / 2.0);
    // Bisection on a scale factor (towards black below 1, towards white above).
    let at = |k: f64, x: [f64; 3]| {
        x.map(|v| if k <= 1.0 { v * k } else { v + (255.0 - v) * (k - 1.0) }.round().clamp(0.0, 255.0) as u8)
    };
    let (mut lo, mut hi) = (0.0, 2.0);
    for _ in 0..40 {
        let k = (lo + hi) / 2.0;
        if luminance(at(k, x)) < LABEL_LUMINANCE { lo = k } else { hi = k }
    }
    x = at(hi, x).map(f64::from);
    rgb(x.map(|v| v as u8))
}

#[cfg(test)]
mod tests {
    #[test]
    fn labels_sit_at_three_to_one_against_both_themes_boxes() {
        // Box luminances measured on web-viewer screenshots (see LABEL_LUMINANCE).
        let (light, dark) = (0.70, 0.03);
        for c in [[235, 235, 235], [235, 50, 50], [60, 110, 255], [250, 200, 60], [20, 20, 20]] {
            let l = super::label(c).to_array();
            let y = super::luminance([l[0], l[1], l[2]]);
            let (on_light, on_dark) = ((light + 0.05) / (y + 0.05), (y + 0.05) / (dark + 0.05));
            assert!(on_light > 2.9 && on_dark > 2.9, "{c:?} -> {l:?}: {on_light:.2}:1 light, {on_dark:.2}:1 dark");
        }
    }

    /// CIELAB (D65) of an sRGB colour.
    fn lab(c: [u8; 3]) -> [f64; 3] {
        let lin = |v: u8| {
            let v = f64::from(v) / 255.0;
            if v <= 0.040_45 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
        };
        let [r, g, b] = c.map(lin);
        let (x, y, z) = (
            0.4124 * r + 0.3576 * g + 0.1805 * b,
            0.2126 * r + 0.7152 * g + 0.0722 * b,
            0.0193 * r + 0.1192 * g + 0.9505 * b,
        );
        let f = |t: f64| if t > 216.0 / 24389.0 { t.cbrt() } else { (24389.0 / 27.0 * t + 16.0) / 116.0 };
        let (fx, fy, fz) = (f(x / 0.950_47), f(y), f(z / 1.088_83));
        [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
    }

    /// CIEDE2000 colour difference (Sharma, Wu and Dalal 2005, eqs. 1-17).
    fn ciede2000([l1, a1, b1]: [f64; 3], [l2, a2, b2]: [f64; 3]) -> f64 {
        let (c1, c2) = (a1.hypot(b1), a2.hypot(b2));
        let c7 = ((c1 + c2) / 2.0).powi(7);
        let g = 0.5 * (1.0 - (c7 / (c7 + 25f64.powi(7))).sqrt());
        let (a1, a2) = ((1.0 + g) * a1, (1.0 + g) * a2);
        let (c1, c2) = (a1.hypot(b1), a2.hypot(b2));
        let hue = |b: f64, a: f64| if a == 0.0 && b == 0.0 { 0.0 } else { b.atan2(a).to_degrees().rem_euclid(360.0) };
        let (h1, h2) = (hue(b1, a1), hue(b2, a2));
        let dh = if c1 * c2 == 0.0 {
            0.0
        } else if (h2 - h1).abs() <= 180.0 {
            h2 - h1
        } else if h2 <= h1 {
            h2 - h1 + 360.0
        } else {
            h2 - h1 - 360.0
        };
        let (dl, dc, dhh) = (l2 - l1, c2 - c1, 2.0 * (c1 * c2).sqrt() * (dh / 2.0).to_radians().sin());
        let (l, c) = ((l1 + l2) / 2.0, (c1 + c2) / 2.0);
        let h = if c1 * c2 == 0.0 {
            h1 + h2
        } else if (h1 - h2).abs() <= 180.0 {
            (h1 + h2) / 2.0
        } else if h1 + h2 < 360.0 {
            (h1 + h2 + 360.0) / 2.0
        } else {
            (h1 + h2 - 360.0) / 2.0
        };
        let cos = |deg: f64| deg.to_radians().cos();
        let t =
            1.0 - 0.17 * cos(h - 30.0) + 0.24 * cos(2.0 * h) + 0.32 * cos(3.0 * h + 6.0) - 0.20 * cos(4.0 * h - 63.0);
        let rc = 2.0 * (c.powi(7) / (c.powi(7) + 25f64.powi(7))).sqrt();
        let rt = -(2.0 * 30.0 * (-((h - 275.0) / 25.0).powi(2)).exp()).to_radians().sin() * rc;
        let sl = 1.0 + 0.015 * (l - 50.0).powi(2) / (20.0 + (l - 50.0).powi(2)).sqrt();
        let (sc, sh) = (1.0 + 0.045 * c, 1.0 + 0.015 * c * t);
        ((dl / sl).powi(2) + (dc / sc).powi(2) + (dhh / sh).powi(2) + rt * (dc / sc) * (dhh / sh)).sqrt()
    }

    #[test]
    fn lines_sharing_a_plot_are_clearly_distinct() {
        // Sharma, Wu and Dalal 2005, Table 1, pairs 1 and 17: the formula as published.
        assert!((ciede2000([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485]) - 2.0425).abs() < 1e-4);
        assert!((ciede2000([50.0, 2.5, 0.0], [73.0, 25.0, -18.0]) - 27.1492).abs() < 1e-4);
        // 2.3 is a just-noticeable difference; the old selfcal palette's orange and yellow were 13.
        let d = super::colors::DISTINCT;
        for (i, (n1, c1)) in d.iter().enumerate() {
            for (n2, c2) in &d[i + 1..] {
                let de = ciede2000(lab(*c1), lab(*c2));
                assert!(de >= 24.0, "{n1} and {n2}: ΔE00 {de:.1}");
            }
        }
    }
}
