//! The table's view in the 3D scene: the gimbal chain as an entity tree of transforms, rings and
//! axes, the exaggerated error geometry (swing cones, non-orthogonality and installation wedges)
//! with their key, the vehicle's deck.

use nalgebra::{UnitQuaternion, Vector3};
use rerun::RecordingStreamResult;

use super::palette::{albedo, colors, p3, rgb, rgba};
use super::{Stream, drawing_factors, to_rerun_quaternion};
use crate::math::units::{ARCSEC_PER_RAD, DEG_PER_RAD, fmt_angle};
use crate::model::gimbal::{AxisGeometry, Chain, ClassFactors, ErrorRotations, TableErrors};
use crate::scenario::Params;
use crate::sim::StepOutput;

/// Entity paths of the chain.
#[derive(Debug, Clone)]
pub(crate) struct ChainPaths {
    pub(crate) vehicle: String,
    pub(crate) base: String,
    /// `<axis>_mount` per axis.
    pub(crate) mounts: Vec<String>,
    /// `<axis>` per axis (the rotor).
    pub(crate) gimbals: Vec<String>,
    pub(crate) imu: String,
}

impl ChainPaths {
    pub(crate) fn new(names: &[String]) -> Self {
        let vehicle = "world/vehicle".to_owned();
        let base = format!("{vehicle}/base");
        let mut parent = base.clone();
        let (mut mounts, mut gimbals) = (Vec::new(), Vec::new());
        for name in names {
            let mount = format!("{parent}/{name}_mount");
            let gimbal = format!("{mount}/{name}");
            mounts.push(mount);
            gimbals.push(gimbal.clone());
            parent = gimbal;
        }
        let imu = format!("{parent}/imu");
        Self { vehicle, base, mounts, gimbals, imu }
    }
}

/// The table in the 3D scene: the gimbal chain as an entity tree of transforms (moving with the
/// gimbal angles), its rings and axes, the vehicle's deck, the IMU, and the exaggerated error
/// geometry (swing cones, non-orthogonality and installation wedges) with their key. It owns
/// `world/vehicle/…` and `world/key`.
pub(crate) struct TableScene {
    chain: Chain,
    /// The true errors exaggerated for drawing.
    drawing: ErrorRotations,
    /// The drawing factor of each error class ([`drawing_factors`]).
    pub(crate) factors: ClassFactors,
    pub(crate) paths: ChainPaths,
    axis_names: Vec<String>,
    /// Per buffered scene frame: the vehicle's attitude, and each gimbal's rotation.
    vehicle: Vec<rerun::Quaternion>,
    gimbals: Vec<Vec<rerun::Quaternion>>,
    /// The last frame sent of each moving transform (vehicle, then gimbals): a transform that has
    /// not moved since is not sent again (a vehicle at rest, a gimbal the scheme holds still).
    last_motion: Vec<Option<rerun::Quaternion>>,
}

impl TableScene {
    /// The table of `params`.
    pub(crate) fn new(params: &Params) -> Self {
        let chain = params.table.chain.clone();
        let factors = drawing_factors(&params.table.truth, params.recording.exaggeration);
        let drawing = chain.error_rotations(&params.table.truth.exaggerated(&factors));
        let axis_names: Vec<String> = chain.axes().iter().map(|a| a.name.clone()).collect();
        let n = axis_names.len();
        Self {
            paths: ChainPaths::new(&axis_names),
            chain,
            drawing,
            factors,
            axis_names,
            vehicle: Vec::new(),
            gimbals: vec![Vec::new(); n],
            last_motion: vec![None; 1 + n],
        }
    }

    /// New true errors (a live reload): the drawing follows them; true if a drawing factor changed.
    pub(crate) fn set_truth(&mut self, truth: &TableErrors, exaggeration: f64) -> bool {
        let factors = drawing_factors(truth, exaggeration);
        let changed = factors != self.factors;
        self.factors = factors;
        self.drawing = self.chain.error_rotations(&truth.exaggerated(&self.factors));
        changed
    }

    /// Buffers one scene frame: the vehicle's attitude and the gimbals' rotations.
    pub(crate) fn push(&mut self, out: &StepOutput) {
        let links = self.chain.link_rotations(&self.drawing, &out.gimbal_rad);
        self.vehicle.push(to_rerun_quaternion(out.n_from_b.quaternion()));
        for (k, col) in self.gimbals.iter_mut().enumerate() {
            col.push(to_rerun_quaternion(&links.gimbal[k]));
        }
    }

