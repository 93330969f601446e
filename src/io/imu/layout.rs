//! Resolving a [`Layout`] to the columns, units, kind and default frame of a file.

use crate::io::error::{LogError, Result};
use crate::io::formats::psins_imu::{first_line, not_psins};
use crate::io::formats::sniff::{Format, detect_format};
use crate::io::formats::table::{Col, ColumnReader, HeaderMode, ReadOptions};
use crate::io::imu::units::{Quantity, split_unit, suffixes_for};
use crate::io::imu::{ColumnMap, ImuOptions, Layout, SampleKind, TimeUnit};
use std::path::Path;

/// The resolved columns of a layout.
pub(crate) struct Plan {
    /// Time, gyro x/y/z, accel x/y/z.
    pub cols: [Col; 7],
    pub time: TimeUnit,
    /// Factors to SI of the six sensor columns.
    pub scale: [f64; 6],
    pub kind: SampleKind,
    /// The layout's documented body frame, if it has one.
    pub frame: Option<&'static str>,
    pub header: HeaderMode,
}

fn fixed(time: TimeUnit, kind: SampleKind, order: [usize; 7], frame: Option<&'static str>, header: HeaderMode) -> Plan {
    Plan { cols: order.map(Col::Index), time, scale: [1.0; 6], kind, frame, header }
}

impl Layout {
    /// The layout's name in a log set's `[imu] layout` and in `--imu-layout`.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::Rinscope => "rinscope",
            Self::Psins => "psins",
            Self::PsinsImu => "psins-imu",
            Self::KfGins => "kf-gins",
            Self::Kalibr => "kalibr",
            Self::Npy7 { .. } => "npy7",
            Self::Ros2 => "ros2",
            Self::Columns(_) => "columns",
        }
    }
}

/// A PSINS SIMU file is read by the psins-imu layout only, and that layout reads nothing else.
fn check_psins(path: &Path, layout: &Layout) -> Result<()> {
    let format = detect_format(path)?;
    let layout_error = |problem: String| LogError::Layout { file: path.to_path_buf(), problem };
    match (layout, format) {
        (Layout::PsinsImu, Format::PsinsImu) => Ok(()),
        (Layout::PsinsImu, Format::Text) => Err(not_psins(path, first_line(path)?.as_deref())),
        (Layout::PsinsImu, other) => Err(layout_error(format!(
            "layout psins-imu reads PSINS SIMU text files (imufile.m), and this is {}",
            other.describe()
        ))),
        (other, Format::PsinsImu) => Err(layout_error(format!(
            "this is a PSINS .imu file (its first line names PSINS and SIMU: PSINS's imufile.m wrote it), not the {} layout: its integer counts are scaled by its header; use layout = \"psins-imu\" (or give no layout: a file that starts so is read as psins-imu)",
            other.name()
        ))),
        _ => Ok(()),
    }
}

/// A layout that reads its columns by position (psins, kf-gins, kalibr, npy7) must see exactly its
/// seven columns in an .npy (no names there to tell an extra one), and no rinscope header in a
/// text file (its names say the units, which a positional layout would ignore).
fn check_positional(path: &Path, layout: &Layout, header: HeaderMode) -> Result<()> {
    let format = detect_format(path)?;
    if !matches!(format, Format::Npy | Format::Text) {
        return Ok(());
    }
    let probe = ColumnReader::open(path, &[], &ReadOptions { header, ..ReadOptions::default() })?;
    let names = probe.all_columns();
    if format == Format::Npy {
        if names.len() != 7 {
            return Err(LogError::Shape {
                file: path.to_path_buf(),
                shape: format!("(N, {})", names.len()),
                expected: format!(
                    "the {} layout reads 7 columns by position ({}); an .npy has no column names, so an array of {} cannot be read: save exactly those 7",
                    layout.name(),
                    positional_columns(layout),
                    names.len()
                ),
            });
        }
        return Ok(());
    }
    if rinscope_plan(path, names).is_ok() {
        return Err(LogError::Layout {
            file: path.to_path_buf(),
            problem: format!(
                "its header names rinscope columns ({}) with their units, but layout = \"{}\" reads {} by position and ignores those names: this is the rinscope layout; use layout = \"rinscope\" (or give no layout)",
                names.join(", "),
                layout.name(),
                positional_columns(layout)
            ),
        });
    }
    Ok(())
}

/// What a positional layout's seven columns are, for messages.
fn positional_columns(layout: &Layout) -> &'static str {
    match layout {
        Layout::Psins | Layout::PsinsImu => "[wm vm t]: Δθ x y z (rad), Δv x y z (m/s), t (s)",
        Layout::KfGins => "GPS seconds of week, Δθ x y z (rad), Δv x y z (m/s)",
        Layout::Kalibr => "timestamp (ns), ω x y z (rad/s), α x y z (m/s²)",
        _ => "t, Δθ x y z (rad), Δv x y z (m/s)",
    }
}

