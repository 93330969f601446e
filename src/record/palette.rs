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
    /// In the order of `Algorithm::ALL` (single-sample, two-sample, two-sample-p1, -p2, three-sample).
    pub const ALGORITHMS: [[u8; 3]; 5] = [[250, 200, 60], [230, 76, 60], [46, 170, 90], [70, 130, 240], [200, 90, 230]];

    /// The name of that colour, for plot titles that stand in for a legend.
    pub fn algorithm_colour_name(name: &str) -> &'static str {
        const NAMES: [&str; 5] = ["yellow", "red", "green", "blue", "purple"];
        crate::ins::coning::Algorithm::ALL.iter().position(|a| a.name() == name).map_or("grey", |k| NAMES[k])
    }

    /// The colour of the coning algorithm named `name`, the same in every recording.
    pub fn algorithm(name: &str) -> [u8; 3] {
        crate::ins::coning::Algorithm::ALL.iter().position(|a| a.name() == name).map_or([200, 200, 200], |k| ALGORITHMS[k])
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
    let at = |k: f64, x: [f64; 3]| x.map(|v| if k <= 1.0 { v * k } else { v + (255.0 - v) * (k - 1.0) }.round().clamp(0.0, 255.0) as u8);
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
}
