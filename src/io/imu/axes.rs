//! Body-frame axis conventions and their conversion to rinscope's sensor frame, RFU.
//!
//! rinscope's sensor frame is **RFU**: x points Right, y Forward, z Up (the convention of PSINS and
//! of many Chinese INS texts). A file's frame is named by three letters, one per axis x, y, z, each
//! the direction that axis points: **F**orward, **B**ack, **R**ight, **L**eft, **U**p, **D**own.
//!
//! | name | x | y | z | used by |
//! |---|---|---|---|---|
//! | `rfu` | right | forward | up | rinscope, PSINS |
//! | `frd` | forward | right | down | KF-GINS, aerospace body axes |
//! | `flu` | forward | left | up | ROS REP 103 body frames |
//! | `rbd`, `lfd`, `bru`, ... | | | | any of the 24 right-handed triads |
//!
//! Aliases, for a level vehicle heading north whose body axes coincide with a local-level frame:
//! `enu` = `rfu`, `ned` = `frd`, `nwu` = `flu`. Names are case-insensitive.
//!
//! The matrix `C` returned by [`frame_matrix`] maps a vector given in the file's axes onto RFU:
//! `v_rfu = C · v_file`. Its columns are the file's x, y, z axes written in RFU. An explicit
//! matrix ([`Frame::Matrix`]) has the same meaning and must be a proper rotation.

use crate::io::error::FrameError;
use nalgebra::{Matrix3, Vector3};

/// A body frame: by name, or the explicit matrix `C` with `v_rfu = C · v_file`.
#[derive(Debug, Clone, PartialEq)]
pub enum Frame {
    /// Three axis letters (`"frd"`) or an alias (`"ned"`); see the module docs.
    Named(String),
    /// `C` with `v_rfu = C · v_file`; must be orthonormal with determinant +1 (to 1e-6).
    Matrix(Matrix3<f64>),
}

impl Frame {
    /// The matrix `C` with `v_rfu = C · v_file`.
    ///
    /// # Errors
    /// An unknown or left-handed name, or a matrix that is not a rotation.
    pub fn to_rfu(&self) -> Result<Matrix3<f64>, FrameError> {
        match self {
            Self::Named(name) => frame_matrix(name),
            Self::Matrix(m) => {
                let orthonormality_error = (m.transpose() * m - Matrix3::identity()).abs().max();
                let determinant = m.determinant();
                // Written so that a NaN anywhere fails too.
                if !(m.iter().all(|x| x.is_finite())
                    && orthonormality_error <= 1e-6
                    && (determinant - 1.0).abs() <= 1e-6)
                {
                    return Err(FrameError::NotARotation { orthonormality_error, determinant });
                }
                Ok(*m)
            }
        }
    }
}

/// The direction an axis letter stands for, in RFU.
fn axis(letter: char) -> Option<Vector3<f64>> {
    Some(match letter {
        'r' => Vector3::new(1.0, 0.0, 0.0),
        'l' => Vector3::new(-1.0, 0.0, 0.0),
        'f' => Vector3::new(0.0, 1.0, 0.0),
        'b' => Vector3::new(0.0, -1.0, 0.0),
        'u' => Vector3::new(0.0, 0.0, 1.0),
        'd' => Vector3::new(0.0, 0.0, -1.0),
        _ => return None,
    })
}

fn direction_word(v: &Vector3<f64>) -> &'static str {
    const WORDS: [(&str, [f64; 3]); 6] = [
        ("right", [1.0, 0.0, 0.0]),
        ("left", [-1.0, 0.0, 0.0]),
        ("forward", [0.0, 1.0, 0.0]),
        ("back", [0.0, -1.0, 0.0]),
        ("up", [0.0, 0.0, 1.0]),
        ("down", [0.0, 0.0, -1.0]),
    ];
    WORDS.iter().find(|(_, d)| (Vector3::from(*d) - v).norm() < 1e-9).map_or("nowhere", |(w, _)| *w)
}

/// The matrix `C` that maps a vector in the named frame onto rinscope's RFU frame, `v_rfu = C · v`.
///
/// `name` is three axis letters (see the module docs), e.g. `frd`: x forward, y right, z down,
/// for which a rotation about the forward axis, `(1, 0, 0)` in FRD, becomes `(0, 1, 0)` in RFU.
///
/// # Errors
/// [`FrameError`] for an unknown name, a repeated axis, or a left-handed triad.
pub fn frame_matrix(name: &str) -> Result<Matrix3<f64>, FrameError> {
    let lower = name.trim().to_ascii_lowercase();
    let letters = match lower.as_str() {
        "enu" => "rfu",
        "ned" => "frd",
        "nwu" => "flu",
        other => other,
    };
    let unknown = || FrameError::UnknownName { name: name.to_owned() };
    let mut cols = [Vector3::zeros(); 3];
    let mut count = 0;
    for (i, c) in letters.chars().enumerate() {
        if i >= 3 {
            return Err(unknown());
        }
        cols[i] = axis(c).ok_or_else(unknown)?;
        count += 1;
    }
    if count != 3 {
        return Err(unknown());
    }
    for i in 0..3 {
        for j in (i + 1)..3 {
            if cols[i].dot(&cols[j]).abs() > 0.5 {
                return Err(FrameError::RepeatedAxis { name: name.to_owned() });
            }
        }
    }
    let cross = cols[0].cross(&cols[1]);
    if cross.dot(&cols[2]) < 0.0 {
        return Err(FrameError::LeftHanded { name: name.to_owned(), z_would_be: direction_word(&cross) });
    }
    Ok(Matrix3::from_columns(&cols))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_right_handed_triads_are_rotations() {
        let letters = ['f', 'b', 'r', 'l', 'u', 'd'];
        let mut ok = 0;
        for a in letters {
            for b in letters {
                for c in letters {
                    let name: String = [a, b, c].iter().collect();
                    if let Ok(m) = frame_matrix(&name) {
                        assert!((m.determinant() - 1.0).abs() < 1e-12, "{name}");
                        ok += 1;
                    }
                }
            }
        }
        // 6 choices for x × 4 for y, z then fixed by handedness: 24 proper rotations.
        assert_eq!(ok, 24);
    }

    #[test]
    fn errors() {
        assert!(matches!(frame_matrix("xyz"), Err(FrameError::UnknownName { .. })));
        assert!(matches!(frame_matrix("frdu"), Err(FrameError::UnknownName { .. })));
        assert!(matches!(frame_matrix("fr"), Err(FrameError::UnknownName { .. })));
        assert!(matches!(frame_matrix("ffd"), Err(FrameError::RepeatedAxis { .. })));
        assert!(matches!(frame_matrix("fbd"), Err(FrameError::RepeatedAxis { .. })));
        // F × R = down in a right-handed world, so "fru" is left-handed.
        assert!(matches!(frame_matrix("fru"), Err(FrameError::LeftHanded { z_would_be: "down", .. })));
        let shear = Matrix3::new(1.0, 0.1, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(matches!(Frame::Matrix(shear).to_rfu(), Err(FrameError::NotARotation { .. })));
    }
}