    /// Sends the buffered frames at `times`; returns the chunks sent. A transform that has not
    /// moved since the frame last sent of it is not sent again.
    pub(crate) fn flush(&mut self, stream: &Stream, times: &[f64]) -> RecordingStreamResult<usize> {
        let mut sent = 0;
        let motion = std::iter::once((self.paths.vehicle.as_str(), std::mem::take(&mut self.vehicle)))
            .chain(self.paths.gimbals.iter().map(String::as_str).zip(self.gimbals.iter_mut().map(std::mem::take)));
        for ((path, q), last) in motion.zip(self.last_motion.iter_mut()) {
            let Some(newest) = q.last().copied() else { continue };
            if q.iter().all(|x| Some(*x) == *last) {
                continue;
            }
            *last = Some(newest);
            stream.rec().send_columns(
                path,
                stream.time_columns(times),
                rerun::Transform3D::update_fields().with_many_quaternion(q).columns_of_unit_batches()?,
            )?;
            sent += 1;
        }
        Ok(sent)
    }

    /// Logs what never changes during a run: the deck, the rings and axes, the IMU.
    pub(crate) fn log_static(&self, stream: &Stream) -> RecordingStreamResult<()> {
        let rec = stream.rec();
        // Vehicle: a deck plate under the table and the body axes.
        rec.log_static(
            format!("{}/deck", self.paths.vehicle),
            &rerun::Boxes3D::from_centers_and_half_sizes([[0.0, 0.0, -1.35]], [[0.9, 1.2, 0.03]])
                .with_colors([rgba([110, 110, 120], 200)])
                .with_fill_mode(rerun::FillMode::Solid),
        )?;
        rec.log_static(
            format!("{}/body_axes", self.paths.vehicle),
            &rerun::Arrows3D::from_vectors([[0.5, 0.0, 0.0], [0.0, 0.9, 0.0], [0.0, 0.0, 0.4]])
                .with_origins([[0.0, 0.0, -1.3]; 3])
                .with_colors([rgba([200, 200, 200], 200); 3])
                .with_radii([0.01]),
        )?;
        let n = self.axis_names.len();
        let axes = self.chain.axes();
        for k in 0..n {
            let g = &axes[k];
            let radius = ring_radius(k, n);
            let half = radius * 1.25;
            let color = colors::AXES[k];
            // Nominal axis (grey) in the mount frame; the rotor's own axis (coloured) in the rotor frame.
            rec.log_static(
                format!("{}/nominal_axis", self.paths.mounts[k]),
                &rerun::LineStrips3D::new([[p3(-g.axis * half), p3(g.axis * half)]])
                    .with_colors([rgb(colors::NOMINAL)])
                    .with_radii([0.006]),
            )?;
            rec.log_static(
                format!("{}/actual_axis", self.paths.gimbals[k]),
                &rerun::LineStrips3D::new([[p3(-g.axis * half * 1.05), p3(g.axis * half * 1.05)]])
                    .with_colors([rgb(color)])
                    .with_radii([0.012]),
            )?;
            // Ring of this gimbal: through its own axis and the next one; the last is a platform.
            rec.log_static(
                format!("{}/ring", self.paths.gimbals[k]),
                &rerun::LineStrips3D::new(ring(axes, k, radius)).with_colors([rgb(color)]).with_radii([0.02]),
            )?;
        }
        // The IMU: a box and its three sensor axes.
        rec.log_static(
            format!("{}/case", self.paths.imu),
            &rerun::Boxes3D::from_half_sizes([[0.22, 0.22, 0.16]])
                .with_colors([rgba([200, 200, 210], 90)])
                .with_fill_mode(rerun::FillMode::Solid),
        )?;
        rec.log_static(
            format!("{}/sensor_axes", self.paths.imu),
            &rerun::Arrows3D::from_vectors([[0.45, 0.0, 0.0], [0.0, 0.45, 0.0], [0.0, 0.0, 0.45]])
                .with_colors(colors::SENSOR.map(rgb))
                .with_radii([0.015]),
        )?;
        rec.log_static(
            format!("{}/sensor_axes/labels", self.paths.imu),
            &rerun::Points3D::new(SENSOR_LABELS_AT)
                .with_labels(["x_s", "y_s", "z_s"])
                // Half-saturated tints of the arrows' colours (a label the colour of its arrow
                // vanishes where it crosses it), legible on both themes (`palette::label`).
                .with_colors(colors::SENSOR.map(super::palette::label))
                .with_radii([0.002]),
        )?;
        Ok(())
    }

