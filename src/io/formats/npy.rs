//! NumPy `.npy`: a hand-written reader and writer of 2-D float arrays.
//!
//! Format (<https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html>): the magic
//! `\x93NUMPY`, a major and minor version byte, the header length (little-endian u16 for v1.0, u32
//! for v2.0 and v3.0), then the header: a Python dict literal
//! `{'descr': '<f8', 'fortran_order': False, 'shape': (N, C), }` padded with spaces and ended by
//! `\n` so that the data start at a multiple of 64 bytes. The data follow, C order (row-major)
//! unless `fortran_order` is True.
//!
//! The reader takes `<f8`, `>f8`, `<f4`, `>f4` (f32 widened exactly to f64), a 2-D shape
//! `(N, C)`, C order (or Fortran order when N or C is 1, where the two are the same), and checks
//! that the file holds exactly N·C items. Rows are read one at a time.
//!
//! The writer streams rows of f64 whose count is unknown up front: it writes a header whose shape
//! is padded to the width of the largest possible row count, and rewrites it with the true count
//! when finished (the header keeps its length, so the data do not move).

use crate::io::error::{Location, LogError, Result};
use crate::io::formats::sniff::NPY_MAGIC;
use crate::io::formats::table::Source;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

const MAX_HEADER_BYTES: usize = 1 << 20;

/// A parsed Python literal, as far as NPY headers need.
#[derive(Debug, Clone, PartialEq)]
enum Py {
    Str(String),
    Bool(bool),
    Int(u64),
    None,
    Seq(Vec<Py>),
    Dict(Vec<(Py, Py)>),
}

struct PyParser<'a> {
    s: &'a [u8],
    i: usize,
}

impl PyParser<'_> {
    fn skip_ws(&mut self) {
        while self.s.get(self.i).is_some_and(u8::is_ascii_whitespace) {
            self.i += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.s.get(self.i).copied()
    }

    fn expect(&mut self, c: u8) -> std::result::Result<(), String> {
        if self.peek() == Some(c) {
            self.i += 1;
            Ok(())
        } else {
            Err(format!("expected '{}' at byte {} of the header", c as char, self.i))
        }
    }

    fn value(&mut self, depth: usize) -> std::result::Result<Py, String> {
        if depth > 8 {
            return Err("header nested too deeply".into());
        }
        match self.peek() {
            Some(q @ (b'\'' | b'"')) => {
                self.i += 1;
                let start = self.i;
                while self.s.get(self.i).is_some_and(|&c| c != q) {
                    self.i += 1;
                }
                let text = self.s.get(start..self.i).ok_or("unterminated string in header")?;
                self.expect(q)?;
                Ok(Py::Str(String::from_utf8_lossy(text).into_owned()))
            }
            Some(open @ (b'(' | b'[')) => {
                let close = if open == b'(' { b')' } else { b']' };
                self.i += 1;
                let mut items = Vec::new();
                loop {
                    if self.peek() == Some(close) {
                        self.i += 1;
                        return Ok(Py::Seq(items));
                    }
                    items.push(self.value(depth + 1)?);
                    match self.peek() {
                        Some(b',') => self.i += 1,
                        Some(c) if c == close => {}
                        _ => return Err(format!("expected ',' or '{}' in header", close as char)),
                    }
                }
            }
            Some(b'{') => {
                self.i += 1;
                let mut items = Vec::new();
                loop {
                    if self.peek() == Some(b'}') {
                        self.i += 1;
                        return Ok(Py::Dict(items));
                    }
                    let key = self.value(depth + 1)?;
                    self.expect(b':')?;
                    let value = self.value(depth + 1)?;
                    items.push((key, value));
                    match self.peek() {
                        Some(b',') => self.i += 1,
                        Some(b'}') => {}
                        _ => return Err("expected ',' or '}' in header".into()),
                    }
                }
            }
            Some(c) if c.is_ascii_alphanumeric() => {
                let start = self.i;
                while self.s.get(self.i).is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_') {
                    self.i += 1;
                }
                let word = self.s.get(start..self.i).unwrap_or(&[]);
                match word {
                    b"True" => Ok(Py::Bool(true)),
                    b"False" => Ok(Py::Bool(false)),
                    b"None" => Ok(Py::None),
                    _ => {
                        // Python 2 wrote long integers with an `L` suffix.
                        let digits = word.strip_suffix(b"L").unwrap_or(word);
                        std::str::from_utf8(digits)
                            .ok()
                            .and_then(|d| d.parse::<u64>().ok())
                            .map(Py::Int)
                            .ok_or_else(|| format!("unexpected {:?} in header", String::from_utf8_lossy(word)))
                    }
                }
            }
            _ => Err(format!("unexpected byte at {} of the header", self.i)),
        }
    }
}

