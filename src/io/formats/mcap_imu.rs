//! MCAP recordings of ROS 2 `sensor_msgs/msg/Imu` (CDR) as a table of seven columns.
//!
//! Columns: `t_ns` (header.stamp as integer nanoseconds, or the message's log_time when the stamp
//! is zero), `gyro_x_rad_per_s`, `gyro_y_rad_per_s`, `gyro_z_rad_per_s` (angular_velocity),
//! `accel_x_mps2`, `accel_y_mps2`, `accel_z_mps2` (linear_acceleration), in the message's frame
//! (ROS REP 103: body frames are x forward, y left, z up).
//!
//! The topic is the one asked for, or else the file's only channel whose schema is
//! `sensor_msgs/msg/Imu` with message encoding `cdr`; channels are taken from the summary section
//! (or, for a file without one, from a first pass over the records). Messages are then read in
//! file order with mcap's sans-io linear reader, fed 64 KiB at a time; it yields whole chunk
//! records, which we decompress (zstd, lz4 or none), CRC-check and walk here, with every length
//! checked. (mcap 0.25's own chunk walker loops forever on a chunk whose inner record length
//! overruns the chunk; found by the garbage tests.) Memory is bounded by one chunk (at most
//! 256 MiB, as recorders write them: typically 1–4 MiB), never by the file.

use crate::io::error::{Location, LogError, Result};
use crate::io::formats::cdr::decode_imu;
use crate::io::formats::table::Source;
use mcap::records::{Record, op};
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::sans_io::summary_reader::{SummaryReadEvent, SummaryReader, SummaryReaderOptions};
use std::collections::{BTreeMap, BTreeSet};
use std::fs::File;
use std::io::{Read, Seek};
use std::path::{Path, PathBuf};

/// The schema name of the messages read.
pub(crate) const IMU_SCHEMA: &str = "sensor_msgs/msg/Imu";
/// Largest record accepted (a chunk or a message); guards against corrupt lengths.
const RECORD_LIMIT: usize = 256 << 20;
const READ_BYTES: usize = 1 << 16;

/// The column names of an MCAP Imu table.
pub const MCAP_IMU_COLUMNS: [&str; 7] = [
    "t_ns",
    "gyro_x_rad_per_s",
    "gyro_y_rad_per_s",
    "gyro_z_rad_per_s",
    "accel_x_mps2",
    "accel_y_mps2",
    "accel_z_mps2",
];

/// A channel as the topic choice needs it.
#[derive(Debug, Clone)]
struct ChannelInfo {
    topic: String,
    schema: String,
    encoding: String,
    /// Its messages, as the summary's statistics count them (None without them).
    messages: Option<u64>,
}

impl ChannelInfo {
    fn is_imu(&self) -> bool {
        self.schema == IMU_SCHEMA && self.encoding == "cdr"
    }
    fn describe(&self) -> String {
        format!(
            "{} ({}, {})",
            self.topic,
            if self.schema.is_empty() { "no schema" } else { &self.schema },
            self.encoding
        )
    }
}

fn mcap_error(path: &Path, e: impl std::fmt::Display) -> LogError {
    LogError::corrupt(path, format!("not a readable MCAP file: {e}"))
}

/// Top-level records of an MCAP file with the records inside chunks unpacked, in file order.
struct Records {
    file: File,
    reader: LinearReader,
    /// The current chunk's decompressed records, and the read position in them.
    chunk: Vec<u8>,
    chunk_pos: usize,
    /// Bytes of the file given to the reader so far.
    fed: u64,
}

impl Records {
    fn new(file: File) -> Self {
        let options = LinearReaderOptions::default().with_record_length_limit(RECORD_LIMIT).with_emit_chunks(true);
        Self { file, reader: LinearReader::new_with_options(options), chunk: Vec::new(), chunk_pos: 0, fed: 0 }
    }