pub(crate) fn plan_for(path: &Path, options: &ImuOptions) -> Result<Plan> {
    use HeaderMode::{Absent, Auto};
    use SampleKind::{Increments, Rates};
    check_psins(path, &options.layout)?;
    if let Layout::Psins | Layout::KfGins | Layout::Kalibr | Layout::Npy7 { .. } = &options.layout {
        // KF-GINS files have no header: its check reads the first line as one only to see names.
        check_positional(path, &options.layout, Auto)?;
    }
    Ok(match &options.layout {
        // imufile.m's [wm vm t], decoded by the PSINS source (`psins_imu`).
        Layout::Psins | Layout::PsinsImu => {
            fixed(TimeUnit::Seconds, Increments, [6, 0, 1, 2, 3, 4, 5], Some("rfu"), Auto)
        }
        Layout::KfGins => fixed(TimeUnit::GpsSecondsOfWeek, Increments, [0, 1, 2, 3, 4, 5, 6], Some("frd"), Absent),
        Layout::Kalibr => fixed(TimeUnit::Nanoseconds, Rates, [0, 1, 2, 3, 4, 5, 6], None, Auto),
        Layout::Npy7 { time } => fixed(*time, Increments, [0, 1, 2, 3, 4, 5, 6], None, Auto),
        Layout::Columns(map) => columns_plan(path, map)?,
        Layout::Rinscope | Layout::Ros2 => {
            let probe = ColumnReader::open(path, &[], &read_options(options, Auto))?;
            let is_mcap = probe.format() == Format::Mcap;
            if options.layout == Layout::Ros2 && !is_mcap {
                return Err(LogError::Layout {
                    file: path.to_path_buf(),
                    problem: "the Ros2 layout reads MCAP files only".into(),
                });
            }
            if options.layout == Layout::Rinscope && is_mcap {
                return Err(LogError::Layout {
                    file: path.to_path_buf(),
                    problem: "this is an MCAP file (ROS 2 sensor_msgs/msg/Imu), which the rinscope layout (tables with units in their column names) does not read: use layout = \"ros2\" (or give no layout)".into(),
                });
            }
            let mut plan = rinscope_plan(path, probe.all_columns())?;
            if is_mcap {
                // ROS REP 103: body frames are x forward, y left, z up.
                plan.frame = Some("flu");
            }
            plan
        }
    })
}

pub(crate) fn read_options(options: &ImuOptions, header: HeaderMode) -> ReadOptions {
    ReadOptions { header, topic: options.topic.clone(), allow_non_finite: false }
}

/// Finds `<base>_<unit>` among `names`; the unit must measure `quantity`.
fn find_unit_column(path: &Path, names: &[String], base: &str, quantity: Quantity) -> Result<Option<(String, f64)>> {
    let prefix = format!("{base}_");
    let hits: Vec<&String> = names.iter().filter(|n| n.starts_with(&prefix)).collect();
    let [name] = hits[..] else {
        if hits.len() > 1 {
            return Err(LogError::Layout {
                file: path.to_path_buf(),
                problem: format!("several {base}_* columns: {hits:?}"),
            });
        }
        return Ok(None);
    };
    let unit_error = |problem: String| LogError::Unit { file: path.to_path_buf(), column: name.clone(), problem };
    match split_unit(name) {
        Some((b, unit)) if b == base && unit.quantity == quantity => Ok(Some((name.clone(), unit.to_si))),
        Some((b, unit)) if b == base => Err(unit_error(format!(
            "{base} is {}, but _{} is a unit of {}; use one of {}",
            quantity_phrase(quantity),
            unit.suffix,
            quantity_phrase(unit.quantity),
            suffixes_for(quantity)
        ))),
        _ => Err(unit_error(format!(
            "unknown unit {:?}; a {base} column takes one of {}",
            name.get(prefix.len()..).unwrap_or(""),
            suffixes_for(quantity)
        ))),
    }
}

fn quantity_phrase(q: Quantity) -> &'static str {
    match q {
        Quantity::Angle => "an angle (increment)",
        Quantity::AngularRate => "an angular rate",
        Quantity::Velocity => "a velocity (increment)",
        Quantity::Acceleration => "an acceleration",
        Quantity::Time => "a time",
        Quantity::Length => "a length",
        Quantity::Dimensionless => "a pure number",
    }
}

