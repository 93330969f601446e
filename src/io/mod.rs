//! Layer 1, files (above `math`, whose units and constants it uses). Three folders say which is
//! which:
//!
//! * [`formats`] — what is in the bytes: streaming column readers for CSV, NumPy .npy, Parquet,
//!   MCAP (ROS 2 `sensor_msgs/msg/Imu`) and PSINS SIMU `.imu` text; atomic table writers.
//!   [`ColumnReader`] reads chosen columns of any supported file as f64 rows, one at a time, with
//!   memory that does not grow with the file; the format comes from the extension and is checked
//!   against the file's first bytes ([`detect_format`]). [`TableWriter`] writes named f64 columns
//!   to CSV, Parquet or .npy through `PATH.partial`, renamed onto `PATH` only when finished.
//! * [`imu`] — what the numbers mean: [`ImuReader`] turns a log of a known [`Layout`] into
//!   [`ImuSample`]s in SI units (the units in column names: [`imu::units`]) and rinscope's RFU
//!   sensor frame (the axis conventions: [`imu::axes`]), checking the time stamps as it goes;
//!   [`check_static`] judges an initial static segment and says what wrongly declared data look
//!   like; [`imu::series`] is one table's columns for `allan --series`.
//! * output and input safety — [`files`]: outputs a reader never sees half-written, the one rule
//!   for opening inputs; [`validity`]: the one finite-and-physical rule for every number.
//!
//! Every error ([`LogError`]) names the file, and where it applies the row, line, column, value
//! and unit. No input makes these functions panic.

pub mod files;
pub mod formats;
pub mod imu;
pub mod validity;

mod error;

pub use error::{FrameError, Location, LogError, Result, fixed_number, short_number};
pub use formats::mcap_imu::MCAP_IMU_COLUMNS;
pub use formats::psins_imu::{PsinsHeader, read_psins_header};
pub use formats::sniff::{Format, detect_format};
pub use formats::table::{Col, ColumnReader, HeaderMode, ReadOptions};
pub use formats::writer::TableWriter;
pub use imu::axes::{Frame, frame_matrix};
pub use imu::guess::guess_layout;
pub use imu::plausibility::{EARTH_RATE_RAD_PER_S, StaticReport, check_static};
pub use imu::{
    BlockEnd, ColumnMap, GPS_WEEK_S, GapPolicy, ImuEvent, ImuOptions, ImuReader, ImuSample, Layout, RATE_TOLERANCE,
    SampleKind, StartTime, StaticCheck, TimeUnit,
};