    /// Calls `on_record` for each record until it returns `true` (then `Ok(true)`), or the file ends (`Ok(false)`).
    fn until(&mut self, path: &Path, mut on_record: impl FnMut(u8, &[u8]) -> Result<bool>) -> Result<bool> {
        loop {
            while self.chunk_pos < self.chunk.len() {
                let rest = self.chunk.get(self.chunk_pos..).unwrap_or(&[]);
                let (opcode, body, used) = split_record(rest).ok_or_else(|| {
                    mcap_error(path, format!("a record inside a chunk overruns the chunk ({} bytes left)", rest.len()))
                })?;
                self.chunk_pos += used;
                if on_record(opcode, body)? {
                    return Ok(true);
                }
            }
            let Some(event) = self.reader.next_event() else {
                // The closing magic was read (the reader is fed no more than it asks for, so
                // nothing of the file is buffered): anything after it is not this recording's —
                // a second file appended, or garbage.
                let mut probe = [0u8; 1];
                let more = self.file.read(&mut probe).map_err(|e| LogError::io(path, "cannot read", e))?;
                if more > 0 {
                    return Err(mcap_error(
                        path,
                        format!(
                            "bytes follow the recording's closing magic at byte {}: a second file appended, or garbage (an MCAP ends with its magic)",
                            self.fed
                        ),
                    ));
                }
                return Ok(false);
            };
            match event.map_err(|e| mcap_error(path, e))? {
                LinearReadEvent::ReadRequest(need) => {
                    let buf = self.reader.insert(need.clamp(1, READ_BYTES));
                    let n = self.file.read(buf).map_err(|e| LogError::io(path, "cannot read", e))?;
                    self.reader.notify_read(n);
                    self.fed += n as u64;
                }
                LinearReadEvent::Record { opcode: op::CHUNK, data } => {
                    self.chunk = decompress_chunk(path, data)?;
                    self.chunk_pos = 0;
                }
                LinearReadEvent::Record { opcode, data } => {
                    if on_record(opcode, data)? {
                        return Ok(true);
                    }
                }
            }
        }
    }
}

/// Splits `opcode (u8), length (u64 LE), body` off the front of `buf`: (opcode, body, bytes used).
fn split_record(buf: &[u8]) -> Option<(u8, &[u8], usize)> {
    let (&opcode, rest) = buf.split_first()?;
    let len = usize::try_from(u64::from_le_bytes(rest.get(..8)?.try_into().ok()?)).ok()?;
    let body = rest.get(8..8usize.checked_add(len)?)?;
    Some((opcode, body, 9 + len))
}

/// The records of a chunk record, decompressed and CRC-checked.
fn decompress_chunk(path: &Path, data: &[u8]) -> Result<Vec<u8>> {
    let Record::Chunk { header, data } = mcap::parse_record(op::CHUNK, data).map_err(|e| mcap_error(path, e))? else {
        return Err(mcap_error(path, "a chunk record that does not parse"));
    };
    let size = usize::try_from(header.uncompressed_size).ok().filter(|&n| n <= RECORD_LIMIT).ok_or_else(|| {
        mcap_error(
            path,
            format!("a chunk claims {} uncompressed bytes (more than {RECORD_LIMIT})", header.uncompressed_size),
        )
    })?;
    let bad = |what: String| mcap_error(path, format!("chunk at log time {}: {what}", header.message_start_time));
    let records = match header.compression.as_str() {
        "" => data.to_vec(),
        "zstd" => zstd::bulk::decompress(&data, size).map_err(|e| bad(format!("zstd: {e}")))?,
        "lz4" => {
            let mut out = Vec::with_capacity(size);
            let decoder = lz4::Decoder::new(&data[..]).map_err(|e| bad(format!("lz4: {e}")))?;
            decoder.take(size as u64 + 1).read_to_end(&mut out).map_err(|e| bad(format!("lz4: {e}")))?;
            out
        }
        other => {
            return Err(bad(format!("compression {other:?} is not zstd, lz4 or none")));
        }
    };
    if records.len() != size {
        return Err(bad(format!("decompresses to {} bytes, the header says {size}", records.len())));
    }
    if header.uncompressed_crc != 0 && crc32fast::hash(&records) != header.uncompressed_crc {
        return Err(bad("CRC mismatch: the chunk is corrupt".into()));
    }
    Ok(records)
}