/// The plan of a file whose columns `[imu.columns]` describes.
fn columns_plan(path: &Path, map: &ColumnMap) -> Result<Plan> {
    const NAMES: [&str; 6] = ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"];
    let unit_error = |i: usize, problem: String| LogError::Unit {
        file: path.to_path_buf(),
        column: format!("imu.columns.{} ({})", NAMES[i], map.sensors[i].0),
        problem,
    };
    let mut scale = [1.0; 6];
    let mut kinds = [SampleKind::Rates; 6];
    for (i, (_, suffix)) in map.sensors.iter().enumerate() {
        let gyro = i < 3;
        let (rate, increment) =
            if gyro { (Quantity::AngularRate, Quantity::Angle) } else { (Quantity::Acceleration, Quantity::Velocity) };
        let Some((_, unit)) = split_unit(&format!("x_{suffix}")).filter(|(b, _)| *b == "x") else {
            return Err(unit_error(
                i,
                format!(
                    "unknown unit {suffix:?}; use one of {} (rates) or {} (increments)",
                    suffixes_for(rate),
                    suffixes_for(increment)
                ),
            ));
        };
        kinds[i] = match unit.quantity {
            q if q == rate => SampleKind::Rates,
            q if q == increment => SampleKind::Increments,
            _ => {
                return Err(unit_error(
                    i,
                    format!(
                        "{suffix:?} is {}; a {} column takes one of {} (rates) or {} (increments)",
                        quantity_phrase(unit.quantity),
                        if gyro { "gyro" } else { "accelerometer" },
                        suffixes_for(rate),
                        suffixes_for(increment)
                    ),
                ));
            }
        };
        scale[i] = unit.to_si;
    }
    if kinds.iter().any(|k| *k != kinds[0]) {
        return Err(LogError::Layout {
            file: path.to_path_buf(),
            problem: format!(
                "[imu.columns] mixes rates and increments ({}): give all six as rates (deg_per_s, mps2, ...) or all as increments (rad, mps, ...)",
                NAMES.iter().zip(kinds).map(|(n, k)| format!("{n} {k:?}")).collect::<Vec<_>>().join(", ")
            ),
        });
    }
    let by_name =
        std::iter::once(&map.time.0).chain(map.sensors.iter().map(|(c, _)| c)).any(|c| matches!(c, Col::Name(_)));
    let [a, b, c, d, e, f] = map.sensors.clone().map(|(col, _)| col);
    Ok(Plan {
        cols: [map.time.0.clone(), a, b, c, d, e, f],
        time: map.time.1,
        scale,
        kind: kinds[0],
        frame: None,
        header: if by_name { HeaderMode::Present } else { HeaderMode::Auto },
    })
}

fn rinscope_plan(path: &Path, names: &[String]) -> Result<Plan> {
    let times: Vec<(&String, TimeUnit)> = names
        .iter()
        .filter_map(|n| {
            let unit = match n.as_str() {
                "t_s" => TimeUnit::Seconds,
                "t_ms" => TimeUnit::Milliseconds,
                "t_us" => TimeUnit::Microseconds,
                "t_ns" => TimeUnit::Nanoseconds,
                "gps_sow_s" => TimeUnit::GpsSecondsOfWeek,
                _ => return None,
            };
            Some((n, unit))
        })
        .collect();
    let layout_error = |problem: String| LogError::Layout { file: path.to_path_buf(), problem };
    let (time_name, time) = match times[..] {
        [(n, u)] => (n.clone(), u),
        [] => {
            return Err(LogError::MissingColumn {
                file: path.to_path_buf(),
                column: "t_s, t_ms, t_us, t_ns or gps_sow_s (the time column of the rinscope layout)".into(),
                available: names.to_vec(),
            });
        }
        _ => {
            return Err(layout_error(format!(
                "several time columns: {:?}",
                times.iter().map(|t| t.0).collect::<Vec<_>>()
            )));
        }
    };
    let mut families = Vec::new();
    for (gyro, q_gyro, accel, q_accel, kind) in [
        ("gyro", Quantity::AngularRate, "accel", Quantity::Acceleration, SampleKind::Rates),
        ("dtheta", Quantity::Angle, "dv", Quantity::Velocity, SampleKind::Increments),
    ] {
        let mut found = Vec::new();
        for (family, q) in [(gyro, q_gyro), (accel, q_accel)] {
            for axis in ["x", "y", "z"] {
                found
                    .push((format!("{family}_{axis}"), find_unit_column(path, names, &format!("{family}_{axis}"), q)?));
            }
        }
        if found.iter().any(|(_, c)| c.is_some()) {
            families.push((kind, found));
        }
    }
    let (kind, found) = match families.len() {
        1 => families.remove(0),
        0 => {
            return Err(layout_error(format!(
                "no IMU columns: the rinscope layout needs gyro_{{x,y,z}}_<rate unit> and accel_{{x,y,z}}_<acceleration unit> (rates) or dtheta_{{x,y,z}}_<angle unit> and dv_{{x,y,z}}_<velocity unit> (increments); the file has {}",
                names.join(", ")
            )));
        }
        _ => {
            return Err(layout_error(
                "both rate (gyro_*/accel_*) and increment (dtheta_*/dv_*) columns: keep one kind".into(),
            ));
        }
    };
    let mut cols: Vec<Col> = vec![Col::Name(time_name)];
    let mut scale = [1.0; 6];
    for (i, (base, column)) in found.into_iter().enumerate() {
        let Some((name, to_si)) = column else {
            return Err(LogError::MissingColumn {
                file: path.to_path_buf(),
                column: format!("{base}_<unit> ({kind:?})"),
                available: names.to_vec(),
            });
        };
        if let Some(s) = scale.get_mut(i) {
            *s = to_si;
        }
        cols.push(Col::Name(name));
    }
    let cols: [Col; 7] = cols.try_into().map_err(|_| layout_error("internal: column plan".into()))?;
    Ok(Plan { cols, time, scale, kind, frame: Some("rfu"), header: HeaderMode::Auto })
}