    /// Everything that depends on the error values (in live mode at `at` on the timeline: a
    /// reload can change them): the exaggerated base, mount and IMU transforms, the swing cones,
    /// the wedges and the key.
    pub(crate) fn log_errors(&self, stream: &Stream, p: &Params, at: Option<f64>) -> RecordingStreamResult<()> {
        // The drawing factors are in the 3D view's title ("errors ×100, swing ×500"): a label in the
        // scene saying so sat where the wedges' labels go (installation over it in the wobble preset).
        let (x, f) = (p.recording.exaggeration, self.factors);
        // The base, mount and IMU links do not depend on the gimbal angles.
        let draw = self.chain.link_rotations(&self.drawing, &[0.0; crate::model::scheme::MAX_AXES]);
        let t = |q: &UnitQuaternion<f64>| rerun::Transform3D::from_rotation(to_rerun_quaternion(q));
        stream.put(at, self.paths.base.as_str(), &t(&draw.base))?;
        for k in 0..self.axis_names.len() {
            stream.put(at, self.paths.mounts[k].as_str(), &t(&draw.mount[k]))?;
        }
        stream.put(at, self.paths.imu.as_str(), &t(&draw.imu))?;

        let n = self.axis_names.len();
        let axes = self.chain.axes();
        let drawing = p.table.truth.exaggerated(&f);
        // Installation: a wedge in the body between the ideal first axis and the tilted one.
        let first_tilted = draw.base * axes[0].axis;
        let installation = p.table.truth.installation_rad.norm() * ARCSEC_PER_RAD;
        // 1.1 long: at 1.5 the wedge and its label ran off the top of the default view.
        let mut key: Vec<(String, [u8; 3])> = Vec::new();
        let wedge = |radii: (f64, f64), both_ends: bool| Wedge { radii, both_ends };
        key.extend(self.log_wedge(
            stream,
            at,
            &format!("{}/installation", self.paths.vehicle),
            axes[0].axis,
            first_tilted,
            wedge((0.0, 1.1), false),
            installation,
            f.installation,
            "installation",
        )?);
        for (k, g) in axes.iter().enumerate() {
            let half = ring_radius(k, n) * 1.25;
            let color = colors::AXES[k];
            // Swing cone: a translucent double cone of half-angle α·x around the nominal axis, with rims.
            let alpha = drawing.axes[k].swing_half_angle_rad;
            let cone_path = format!("{}/swing_cone", self.paths.mounts[k]);
            if alpha > 0.0 {
                let (mesh, rims) = cone(g.axis, g.e1, g.e2, alpha, half);
                stream.put(
                    at,
                    cone_path.as_str(),
                    &rerun::Mesh3D::new(mesh.0).with_triangle_indices(mesh.1).with_albedo_factor(albedo(color, 60)),
                )?;
                stream.put(
                    at,
                    format!("{cone_path}/rims"),
                    &rerun::LineStrips3D::new(rims).with_colors([rgba(color, 200)]).with_radii([0.004]),
                )?;
                let text = format!(
                    "{} cone: {} swing α = {}, φ = {:.1}°{}",
                    super::palette::colors::AXIS_COLOR_NAMES[k],
                    g.name,
                    fmt_angle(p.table.truth.axes[k].swing_half_angle_rad),
                    p.table.truth.axes[k].swing_phase_rad * DEG_PER_RAD,
                    if f.swing == x { String::new() } else { format!(" (drawn ×{})", f.swing) }
                );
                key.push((text, color));
            } else {
                stream.clear(at, cone_path.as_str())?;
            }
            // Non-orthogonality: a wedge, in the previous rotor, between the normal to the previous
            // axis and this axis, at both ends of the axis beyond everything on it — its swing
            // cone and the previous ring, which crosses it. From the centre (it was 0 to the cone's
            // end) it lay inside the IMU's case and the cone, over the axis's own lines: on the
            // dual-axis presets nothing of it showed from the default eye. 0.25 long: the vertical
            // inner axis's lower end then stops above the deck (its upper end runs into the top of
            // the view and the key, so one end alone would not do).
            if k > 0 {
                let tilted = draw.mount[k] * g.axis;
                let eta_arcsec = p.table.truth.axes[k].non_orthogonality_rad * ARCSEC_PER_RAD;
                let from = half.max(ring_radius(k - 1, n)) + 0.05;
                // Short: the key's line must stop short of the upper wedge (the inner axis's, from
                // the default eye, passes just left of the key's middle).
                let what = format!("{} η", g.name);
                key.extend(self.log_wedge(
                    stream,
                    at,
                    &format!("{}/non_orthogonality", self.paths.gimbals[k - 1]),
                    g.axis,
                    tilted,
                    wedge((from, from + 0.25), true),
                    eta_arcsec,
                    f.non_orthogonality,
                    &what,
                )?);
            }
        }
        self.log_key(stream, at, &key)
    }