/// Channels from the summary section, if the file has one.
fn summary_channels(path: &Path, file: &mut File) -> Result<Option<BTreeMap<u16, ChannelInfo>>> {
    let len = file.metadata().map_err(|e| LogError::io(path, "cannot read", e))?.len();
    let mut reader = SummaryReader::new_with_options(
        SummaryReaderOptions::default().with_file_size(len).with_record_length_limit(RECORD_LIMIT),
    );
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| mcap_error(path, e))? {
            SummaryReadEvent::ReadRequest(need) => {
                let buf = reader.insert(need.clamp(1, READ_BYTES));
                let n = file.read(buf).map_err(|e| LogError::io(path, "cannot read", e))?;
                reader.notify_read(n);
            }
            SummaryReadEvent::SeekRequest(to) => {
                let pos = file.seek(to).map_err(|e| LogError::io(path, "cannot seek", e))?;
                reader.notify_seeked(pos);
            }
        }
    }
    let Some(summary) = reader.finish() else {
        return Ok(None);
    };
    if summary.channels.is_empty() {
        return Ok(None);
    }
    let counts = summary.stats.as_ref().map(|s| &s.channel_message_counts);
    Ok(Some(
        summary
            .channels
            .iter()
            .map(|(&id, c)| {
                let schema = c.schema.as_ref().map(|s| s.name.clone()).unwrap_or_default();
                let messages = counts.map(|m| m.get(&id).copied().unwrap_or(0));
                (id, ChannelInfo { topic: c.topic.clone(), schema, encoding: c.message_encoding.clone(), messages })
            })
            .collect(),
    ))
}

/// Channels from a pass over all records (files without a summary).
fn scan_channels(path: &Path, file: &File) -> Result<BTreeMap<u16, ChannelInfo>> {
    let mut file = file.try_clone().map_err(|e| LogError::io(path, "cannot read", e))?;
    file.rewind().map_err(|e| LogError::io(path, "cannot seek", e))?;
    let mut schemas: BTreeMap<u16, String> = BTreeMap::new();
    let mut channels: BTreeMap<u16, (u16, String, String)> = BTreeMap::new();
    let mut records = Records::new(file);
    let scanned = records.until(path, |opcode, data| {
        match opcode {
            op::SCHEMA => {
                if let Record::Schema { header, .. } =
                    mcap::parse_record(opcode, data).map_err(|e| mcap_error(path, e))?
                {
                    schemas.insert(header.id, header.name);
                }
            }
            op::CHANNEL => {
                if let Record::Channel(c) = mcap::parse_record(opcode, data).map_err(|e| mcap_error(path, e))? {
                    channels.insert(c.id, (c.schema_id, c.topic, c.message_encoding));
                }
            }
            _ => {}
        }
        Ok(false)
    });
    // A damaged or cut-off recording: keep the channels seen before the damage, the message
    // stream reports the damage when it gets there.
    if let Err(e) = scanned
        && channels.is_empty()
    {
        return Err(e);
    }
    Ok(channels
        .into_iter()
        .map(|(id, (schema_id, topic, encoding))| {
            let schema = schemas.get(&schema_id).cloned().unwrap_or_default();
            (id, ChannelInfo { topic, schema, encoding, messages: None })
        })
        .collect())
}

pub(crate) struct McapImuSource {
    path: PathBuf,
    records: Records,
    channel_ids: BTreeSet<u16>,
    topic: String,
    names: Vec<String>,
    selected: Vec<usize>,
    row: u64,
    /// The IMU topic's messages, from the summary's statistics.
    rows_hint: Option<u64>,
}

