//! The 3D scene of a strapdown replay: no table, the IMU's axes — which are the body's — turning
//! with the INS's attitude, the reference's beside them in grey when the log has one.

use rerun::RecordingStreamResult;

use super::palette::{colors, rgb, rgba};
use super::{Stream, to_rerun_quaternion};
use crate::ins::pipeline::InsView;

/// The INS's body axes.
pub(crate) const INS_BODY: &str = "world/ins_body";
/// The reference's body axes (with a reference only).
pub(crate) const REFERENCE_BODY: &str = "world/reference_body";

/// The body frames of the recorded scene rows.
pub(crate) struct BodyScene {
    ins: Vec<rerun::Quaternion>,
    /// None without a reference.
    reference: Option<Vec<rerun::Quaternion>>,
}

impl BodyScene {
    pub(crate) fn new(reference: bool) -> Self {
        Self { ins: Vec::new(), reference: reference.then(Vec::new) }
    }

    /// One scene row: the INS's attitude and the reference's at the instant it stands for.
    pub(crate) fn push(&mut self, view: Option<&InsView>) {
        // FRAME: a strapdown IMU's axes are the body's (b_from_s = identity), so C_s^n is C_b^n.
        let ins = view.map_or_else(nalgebra::UnitQuaternion::identity, |v| *v.imu_ins.quaternion());
        self.ins.push(to_rerun_quaternion(&ins));
        if let Some(r) = self.reference.as_mut() {
            let truth = view.and_then(|v| v.imu_true).map_or(ins, |t| *t.quaternion());
            r.push(to_rerun_quaternion(&truth));
        }
    }

    /// Sends the buffered rows at `times`; returns the chunks sent.
    pub(crate) fn flush(&mut self, stream: &Stream, times: &[f64]) -> RecordingStreamResult<usize> {
        let reference = self.reference.as_mut().map(std::mem::take);
        for (path, q) in [(INS_BODY, Some(std::mem::take(&mut self.ins))), (REFERENCE_BODY, reference)] {
            let Some(q) = q.filter(|q| !q.is_empty()) else { continue };
            stream.rec().send_columns(
                path,
                stream.time_columns(times),
                rerun::Transform3D::update_fields().with_many_quaternion(q).columns_of_unit_batches()?,
            )?;
        }
        Ok(1)
    }

    /// The body's static parts: an IMU case and its three axes (x right, y forward, z up), and the
    /// reference's axes in grey.
    pub(crate) fn log_static(&self, stream: &Stream) -> RecordingStreamResult<()> {
        let rec = stream.rec();
        rec.log_static(INS_BODY, &rerun::Transform3D::IDENTITY)?;
        rec.log_static(
            format!("{INS_BODY}/case"),
            &rerun::Boxes3D::from_half_sizes([[0.3, 0.45, 0.15]])
                .with_colors([rgba([200, 200, 210], 90)])
                .with_fill_mode(rerun::FillMode::Solid),
        )?;
        let tips = [[0.8, 0.0, 0.0], [0.0, 1.1, 0.0], [0.0, 0.0, 0.7]];
        rec.log_static(
            format!("{INS_BODY}/axes"),
            &rerun::Arrows3D::from_vectors(tips).with_colors(colors::SENSOR.map(rgb)).with_radii([0.02]),
        )?;
        // Labels beyond the tips (an arrow's own label sits at its middle, inside the case).
        let at = tips.map(|[x, y, z]| [x * 1.12, y * 1.1, z * 1.15]);
        let names = ["x right", "y forward", "z up"];
        rec.log_static(
            format!("{INS_BODY}/axes/labels"),
            &rerun::Points3D::new(at)
                .with_labels(names)
                .with_colors(colors::SENSOR.map(super::palette::label))
                .with_radii([0.002]),
        )?;
        if self.reference.is_some() {
            rec.log_static(REFERENCE_BODY, &rerun::Transform3D::IDENTITY)?;
            let longer = tips.map(|[x, y, z]| [x * 1.3, y * 1.3, z * 1.3]);
            rec.log_static(
                format!("{REFERENCE_BODY}/axes"),
                &rerun::Arrows3D::from_vectors(longer).with_colors([rgba([170, 170, 170], 200); 3]).with_radii([0.008]),
            )?;
            rec.log_static(
                format!("{REFERENCE_BODY}/axes/label"),
                &rerun::Points3D::new([[0.0, 1.3 * 1.1 * 1.1, 0.08]])
                    .with_labels(["reference"])
                    .with_colors([super::palette::label([190, 190, 190])])
                    .with_radii([0.002]),
            )?;
        }
        Ok(())
    }
}
