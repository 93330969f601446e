//! The file formats, as tables of f64 columns: what is in the bytes, nothing of what the numbers
//! mean. Readers stream rows ([`table::ColumnReader`] dispatches on [`sniff::Format`]); writers
//! ([`writer::TableWriter`]) replace their target only when finished.

pub(crate) mod cdr;
pub mod mcap_imu;
pub(crate) mod npy;
pub(crate) mod parquet_io;
pub mod psins_imu;
pub mod sniff;
pub mod table;
pub(crate) mod text;
pub mod writer;