impl McapImuSource {
    pub(crate) fn open(path: &Path, topic: Option<&str>) -> Result<Self> {
        let mut file = crate::io::files::open_input(path).map_err(|e| LogError::io(path, "cannot open", e))?;
        let channels = match summary_channels(path, &mut file) {
            Ok(Some(c)) => c,
            // No (usable) summary: a recording cut short, or written without one.
            Ok(None) | Err(LogError::Corrupt { .. }) => scan_channels(path, &file)?,
            Err(e) => return Err(e),
        };
        let topics: Vec<String> = channels.values().map(ChannelInfo::describe).collect();
        let topic_error =
            |problem: String| LogError::Topic { file: path.to_path_buf(), problem, topics: topics.clone() };
        let chosen: String = match topic {
            Some(t) => {
                let on_topic: Vec<&ChannelInfo> = channels.values().filter(|c| c.topic == t).collect();
                if on_topic.is_empty() {
                    return Err(topic_error(format!("no topic {t:?}")));
                }
                if let Some(bad) = on_topic.iter().find(|c| !c.is_imu()) {
                    return Err(topic_error(format!(
                        "topic {t:?} carries {}, not {IMU_SCHEMA} in cdr",
                        bad.describe()
                    )));
                }
                t.to_owned()
            }
            None => {
                let imu_topics: BTreeSet<&str> =
                    channels.values().filter(|c| c.is_imu()).map(|c| c.topic.as_str()).collect();
                match imu_topics.len() {
                    0 => return Err(topic_error(format!("no {IMU_SCHEMA} topic in cdr"))),
                    1 => imu_topics.into_iter().next().unwrap_or_default().to_owned(),
                    _ => {
                        return Err(topic_error(format!(
                            "{} {IMU_SCHEMA} topics; choose one with ReadOptions::topic",
                            imu_topics.len()
                        )));
                    }
                }
            }
        };
        let channel_ids = channels.iter().filter(|(_, c)| c.topic == chosen).map(|(&id, _)| id).collect();
        // The rows: the topic's messages, if the summary counts every one of its channels'.
        let rows_hint = channels.values().filter(|c| c.topic == chosen).map(|c| c.messages).sum();
        file.rewind().map_err(|e| LogError::io(path, "cannot seek", e))?;
        Ok(Self {
            path: path.to_path_buf(),
            records: Records::new(file),
            channel_ids,
            topic: chosen,
            names: MCAP_IMU_COLUMNS.iter().map(|s| (*s).to_owned()).collect(),
            selected: Vec::new(),
            row: 0,
            rows_hint,
        })
    }
}

impl Source for McapImuSource {
    fn all_columns(&self) -> &[String] {
        &self.names
    }

    fn select(&mut self, indices: &[usize]) -> Result<()> {
        self.selected = indices.to_vec();
        Ok(())
    }

    fn next_row(&mut self, out: &mut [f64], exact: &mut [Option<i64>]) -> Result<bool> {
        let (path, ids, topic, row) = (&self.path, &self.channel_ids, &self.topic, self.row);
        let mut values = [0.0f64; 7];
        let mut t_ns = 0i64;
        let found = self.records.until(path, |opcode, data| {
            if opcode != op::MESSAGE {
                return Ok(false);
            }
            let Record::Message { header, data } = mcap::parse_record(opcode, data).map_err(|e| mcap_error(path, e))?
            else {
                return Ok(false);
            };
            if !ids.contains(&header.channel_id) {
                return Ok(false);
            }
            let bad = |detail: String| {
                LogError::corrupt(
                    path,
                    format!("Imu message {} on {topic} (log_time {} ns): {detail}", row + 1, header.log_time),
                )
            };
            let m = decode_imu(&data).map_err(bad)?;
            t_ns = if m.stamp_sec == 0 && m.stamp_nanosec == 0 {
                i64::try_from(header.log_time).map_err(|_| bad("log_time beyond year 2262".into()))?
            } else {
                i64::from(m.stamp_sec) * 1_000_000_000 + i64::from(m.stamp_nanosec)
            };
            values = [
                t_ns as f64,
                m.angular_velocity[0],
                m.angular_velocity[1],
                m.angular_velocity[2],
                m.linear_acceleration[0],
                m.linear_acceleration[1],
                m.linear_acceleration[2],
            ];
            Ok(true)
        })?;
        if !found {
            // A record a reader does not know is skipped (the format's rule for newer opcodes), so
            // a chunk whose opcode byte is damaged vanished with its messages, and the log read on
            // as if it started or ended later. The summary's statistics count every message.
            if let Some(counted) = self.rows_hint.filter(|&n| n != self.row) {
                return Err(LogError::corrupt(
                    path,
                    format!(
                        "its summary counts {counted} messages on {topic}, {row} were read: records of the file are damaged (a chunk or a message that does not read as one)"
                    ),
                ));
            }
            return Ok(false);
        }
        self.row += 1;
        for (k, &col) in self.selected.iter().enumerate() {
            if let (Some(o), Some(e)) = (out.get_mut(k), exact.get_mut(k)) {
                *o = values.get(col).copied().unwrap_or(f64::NAN);
                *e = (col == 0).then_some(t_ns);
            }
        }
        Ok(true)
    }

    fn selected_width(&self) -> usize {
        self.selected.len()
    }

    fn location(&self) -> Location {
        Location { row: self.row, line: None }
    }

    fn rows_hint(&self) -> Option<u64> {
        self.rows_hint
    }
}
