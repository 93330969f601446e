//! Teaching coning in 3D: beside the table, the body z axis tracing its cone, magnified so that a
//! 1° cone reads. Only for pure coning (the classical test, `[vehicle] coning_*`): there the cone
//! is the whole motion.

use nalgebra::{UnitQuaternion, Vector3};
use rerun::{RecordingStream, RecordingStreamResult};

use super::TIMELINE;
use super::palette::{albedo, rgb, rgba};
use crate::math::frames::{B, N, Rot};
use crate::math::units::{RAD_PER_DEG, fmt_angle};

/// Where the gizmo stands: beside the table, towards the default camera.
const OFFSET: [f32; 3] = [1.0, -0.9, 0.5];
/// The magnified cone's half-angle, rad: wide enough to see, narrow enough to read as a cone.
const DRAWN_HALF_ANGLE_RAD: f64 = 20.0 * RAD_PER_DEG;
/// Half length of the drawn axis.
const HALF: f64 = 0.6;

/// The gizmo's state: the magnification and the buffered frames.
pub(crate) struct ConeGizmo {
    /// Magnification of the tilt.
    gain: f64,
    /// Per buffered scene frame, the drawn axis's attitude (the tilt magnified).
    frames: Vec<rerun::Quaternion>,
}

/// The drawn axis: a fixed line along z, turned by a rotation on the timeline (one quaternion a
/// frame; a trail of earlier positions doubled the scene's size per hour at 25 frames a second,
/// and the drawn cone shows the path).
const AXIS_PATH: &str = "world/cone/axis";

impl ConeGizmo {
    /// The gizmo for a cone of half-angle `alpha_rad` (> 0); logs its fixed parts (in live mode,
    /// those that depend on the cone at `at_s` on the timeline: a change of the cone redraws them).
    pub(crate) fn new(rec: &RecordingStream, alpha_rad: f64, at_s: Option<f64>) -> RecordingStreamResult<Self> {
        let gain = Self::gain_for(alpha_rad);
        rec.log_static("world/cone", &rerun::Transform3D::from_translation(OFFSET))?;
        rec.log_static(
            "world/cone/nominal",
            &rerun::LineStrips3D::new([[[0.0, 0.0, -0.7f32], [0.0, 0.0, 0.7]]])
                .with_colors([rgb([150, 150, 150])])
                .with_radii([0.005]),
        )?;
        let end = (HALF * 1.1) as f32;
        rec.log_static(
            format!("{AXIS_PATH}/line"),
            &rerun::LineStrips3D::new([[[0.0, 0.0, -end], [0.0, 0.0, end]]])
                .with_colors([rgba([255, 230, 120], 230)])
                .with_radii([0.012f32]),
        )?;
        let me = Self { gain, frames: Vec::new() };
        me.log_cone(rec, alpha_rad, at_s)?;
        Ok(me)
    }

    fn gain_for(alpha_rad: f64) -> f64 {
        (DRAWN_HALF_ANGLE_RAD / alpha_rad).max(1.0).round()
    }

    /// The drawn cone and its label for half-angle `alpha_rad`: static, or in live mode at `at_s`.
    fn log_cone(&self, rec: &RecordingStream, alpha_rad: f64, at_s: Option<f64>) -> RecordingStreamResult<()> {
        let (mesh, rims) =
            super::scene::cone(Vector3::z(), Vector3::x(), Vector3::y(), (alpha_rad * self.gain).min(1.4), HALF);
        let color = [120, 200, 255];
        let label = if alpha_rad > 0.0 {
            format!("body z on its {} cone, tilt ×{}", fmt_angle(alpha_rad), self.gain)
        } else {
            "body z: no cone (half-angle 0)".to_owned()
        };
        let surface = rerun::Mesh3D::new(mesh.0).with_triangle_indices(mesh.1).with_albedo_factor(albedo(color, 35));
        let rims = rerun::LineStrips3D::new(rims).with_colors([rgba(color, 160)]).with_radii([0.004]);
        // Above the cone (below it, it sat on the table's deck, where no colour reads).
        let label = rerun::Points3D::new([[0.0f32, 0.0, 0.85]])
            .with_labels([label])
            .with_radii([0.002])
            .with_colors([super::palette::label(color)]);
        match at_s {
            None => {
                rec.log_static("world/cone/surface", &surface)?;
                rec.log_static("world/cone/rims", &rims)?;
                rec.log_static("world/cone/label", &label)
            }
            Some(t) => {
                rec.set_duration_secs(TIMELINE, t);
                rec.log("world/cone/surface", &surface)?;
                rec.log("world/cone/rims", &rims)?;
                rec.log("world/cone/label", &label)
            }
        }
    }

    /// Live mode: the cone is now of half-angle `alpha_rad` from `t_s` on (its magnification
    /// follows, as a new gizmo's would).
    pub(crate) fn reshape(&mut self, rec: &RecordingStream, alpha_rad: f64, t_s: f64) -> RecordingStreamResult<()> {
        if alpha_rad > 0.0 {
            self.gain = Self::gain_for(alpha_rad);
        }
        self.log_cone(rec, alpha_rad, Some(t_s))
    }

    /// Buffers one scene frame of the body attitude `n_from_b`.
    pub(crate) fn push(&mut self, n_from_b: &Rot<N, B>) {
        // The body z axis in the navigation frame, its tilt from Up magnified about the same azimuth.
        let z: Vector3<f64> = n_from_b.quaternion() * Vector3::z();
        let tilt = z.z.clamp(-1.0, 1.0).acos();
        let about = Vector3::z().cross(&z);
        let drawn = match nalgebra::Unit::try_new(about, 1e-15) {
            Some(axis) => UnitQuaternion::from_axis_angle(&axis, (tilt * self.gain).min(1.4)),
            None => UnitQuaternion::identity(),
        };
        self.frames.push(super::to_rerun_quaternion(&drawn));
    }

    /// Sends the buffered frames at `times`.
    pub(crate) fn flush(&mut self, stream: &super::Stream, times: &[f64]) -> RecordingStreamResult<()> {
        let frames = std::mem::take(&mut self.frames);
        stream.rec().send_columns(
            AXIS_PATH,
            stream.time_columns(times),
            rerun::Transform3D::update_fields().with_many_quaternion(frames).columns_of_unit_batches()?,
        )?;
        Ok(())
    }
}
