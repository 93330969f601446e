//! One palette for every recording, and the small conversions Rerun's types need.

use nalgebra::Vector3;

/// Display colours, one place.
pub(crate) mod colors {

    pub const VARIANT: [[u8; 3]; 3] = [[230, 76, 60], [46, 170, 90], [70, 130, 240]];
    pub const AXES: [[u8; 3]; 3] = [[240, 160, 40], [200, 90, 230], [60, 200, 200]];
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