/// Element type of the array.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Dtype {
    F64 { little: bool },
    F32 { little: bool },
}

impl Dtype {
    fn size(self) -> usize {
        match self {
            Self::F64 { .. } => 8,
            Self::F32 { .. } => 4,
        }
    }

    fn read(self, bytes: &[u8]) -> f64 {
        match self {
            Self::F64 { little } => {
                let mut b = [0u8; 8];
                b.copy_from_slice(bytes.get(..8).unwrap_or(&[0; 8]));
                if little { f64::from_le_bytes(b) } else { f64::from_be_bytes(b) }
            }
            Self::F32 { little } => {
                let mut b = [0u8; 4];
                b.copy_from_slice(bytes.get(..4).unwrap_or(&[0; 4]));
                f64::from(if little { f32::from_le_bytes(b) } else { f32::from_be_bytes(b) })
            }
        }
    }
}

/// A parsed header.
#[derive(Debug)]
struct Header {
    dtype: Dtype,
    rows: u64,
    cols: usize,
    data_offset: u64,
}

fn parse_header(path: &Path, file: &mut impl Read, file_len: u64) -> Result<Header> {
    let corrupt = |d: String| LogError::corrupt(path, format!("not a valid .npy file: {d}"));
    let mut pre = [0u8; 8];
    file.read_exact(&mut pre).map_err(|_| corrupt("shorter than the 8-byte preamble".into()))?;
    if !pre.starts_with(NPY_MAGIC) {
        return Err(corrupt("no \\x93NUMPY magic".into()));
    }
    let (major, minor) = (pre[6], pre[7]);
    // NumPy reads versions 1.0, 2.0 and 3.0 only (`numpy.lib.format`), and so do we.
    let header_len = match if minor == 0 { major } else { 0 } {
        1 => {
            let mut b = [0u8; 2];
            file.read_exact(&mut b).map_err(|_| corrupt("truncated in the header length".into()))?;
            usize::from(u16::from_le_bytes(b))
        }
        2 | 3 => {
            let mut b = [0u8; 4];
            file.read_exact(&mut b).map_err(|_| corrupt("truncated in the header length".into()))?;
            usize::try_from(u32::from_le_bytes(b)).unwrap_or(usize::MAX)
        }
        _ => {
            return Err(corrupt(format!("format version {major}.{minor} is not 1.0, 2.0 or 3.0")));
        }
    };
    if header_len > MAX_HEADER_BYTES {
        return Err(corrupt(format!("header of {header_len} bytes (more than {MAX_HEADER_BYTES})")));
    }
    let mut text = vec![0u8; header_len];
    file.read_exact(&mut text).map_err(|_| corrupt(format!("truncated inside its {header_len}-byte header")))?;
    let mut parser = PyParser { s: &text, i: 0 };
    let Py::Dict(items) = parser.value(0).map_err(corrupt)? else {
        return Err(corrupt("the header is not a dict".into()));
    };
    // Exactly NumPy's three keys, each once: NumPy refuses another key, and of a key given twice
    // it would take the last (a `shape` given twice could describe the data two ways).
    let mut seen: Vec<&str> = Vec::new();
    for (key, _) in &items {
        let Py::Str(key) = key else { return Err(corrupt(format!("a header key that is not a string: {key:?}"))) };
        if !["descr", "fortran_order", "shape"].contains(&key.as_str()) {
            return Err(corrupt(format!(
                "the header has a key '{key}' (NumPy's format has exactly 'descr', 'fortran_order' and 'shape')"
            )));
        }
        if seen.contains(&key.as_str()) {
            return Err(corrupt(format!("the header gives '{key}' twice")));
        }
        seen.push(key);
    }
    let get = |key: &str| items.iter().find(|(k, _)| *k == Py::Str(key.into())).map(|(_, v)| v);
    let descr = match get("descr") {
        Some(Py::Str(s)) => s.clone(),
        Some(other) => {
            return Err(LogError::NpyDtype {
                file: path.to_path_buf(),
                dtype: format!("{other:?} (a structured dtype)"),
            });
        }
        None => return Err(corrupt("the header has no 'descr'".into())),
    };
    let dtype = match descr.as_str() {
        "<f8" => Dtype::F64 { little: true },
        ">f8" => Dtype::F64 { little: false },
        "<f4" => Dtype::F32 { little: true },
        ">f4" => Dtype::F32 { little: false },
        _ => {
            return Err(LogError::NpyDtype { file: path.to_path_buf(), dtype: descr });
        }
    };
    let fortran = match get("fortran_order") {
        Some(Py::Bool(b)) => *b,
        _ => return Err(corrupt("the header has no boolean 'fortran_order'".into())),
    };
    let dims: Vec<u64> =
        match get("shape") {
            Some(Py::Seq(items)) => items
                .iter()
                .map(|d| {
                    if let Py::Int(n) = d { Ok(*n) } else { Err(corrupt("a non-integer dimension in 'shape'".into())) }
                })
                .collect::<Result<_>>()?,
            _ => return Err(corrupt("the header has no tuple 'shape'".into())),
        };
    let shape_text = format!("({})", dims.iter().map(u64::to_string).collect::<Vec<_>>().join(", "));
    let shape_err = |expected: &str| LogError::Shape {
        file: path.to_path_buf(),
        shape: shape_text.clone(),
        expected: expected.into(),
    };
    let &[rows, cols] = dims.as_slice() else {
        return Err(shape_err("expected a 2-D array (N rows, C columns); reshape with a.reshape(len(a), -1)"));
    };
    if cols == 0 {
        return Err(shape_err("the array has no columns"));
    }
    if fortran && rows > 1 && cols > 1 {
        return Err(shape_err("the array is stored in Fortran (column-major) order; save np.ascontiguousarray(a)"));
    }
    let prefix = if major == 1 { 10 } else { 12 };
    let data_offset = prefix + header_len as u64;
    let needed = rows
        .checked_mul(cols)
        .and_then(|n| n.checked_mul(dtype.size() as u64))
        .ok_or_else(|| shape_err("the shape is too large to exist"))?;
    let present = file_len.saturating_sub(data_offset);
    if present != needed {
        let what = if present < needed { "the file is truncated" } else { "extra bytes follow the array" };
        return Err(corrupt(format!(
            "{what}: shape {shape_text} of {descr} needs {needed} data bytes, the file has {present} after its header"
        )));
    }
    Ok(Header { dtype, rows, cols: usize::try_from(cols).map_err(|_| shape_err("too many columns"))?, data_offset })
}

