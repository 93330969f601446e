//! Layer 1, files (above `math`, whose units and constants it uses): tabular logs in and out — streaming column readers for CSV, NumPy .npy, Parquet,
//! MCAP (ROS 2 `sensor_msgs/msg/Imu`) and PSINS SIMU `.imu` text ([`read_psins_header`]), IMU
//! layouts with checked units and frames, atomic table writers — and outputs that a reader never
//! sees half-written ([`files`]).
//!
//! * [`ColumnReader`] reads chosen columns of any supported file as f64 rows, one at a time, with
//!   memory that does not grow with the file. The format comes from the extension and is checked
//!   against the file's first bytes ([`detect_format`]).
//! * [`ImuReader`] turns a log of a known [`Layout`] into [`ImuSample`]s in SI units and rinscope's
//!   RFU sensor frame ([`frame_matrix`]), checking the time stamps as it goes; [`check_static`]
//!   judges an initial static segment and says what wrongly declared data look like.
//! * [`TableWriter`] writes named f64 columns to CSV, Parquet or .npy through `PATH.partial`,
//!   renamed onto `PATH` only when finished.
//!
//! Every error ([`LogError`]) names the file, and where it applies the row, line, column, value
//! and unit. No input makes these functions panic.

mod cdr;
mod clock;
mod error;
pub mod files;
mod frames;
mod guess;
mod imu;
mod layout;
mod mcap_imu;
mod npy;
mod parquet_io;
mod plausibility;
mod psins_imu;
pub mod series;
mod sniff;
mod table;
mod text;
pub mod units;
pub mod validity;
mod writer;

pub use error::{FrameError, Location, LogError, Result, fixed_number, short_number};
pub use frames::{Frame, frame_matrix};
pub use guess::guess_layout;
pub use imu::{
    BlockEnd, ColumnMap, GPS_WEEK_S, GapPolicy, ImuEvent, ImuOptions, ImuReader, ImuSample, Layout, RATE_TOLERANCE,
    SampleKind, StartTime, StaticCheck, TimeUnit,
};
pub use mcap_imu::MCAP_IMU_COLUMNS;
pub use plausibility::{EARTH_RATE_RAD_PER_S, StaticReport, check_static};
pub use psins_imu::{PsinsHeader, read_psins_header};
pub use sniff::{Format, detect_format};
pub use table::{Col, ColumnReader, HeaderMode, ReadOptions};
pub use writer::TableWriter;
