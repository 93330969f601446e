//! Writers: bit-exact round trips through each format, and the partial-file discipline.

use crate::common::*;
use rinscope::io::{Col, ColumnReader, LogError, ReadOptions, TableWriter};
use std::path::Path;

const COLUMNS: [&str; 4] = ["t_s", "att_roll_deg", "pos_h_m", "gyro_bias_x_deg_per_h"];

/// Awkward f64s: signed zeros, subnormals, extremes, values with long shortest representations.
fn tricky_rows(n: usize) -> Vec<[f64; 4]> {
    let specials =
        [0.0, -0.0, f64::MIN_POSITIVE, 5e-324, f64::MAX, -f64::MAX, 1.0 / 3.0, 0.1 + 0.2, 1e-7, 123_456_789.123_456_78];
    (0..n)
        .map(|i| {
            let x = i as f64;
            [x * 0.005, specials[i % specials.len()], (x * 0.7).sin() * 1e3, -(x + 0.5).ln()]
        })
        .collect()
}

fn read_back(path: &Path) -> Vec<[f64; 4]> {
    let cols: Vec<Col> = (0..4).map(Col::Index).collect();
    let mut reader = ColumnReader::open(path, &cols, &ReadOptions::default()).unwrap();
    let mut out = Vec::new();
    let mut row = [0.0; 4];
    while reader.next_row(&mut row).unwrap() {
        out.push(row);
    }
    out
}

#[test]
fn round_trips_are_bit_identical() {
    let dir = scratch("roundtrip");
    // 150 000 rows: three Parquet row groups (65 536 + 65 536 + 18 928).
    let rows = tricky_rows(150_000);
    for name in ["t.csv", "t.npy", "t.parquet"] {
        let path = dir.join(name);
        let mut w = TableWriter::create(&path, &COLUMNS).unwrap();
        for r in &rows {
            w.write_row(r).unwrap();
        }
        assert_eq!(w.finish().unwrap(), rows.len() as u64);
        assert!(!dir.join(format!("{name}.partial")).exists());
        let back = read_back(&path);
        assert_eq!(back.len(), rows.len(), "{name}");
        for (i, (a, b)) in back.iter().zip(&rows).enumerate() {
            for k in 0..4 {
                assert_eq!(a[k].to_bits(), b[k].to_bits(), "{name} row {i} col {k}: {} vs {}", a[k], b[k]);
            }
        }
    }
    let names = ColumnReader::open(dir.join("t.parquet"), &[], &ReadOptions::default()).unwrap().all_columns().to_vec();
    assert_eq!(names, COLUMNS);
    let meta = parquet::file::reader::FileReader::metadata(
        &parquet::file::serialized_reader::SerializedFileReader::new(
            std::fs::File::open(dir.join("t.parquet")).unwrap(),
        )
        .unwrap(),
    )
    .clone();
    assert_eq!(meta.num_row_groups(), 3);
    assert_eq!(meta.row_group(0).num_rows(), 65_536);
    let csv_head = std::fs::read_to_string(dir.join("t.csv")).unwrap();
    assert!(csv_head.starts_with("t_s,att_roll_deg,pos_h_m,gyro_bias_x_deg_per_h\n0,0,0,"), "{}", &csv_head[..80]);
}

#[test]
fn empty_table_round_trips() {
    let dir = scratch("empty_tables");
    for name in ["e.csv", "e.npy", "e.parquet"] {
        let path = dir.join(name);
        TableWriter::create(&path, &COLUMNS).unwrap().finish().unwrap();
        assert!(read_back(&path).is_empty(), "{name}");
    }
}