    /// A translucent wedge from `ideal` to `tilted` (both unit, same frame) over `shape`'s radii;
    /// its line of the key (None when there is no wedge).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn log_wedge(
        &self,
        stream: &Stream,
        at: Option<f64>,
        path: &str,
        ideal: Vector3<f64>,
        tilted: Vector3<f64>,
        shape: Wedge,
        true_arcsec: f64,
        x: f64,
        what: &str,
    ) -> RecordingStreamResult<Option<(String, [u8; 3])>> {
        if true_arcsec == 0.0 {
            stream.clear(at, path)?;
            return Ok(None);
        }
        let (r0, r1) = shape.radii;
        let steps = 16u32;
        let (mut positions, mut triangles, mut edges) = (Vec::new(), Vec::new(), Vec::new());
        for &sign in if shape.both_ends { &[1.0, -1.0][..] } else { &[1.0][..] } {
            // An inner and an outer arc (the inner a point when r0 = 0), joined by quads.
            let base = positions.len() as u32;
            for i in 0..=steps {
                let s = f64::from(i) / f64::from(steps);
                let dir = sign * ((1.0 - s) * ideal + s * tilted).normalize();
                positions.extend([p3(dir * r0), p3(dir * r1)]);
            }
            for i in 0..steps {
                let (a, b) = (base + 2 * i, base + 2 * i + 2);
                triangles.extend([[a, a + 1, b + 1], [a, b + 1, b]]);
            }
            edges.extend([
                [p3(sign * ideal * r0), p3(sign * ideal * r1)],
                [p3(sign * tilted * r0), p3(sign * tilted * r1)],
            ]);
        }
        stream.put(
            at,
            format!("{path}/wedge"),
            &rerun::Mesh3D::new(positions).with_triangle_indices(triangles).with_albedo_factor(albedo(WEDGE, 110)),
        )?;
        let edge_colors: Vec<rerun::Color> =
            (0..edges.len()).map(|i| if i % 2 == 0 { rgb([255, 255, 255]) } else { rgb(WEDGE) }).collect();
        stream.put(
            at,
            format!("{path}/edges"),
            &rerun::LineStrips3D::new(edges).with_colors(edge_colors).with_radii([0.004]),
        )?;
        let wedges = if shape.both_ends { "wedges" } else { "wedge" };
        Ok(Some((format!("yellow {wedges}: {what} = {} (drawn ×{x})", fmt_angle(true_arcsec / ARCSEC_PER_RAD)), WEDGE)))
    }

    /// The key of the error classes drawn: one line each, in its object's colour, in a fixed column
    /// of the world beside the table. Labels on the objects rode with the gimbals into the middle
    /// of the scene, where five of them piled up (seed preset jiang2017-calibration after 40 s).
    fn log_key(&self, stream: &Stream, at: Option<f64>, entries: &[(String, [u8; 3])]) -> RecordingStreamResult<()> {
        if entries.is_empty() {
            return stream.clear(at, KEY_PATH);
        }
        let positions: Vec<[f32; 3]> =
            (0..entries.len()).map(|i| [KEY_AT[0], KEY_AT[1], KEY_AT[2] - KEY_STEP * i as f32]).collect();
        stream.put(
            at,
            KEY_PATH,
            &rerun::Points3D::new(positions)
                .with_labels(entries.iter().map(|(t, _)| t.as_str()))
                .with_colors(entries.iter().map(|(_, c)| super::palette::label(*c)))
                .with_radii([0.002]),
        )
    }
}