pub(crate) struct NpySource {
    path: PathBuf,
    reader: BufReader<File>,
    header: Header,
    names: Vec<String>,
    selected: Vec<usize>,
    buf: Vec<u8>,
    /// A block of rows read at once (`next_rows`).
    block: Vec<u8>,
    row: u64,
}

impl NpySource {
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let mut file = crate::io::files::open_input(path).map_err(|e| LogError::io(path, "cannot open", e))?;
        let len = file.metadata().map_err(|e| LogError::io(path, "cannot read", e))?.len();
        let header = parse_header(path, &mut BufReader::new(&mut file), len)?;
        file.seek(SeekFrom::Start(header.data_offset)).map_err(|e| LogError::io(path, "cannot read", e))?;
        if header.cols > 1 << 20 {
            return Err(LogError::Shape {
                file: path.to_path_buf(),
                shape: format!("({}, {})", header.rows, header.cols),
                expected: "at most 1048576 columns".into(),
            });
        }
        Ok(Self {
            path: path.to_path_buf(),
            reader: BufReader::with_capacity(1 << 16, file),
            names: (0..header.cols).map(|i| format!("index {i}")).collect(),
            buf: vec![0; header.cols * header.dtype.size()],
            block: Vec::new(),
            header,
            selected: Vec::new(),
            row: 0,
        })
    }
}

impl Source for NpySource {
    fn all_columns(&self) -> &[String] {
        &self.names
    }

    fn select(&mut self, indices: &[usize]) -> Result<()> {
        self.selected = indices.to_vec();
        Ok(())
    }

