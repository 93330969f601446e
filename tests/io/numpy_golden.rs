//! .npy files written by NumPy itself (tests/data, see its README: NumPy 2.4.6 `np.save`).

use rinscope::io::{Col, ColumnReader, Frame, ImuOptions, ImuReader, Layout, LogError, ReadOptions, TimeUnit};
use std::path::PathBuf;

/// The array the golden files were saved from (tests/data/README.md).
const A: [[f64; 7]; 3] = [
    [0.0, 1e-5, -2e-5, 3e-5, 0.001, -0.002, 0.0490332],
    [0.005, 1.5e-5, -2.5e-5, 3.5e-5, 0.0011, -0.0021, 0.0490333],
    [0.01, 2e-5, -3e-5, 4e-5, 0.0012, -0.0022, 0.0490334],
];

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn read(name: &str) -> rinscope::io::Result<Vec<[f64; 7]>> {
    let cols: Vec<Col> = (0..7).map(Col::Index).collect();
    let mut r = ColumnReader::open(data(name), &cols, &ReadOptions::default())?;
    let mut out = Vec::new();
    let mut row = [0.0; 7];
    while r.next_row(&mut row)? {
        out.push(row);
    }
    Ok(out)
}

#[test]
fn numpy_written_files() {
    assert_eq!(read("numpy_f8.npy").unwrap(), A);
    assert_eq!(read("numpy_be_f8.npy").unwrap(), A);
    let f4 = read("numpy_f4.npy").unwrap();
    for (r, a) in f4.iter().zip(&A) {
        for k in 0..7 {
            assert_eq!(r[k], f64::from(a[k] as f32), "f32 widens exactly");
        }
    }
    assert!(matches!(read("numpy_fortran.npy"), Err(LogError::Shape { .. })));
    assert!(matches!(read("numpy_i8.npy"), Err(LogError::NpyDtype { .. })));
    // As an N×7 increments log (time in s, rad, m/s): 200 Hz, 0.049 m/s ≈ 9.8 m/s² × 5 ms.
    let mut opts = ImuOptions::new(Layout::Npy7 { time: TimeUnit::Seconds });
    opts.frame = Some(Frame::Named("rfu".into()));
    let n = ImuReader::open(data("numpy_f8.npy"), &opts).unwrap().count();
    assert_eq!(n, 3);
}
