//! Teaching coning in 3D: beside the table, the body z axis tracing its cone, magnified so that a
//! 1° cone reads, with a fading trail of its last positions. Only for pure coning (the classical
//! test, `[vehicle] coning_*`): there the cone is the whole motion.

use std::collections::VecDeque;

use nalgebra::{UnitQuaternion, Vector3};
use rerun::{RecordingStream, RecordingStreamResult, TimeColumn};

use super::palette::{albedo, rgb, rgba};
use super::{to_rerun_quaternion, TIMELINE};
use crate::math::frames::{Rot, B, N};
use crate::math::units::{fmt_angle, RAD_PER_DEG};

/// Where the gizmo stands: beside the table, towards the default camera.
const OFFSET: [f32; 3] = [1.0, -0.9, 0.5];
/// The magnified cone's half-angle, rad: wide enough to see, narrow enough to read as a cone.
const DRAWN_HALF_ANGLE_RAD: f64 = 20.0 * RAD_PER_DEG;
/// The axis and its trail: the newest position and this many older ones, fading.
const TRAIL: usize = 3;
/// Half length of the drawn axis.
const HALF: f64 = 0.6;

/// The gizmo's state: the magnification and the buffered frames.
pub(crate) struct ConeGizmo {
    /// Magnification of the tilt.
    gain: f64,
    /// The last `TRAIL` rotations, newest last.
    history: VecDeque<rerun::Quaternion>,
    /// Per trail position, the rotation per buffered scene frame.
    columns: Vec<Vec<rerun::Quaternion>>,
}

fn path(i: usize) -> String {
    format!("world/cone/axis_{i}")
}

impl ConeGizmo {
    /// The gizmo for a cone of half-angle `alpha_rad` (> 0); logs its fixed parts.
    pub(crate) fn new(rec: &RecordingStream, alpha_rad: f64) -> RecordingStreamResult<Self> {
        let gain = (DRAWN_HALF_ANGLE_RAD / alpha_rad).max(1.0).round();
        rec.log_static("world/cone", &rerun::Transform3D::from_translation(OFFSET))?;
        let (mesh, rims) = super::scene::cone(Vector3::z(), Vector3::x(), Vector3::y(), (alpha_rad * gain).min(1.4), HALF);
        let color = [120, 200, 255];
        rec.log_static("world/cone/surface", &rerun::Mesh3D::new(mesh.0).with_triangle_indices(mesh.1).with_albedo_factor(albedo(color, 35)))?;
        rec.log_static("world/cone/rims", &rerun::LineStrips3D::new(rims).with_colors([rgba(color, 160)]).with_radii([0.004]))?;
        rec.log_static("world/cone/nominal", &rerun::LineStrips3D::new([[[0.0, 0.0, -0.7f32], [0.0, 0.0, 0.7]]]).with_colors([rgb([150, 150, 150])]).with_radii([0.005]))?;
        let label = format!("body z on its {} cone, tilt ×{gain}", fmt_angle(alpha_rad));
        // Above the cone (below it, it sat on the table's deck, where no colour reads).
        rec.log_static("world/cone/label", &rerun::Points3D::new([[0.0f32, 0.0, 0.85]]).with_labels([label]).with_radii([0.002]).with_colors([super::palette::label(color)]))?;
        for i in 0..TRAIL {
            let alpha = (230.0 * (1.0 - i as f64 / TRAIL as f64)) as u8;
            rec.log_static(
                format!("{}/line", path(i)),
                &rerun::LineStrips3D::new([[[0.0, 0.0, -HALF as f32 * 1.1], [0.0, 0.0, HALF as f32 * 1.1]]])
                    .with_colors([rgba([255, 230, 120], alpha)])
                    .with_radii([if i == 0 { 0.012 } else { 0.007 }]),
            )?;
        }
        Ok(Self { gain, history: VecDeque::with_capacity(TRAIL), columns: vec![Vec::new(); TRAIL] })
    }

    /// Buffers one scene frame of the body attitude `n_from_b`.
    pub(crate) fn push(&mut self, n_from_b: &Rot<N, B>) {
        // The body z axis in the navigation frame, its tilt from Up magnified about the same azimuth.
        let z: Vector3<f64> = n_from_b.quaternion() * Vector3::z();
        let tilt = z.z.clamp(-1.0, 1.0).acos();
        let about = Vector3::z().cross(&z);
        let q = match nalgebra::Unit::try_new(about, 1e-15) {
            Some(axis) => UnitQuaternion::from_axis_angle(&axis, (tilt * self.gain).min(1.4)),
            None => UnitQuaternion::identity(),
        };
        if self.history.len() == TRAIL {
            self.history.pop_front();
        }
        self.history.push_back(to_rerun_quaternion(&q));
        let newest = self.history.len() - 1;
        for (i, col) in self.columns.iter_mut().enumerate() {
            col.push(self.history[newest.saturating_sub(i)]);
        }
    }

    /// Sends the buffered frames at `times`.
    pub(crate) fn flush(&mut self, rec: &RecordingStream, times: &[f64]) -> RecordingStreamResult<()> {
        for (i, col) in self.columns.iter_mut().enumerate() {
            let q = std::mem::take(col);
            let time = TimeColumn::new_duration_secs(TIMELINE, times.iter().copied());
            rec.send_columns(path(i), [time], rerun::Transform3D::update_fields().with_many_quaternion(q).columns_of_unit_batches()?)?;
        }
        Ok(())
    }
}