    fn next_row(&mut self, out: &mut [f64], exact: &mut [Option<i64>]) -> Result<bool> {
        if self.row >= self.header.rows {
            return Ok(false);
        }
        self.row += 1;
        self.reader.read_exact(&mut self.buf).map_err(|e| LogError::io(&self.path, "cannot read", e))?;
        let size = self.header.dtype.size();
        for (k, &col) in self.selected.iter().enumerate() {
            let bytes = self.buf.get(col * size..(col + 1) * size).unwrap_or(&[]);
            if let Some(o) = out.get_mut(k) {
                *o = self.header.dtype.read(bytes);
            }
            if let Some(e) = exact.get_mut(k) {
                *e = None;
            }
        }
        Ok(true)
    }

    fn selected_width(&self) -> usize {
        self.selected.len()
    }

    fn never_exact(&self) -> bool {
        true
    }

    fn next_rows(&mut self, out: &mut Vec<f64>, max_rows: usize) -> Result<usize> {
        let rows = (self.header.rows - self.row).min(max_rows as u64) as usize;
        if rows == 0 {
            return Ok(0);
        }
        let row_bytes = self.buf.len();
        let mut block = std::mem::take(&mut self.block);
        block.resize(rows * row_bytes, 0);
        let read = self.reader.read_exact(&mut block).map_err(|e| LogError::io(&self.path, "cannot read", e));
        let size = self.header.dtype.size();
        if read.is_ok() {
            out.reserve(rows * self.selected.len());
            let size_cols = row_bytes / size.max(1);
            if self.header.dtype == (Dtype::F64 { little: true }) && self.selected.iter().copied().eq(0..size_cols) {
                // Every column of little-endian f64 rows, in order (what numpy writes on every common
                // machine): the block is the values.
                out.extend(block.chunks_exact(8).map(|b| f64::from_le_bytes(b.try_into().unwrap_or([0; 8]))));
            } else {
                for r in block.chunks_exact(row_bytes) {
                    for &col in &self.selected {
                        out.push(self.header.dtype.read(r.get(col * size..(col + 1) * size).unwrap_or(&[])));
                    }
                }
            }
            self.row += rows as u64;
        }
        self.block = block;
        read.map(|()| rows)
    }

    fn location(&self) -> Location {
        Location { row: self.row, line: None }
    }

    fn rows_hint(&self) -> Option<u64> {
        Some(self.header.rows)
    }
}

/// Streams rows of f64 into a `.npy` (v1.0, `<f8`, C order) whose row count is patched at the end.
pub(crate) struct NpyWriter {
    out: BufWriter<File>,
    cols: usize,
    rows: u64,
    header_len: usize,
}

fn header_bytes(rows: u64, cols: usize, total: usize) -> Vec<u8> {
    let dict = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
    let mut h = Vec::with_capacity(total);
    h.extend_from_slice(NPY_MAGIC);
    h.extend_from_slice(&[1, 0]);
    let len = total.saturating_sub(10);
    h.extend_from_slice(&u16::try_from(len).unwrap_or(u16::MAX).to_le_bytes());
    h.extend_from_slice(dict.as_bytes());
    h.resize(total.saturating_sub(1), b' ');
    h.push(b'\n');
    h
}

