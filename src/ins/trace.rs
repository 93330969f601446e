//! The sampled navigation errors of a run (position and heading), as commands collect them for
//! tables and recordings.

/// One sample of a navigation run: position and heading errors.
#[derive(Debug, Clone, Copy, Default)]
pub struct NavSample {
    /// Time, s.
    pub t_s: f64,
    /// Position error east, north, radial, m.
    pub position_m: [f64; 3],
    /// Heading error, arcsec.
    pub heading_arcsec: f64,
}

/// The sampled navigation errors of one run.
#[derive(Debug, Clone, Default)]
pub struct NavTrace {
    /// Label.
    pub label: String,
    /// Samples every `sample_s`.
    pub samples: Vec<NavSample>,
}

impl NavTrace {
    /// Largest radial error, m.
    #[must_use]
    pub fn peak_radial_m(&self) -> f64 {
        self.samples.iter().map(|s| s.position_m[2]).fold(0.0, f64::max)
    }

    /// Largest |heading error|, arcsec.
    #[must_use]
    pub fn peak_heading_arcsec(&self) -> f64 {
        self.samples.iter().map(|s| s.heading_arcsec.abs()).fold(0.0, f64::max)
    }
}