#[test]
fn partial_file_discipline() {
    let dir = scratch("partial");
    let path = dir.join("out.csv");
    std::fs::write(&path, "old contents\n").unwrap();
    // An abandoned writer leaves no partial and the old file untouched.
    let mut w = TableWriter::create(&path, &COLUMNS).unwrap();
    w.write_row(&[0.0, 1.0, 2.0, 3.0]).unwrap();
    assert!(dir.join("out.csv.partial").exists());
    drop(w);
    assert!(!dir.join("out.csv.partial").exists());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "old contents\n");
    // A failed write (wrong row length) then finish: error, partial removed, old file kept.
    let mut w = TableWriter::create(&path, &COLUMNS).unwrap();
    assert!(matches!(w.write_row(&[1.0]), Err(LogError::Shape { .. })));
    assert!(w.finish().is_err());
    assert!(!dir.join("out.csv.partial").exists());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "old contents\n");
    // A partial another writer holds is refused and left alone; one a crash left (unlocked) is
    // started afresh.
    let mut other = TableWriter::create(&path, &COLUMNS).unwrap();
    other.write_row(&[0.0, 1.0, 2.0, 3.0]).unwrap();
    let e = TableWriter::create(&path, &COLUMNS).unwrap_err();
    assert!(
        e.to_string().starts_with(&path.display().to_string()) && e.to_string().contains("another run is writing"),
        "{e}"
    );
    assert!(dir.join("out.csv.partial").exists());
    drop(other);
    std::fs::write(dir.join("out.csv.partial"), "a crashed run's bytes").unwrap();
    let mut w = TableWriter::create(&path, &COLUMNS).unwrap();
    w.write_row(&[0.0, 1.0, 2.0, 3.0]).unwrap();
    drop(w);
    assert!(!dir.join("out.csv.partial").exists());
    // A symlink as the partial is refused and never followed.
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, "precious").unwrap();
    std::os::unix::fs::symlink(&victim, dir.join("out.csv.partial")).unwrap();
    let e = TableWriter::create(&path, &COLUMNS).unwrap_err();
    assert!(e.to_string().contains("is a symlink"), "{e}");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    std::fs::remove_file(dir.join("out.csv.partial")).unwrap();
    // A symlink as the target is refused too.
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    assert!(TableWriter::create(&link, &COLUMNS).is_err());
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    // A finished writer replaces the old file.
    let mut w = TableWriter::create(&path, &COLUMNS).unwrap();
    w.write_row(&[0.0, 1.0, 2.0, 3.0]).unwrap();
    w.finish().unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "t_s,att_roll_deg,pos_h_m,gyro_bias_x_deg_per_h\n0,1,2,3\n");
}

#[test]
fn column_names_are_checked() {
    let dir = scratch("names");
    let p = dir.join("x.csv");
    assert!(TableWriter::create(&p, &["time", "a_m"]).is_err(), "t_s must be first");
    assert!(TableWriter::create(&p, &["t_s", "roll"]).is_err(), "no unit");
    assert!(TableWriter::create(&p, &["t_s", "a b_m"]).is_err(), "bad character");
    assert!(TableWriter::create(&p, &["t_s", "a_m", "a_m"]).is_err(), "duplicate");
    assert!(TableWriter::create(dir.join("x.mcap"), &["t_s"]).is_err(), "no MCAP writer");
    // A table that is not a time series (an Allan curve, fitted coefficients): any key first, any
    // names, but still plain characters, each once.
    let keyed = dir.join("k.csv");
    assert!(TableWriter::create_keyed(&keyed, &["axis", "n_deg_per_sqrt_h", "edf"]).is_ok_and(|w| w.finish().is_ok()));
    assert_eq!(std::fs::read_to_string(&keyed).expect("written"), "axis,n_deg_per_sqrt_h,edf\n");
    assert!(TableWriter::create_keyed(&p, &["tau s"]).is_err(), "bad character");
    assert!(TableWriter::create_keyed(&p, &["tau_s", "edf", "edf"]).is_err(), "duplicate");
    assert!(TableWriter::create_keyed(&p, &[]).is_err(), "no column");
    assert!(!dir.join("x.csv.partial").exists());
}