impl NpyWriter {
    pub(crate) fn new(path: &Path, file: File, cols: usize) -> Result<Self> {
        // Room for the largest u64 row count; the total is a multiple of 64 as the format asks.
        let widest = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, {cols}), }}", u64::MAX);
        let header_len = (10 + widest.len() + 1).div_ceil(64) * 64;
        if header_len - 10 > usize::from(u16::MAX) {
            return Err(LogError::Output {
                file: path.to_path_buf(),
                problem: "too many columns for a .npy v1.0 header".into(),
            });
        }
        let mut out = BufWriter::with_capacity(1 << 16, file);
        out.write_all(&header_bytes(0, cols, header_len)).map_err(|e| LogError::io(path, "cannot write", e))?;
        Ok(Self { out, cols, rows: 0, header_len })
    }

    pub(crate) fn write_row(&mut self, path: &Path, row: &[f64]) -> Result<()> {
        debug_assert_eq!(row.len(), self.cols);
        for v in row {
            self.out.write_all(&v.to_le_bytes()).map_err(|e| LogError::io(path, "cannot write", e))?;
        }
        self.rows += 1;
        Ok(())
    }

    pub(crate) fn finish(mut self, path: &Path) -> Result<File> {
        let io = |e| LogError::io(path, "cannot write", e);
        self.out.flush().map_err(io)?;
        let mut file = self.out.into_inner().map_err(|e| LogError::io(path, "cannot write", e.into_error()))?;
        file.seek(SeekFrom::Start(0)).map_err(io)?;
        file.write_all(&header_bytes(self.rows, self.cols, self.header_len)).map_err(io)?;
        Ok(file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A version 1.x/2.x file as NumPy's format document lays it out: magic, version, the header
    /// length, the dict padded with spaces to a multiple of 64 bytes and ended by '\n', then zeros.
    fn by_hand(major: u8, minor: u8, dict: &str, data_bytes: usize) -> Vec<u8> {
        let len_bytes = if major == 1 { 2 } else { 4 };
        let mut header = dict.to_owned();
        while !(6 + 2 + len_bytes + header.len() + 1).is_multiple_of(64) {
            header.push(' ');
        }
        header.push('\n');
        let mut b = b"\x93NUMPY".to_vec();
        b.extend([major, minor]);
        if major == 1 {
            b.extend((header.len() as u16).to_le_bytes());
        } else {
            b.extend((header.len() as u32).to_le_bytes());
        }
        b.extend(header.bytes());
        b.extend(std::iter::repeat_n(0u8, data_bytes));
        b
    }

    #[test]
    fn a_header_numpy_would_refuse_or_read_otherwise_is_refused() {
        let parse =
            |b: Vec<u8>| parse_header(Path::new("x.npy"), &mut &b[..], b.len() as u64).map_err(|e| e.to_string());
        let good = "{'descr': '<f8', 'fortran_order': False, 'shape': (4, 7), }";
        for (major, minor) in [(1, 0), (2, 0), (3, 0)] {
            let h = parse(by_hand(major, minor, good, 4 * 7 * 8)).expect("NumPy's own versions");
            assert_eq!((h.rows, h.cols), (4, 7));
        }
        // NumPy 2.x: "we only support format version (1,0), (2,0), and (3,0), not (1, 90)".
        for (major, minor) in [(1, 90), (2, 1), (4, 0)] {
            let e = parse(by_hand(major, minor, good, 4 * 7 * 8)).expect_err("another version");
            assert!(e.contains(&format!("format version {major}.{minor}")), "{e}");
        }
        // A key given twice (NumPy would take the last: 9 rows of which the file has 4) or a key
        // NumPy's format does not have ("Header does not contain the correct keys").
        let twice = "{'descr': '<f8', 'fortran_order': False, 'shape': (4, 7), 'shape': (9, 7), }";
        assert!(parse(by_hand(1, 0, twice, 4 * 7 * 8)).expect_err("twice").contains("gives 'shape' twice"));
        let extra = "{'descr': '<f8', 'fortran_order': False, 'shape': (4, 7), 'units': 'rad', }";
        assert!(parse(by_hand(1, 0, extra, 4 * 7 * 8)).expect_err("extra key").contains("a key 'units'"));
    }

    #[test]
    fn header_is_aligned_and_parses() {
        let h = header_bytes(123, 7, 128);
        assert_eq!(h.len(), 128);
        assert_eq!(h.last(), Some(&b'\n'));
        let mut data = h.clone();
        data.extend(std::iter::repeat_n(0u8, 123 * 7 * 8));
        let header = parse_header(Path::new("x.npy"), &mut &data[..], data.len() as u64).unwrap();
        assert_eq!((header.rows, header.cols, header.data_offset), (123, 7, 128));
    }

    #[test]
    fn python_literals() {
        let mut p = PyParser { s: b"{'descr': '<f4', 'fortran_order': False, 'shape': (10L, 3), }", i: 0 };
        let Py::Dict(items) = p.value(0).unwrap() else { panic!() };
        assert_eq!(items.len(), 3);
        assert_eq!(items[2].1, Py::Seq(vec![Py::Int(10), Py::Int(3)]));
        let mut deep = PyParser { s: &[b'('; 100], i: 0 };
        assert!(deep.value(0).is_err());
    }
}