/// Where the sensor axes' labels stand in the IMU frame (m; the arrows are 0.45 long): beyond the
/// tips and off their lines, each pushed its own way. (An arrow's own label sat at its middle,
/// inside the box, where the three piled up; on the line past the tip it covered the arrowhead
/// and, along a gimbal axis, sat in that axis's swing cone.) Labels turn with the IMU, so two of
/// them line up with the eye at some attitude wherever they stand; these places were searched for
/// in a pinhole model of the two default eyes (the table's and, with an INS, the one stepped back;
/// 55° field of view, checked against screenshots to ~20 px) over the attitudes of
/// jiang2017-dual-axis's continuous rotation and dual-axis-16-position's moves and dwells, a label
/// taken as a 54×30 px box. From the table's eye no two labels meet during the continuous rotation
/// (before, [0.72, 0, −0.22] and its turns: x_s and z_s for 11% of each turn, y_s and z_s for
/// 3.5%, 3 s into the preset among them), at no dwell, at 1.4% of the moves' attitudes (2.8%);
/// from the INS's eye at 0.7% (21%) and 4.9% (6.2%). A label is nearer another arrow's tip than
/// its own 5% of the time (21%). Screenshots of jiang2017-dual-axis every 2 s of a turn show no two
/// labels on each other.
const SENSOR_LABELS_AT: [[f32; 3]; 3] = [[0.85, -0.2, -0.16], [0.26, 0.74, -0.06], [-0.31, -0.03, 0.65]];

/// Where a wedge is drawn along its axis.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Wedge {
    /// From and to this distance from the axis's centre (m in the scene).
    pub(crate) radii: (f64, f64),
    /// At both ends of the axis (else along `ideal` only).
    pub(crate) both_ends: bool,
}

/// The entity of the error classes' key, where it stands (world, m) and its line spacing.
const KEY_PATH: &str = "world/key";
const KEY_AT: [f32; 3] = [-0.9, 1.6, 1.25];
const KEY_STEP: f32 = 0.2;
/// The wedges' colour.
const WEDGE: [u8; 3] = [255, 200, 60];

/// "x", "y" or "z" for a coordinate unit vector.
pub(crate) fn axis_letter(v: &Vector3<f64>) -> &'static str {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        "x"
    } else if a.y >= a.z {
        "y"
    } else {
        "z"
    }
}

/// Ring radius of gimbal k of n: nested, outer first.
pub(crate) fn ring_radius(k: usize, n: usize) -> f64 {
    let radii: [f64; 3] = [1.0, 0.75, 0.52];
    radii[3 - n + k].max(0.5)
}

/// Polylines of gimbal k's ring: a circle through its axis and the next axis (with bearing stubs),
/// or, for the last gimbal, a platform circle with spokes so that its rotation shows.
pub(crate) fn ring(axes: &[AxisGeometry], k: usize, radius: f64) -> Vec<Vec<[f32; 3]>> {
    let g = &axes[k];
    let (u, w) = if k + 1 < axes.len() { (g.axis, axes[k + 1].axis) } else { (g.e1, g.e2) };
    let circle: Vec<[f32; 3]> = (0..=96)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / 96.0;
            p3((u * t.cos() + w * t.sin()) * radius)
        })
        .collect();
    let mut strips = vec![circle];
    if k + 1 == axes.len() {
        for j in 0..4 {
            let t = std::f64::consts::FRAC_PI_2 * j as f64;
            strips.push(vec![[0.0; 3], p3((u * t.cos() + w * t.sin()) * radius)]);
        }
        // A marker notch at e1 so the sense of rotation reads at a glance.
        strips.push(vec![
            p3(u * radius * 1.12 + w * 0.05),
            p3(u * radius * 1.12 - w * 0.05),
            p3(u * radius * 0.95),
            p3(u * radius * 1.12 + w * 0.05),
        ]);
    }
    strips
}

/// A double cone of half-angle `alpha` around `axis` (length `half` each way): mesh and rim circles.
#[allow(clippy::type_complexity)]
pub(crate) fn cone(
    axis: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    alpha: f64,
    half: f64,
) -> ((Vec<[f32; 3]>, Vec<[u32; 3]>), Vec<Vec<[f32; 3]>>) {
    let segments = 48u32;
    let r = half * alpha.tan();
    let mut positions = vec![[0.0f32; 3]];
    let mut rims = Vec::new();
    for sign in [1.0, -1.0] {
        let mut rim = Vec::new();
        for i in 0..=segments {
            let t = std::f64::consts::TAU * f64::from(i) / f64::from(segments);
            let p = p3(axis * half * sign + (e1 * t.cos() + e2 * t.sin()) * r);
            if i < segments {
                positions.push(p);
            }
            rim.push(p);
        }
        rims.push(rim);
    }
    let mut triangles = Vec::new();
    for nappe in 0..2u32 {
        let base = 1 + nappe * segments;
        for i in 0..segments {
            triangles.push([0, base + i, base + (i + 1) % segments]);
        }
    }
    ((positions, triangles), rims)
}
