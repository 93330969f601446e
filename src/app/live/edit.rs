//! Writing one value of a scenario file in place, keeping the user's comments and layout
//! (`toml_edit`), atomically (temporary file + rename) so the watcher never reads half a file.

use std::fmt;
use std::path::Path;

use toml_edit::{DocumentMut, Item, Table, TableLike, Value};

use crate::io::files::rewrite_input;

/// One step of a key path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Seg {
    /// A table key.
    Key(String),
    /// An index into an array of tables.
    Index(usize),
}

/// A dotted key path such as `turntable.axis[1].swing_half_angle_arcsec`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyPath(pub Vec<Seg>);

impl KeyPath {
    /// Parses `a.b[2].c`.
    #[must_use]
    pub fn parse(s: &str) -> Self {
        let mut segs = Vec::new();
        for part in s.split('.') {
            let (name, rest) = part.split_once('[').map_or((part, None), |(n, r)| (n, Some(r)));
            segs.push(Seg::Key(name.to_owned()));
            if let Some(r) = rest
                && let Ok(i) = r.trim_end_matches(']').parse()
            {
                segs.push(Seg::Index(i));
            }
        }
        Self(segs)
    }
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, s) in self.0.iter().enumerate() {
            match s {
                Seg::Key(k) if i == 0 => write!(f, "{k}")?,
                Seg::Key(k) => write!(f, ".{k}")?,
                Seg::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

/// Why a value could not be written.
#[derive(Debug, thiserror::Error)]
pub enum EditError {
    /// Reading the file.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Writing the file.
    #[error(transparent)]
    Write(#[from] crate::io::files::OutputError),
    /// The file is not valid TOML (the user is mid-edit); the slider waits.
    #[error("{path} is not valid TOML right now ({message}); not writing")]
    Syntax {
        /// The file.
        path: String,
        /// toml_edit's message.
        message: String,
    },
    /// The key path does not lead to a value.
    #[error("{path}: no place for `{key}` in the file")]
    Missing {
        /// The file.
        path: String,
        /// The key path.
        key: String,
    },
}

/// Sets `key` to `value` in the TOML text, creating missing tables; keeps the old value's comment.
pub fn set_in_text(text: &str, key: &KeyPath, value: Value) -> Result<String, String> {
    let mut doc: DocumentMut = text.parse().map_err(|e: toml_edit::TomlError| e.to_string())?;
    let Some((Seg::Key(last), parents)) = key.0.split_last() else {
        return Err("a key path must end with a key".into());
    };
    let mut table: &mut dyn TableLike = doc.as_table_mut();
    let mut i = 0;
    while i < parents.len() {
        let Seg::Key(k) = &parents[i] else {
            return Err(format!("misplaced index in `{key}`"));
        };
        let current = table;
        if let Some(Seg::Index(n)) = parents.get(i + 1) {
            let array = current
                .get_mut(k)
                .and_then(Item::as_array_of_tables_mut)
                .ok_or_else(|| format!("`{k}` is not an array of tables"))?;
            table = array.get_mut(*n).ok_or_else(|| format!("`{k}` has no entry [{n}]"))?;
            i += 2;
        } else {
            if current.get(k).is_none() {
                // Implicit: a table that only holds tables gets no header of its own
                // (`[compensation.axis.inner]`, not an empty `[compensation.axis]` above it).
                let mut t = Table::new();
                t.set_implicit(true);
                current.insert(k, Item::Table(t));
            }
            table =
                current.get_mut(k).and_then(Item::as_table_like_mut).ok_or_else(|| format!("`{k}` is not a table"))?;
            i += 1;
        }
    }
    let mut value = value;
    if let Some(old) = table.get(last).and_then(Item::as_value) {
        *value.decor_mut() = old.decor().clone();
    }
    table.insert(last, Item::Value(value));
    Ok(doc.to_string())
}

/// Sets `key` to `value` in the file at `path`, atomically.
///
/// # Errors
/// The file cannot be read or written, is not valid TOML right now, or has no place for `key`.
pub fn set_in_file(path: &Path, key: &KeyPath, value: Value) -> Result<(), EditError> {
    set_many_in_file(path, &[(key.clone(), value)])
}

/// Sets every key of `writes` in the file at `path`, atomically and at once (one reload for a
/// control that writes several keys, or "calibrate now").
///
/// # Errors
/// As [`set_in_file`]; nothing is written unless every key could be set.
pub fn set_many_in_file(path: &Path, writes: &[(KeyPath, Value)]) -> Result<(), EditError> {
    let shown = path.display().to_string();
    let mut text = super::read_text(path).map_err(|source| EditError::Io { path: shown.clone(), source })?;
    for (key, value) in writes {
        text = set_in_text(&text, key, value.clone()).map_err(|message| {
            if message.contains("TOML parse error") || message.contains("expected") {
                EditError::Syntax { path: shown.clone(), message }
            } else {
                EditError::Missing { path: shown.clone(), key: key.to_string() }
            }
        })?;
    }
    Ok(rewrite_input(path, text.as_bytes())?)
}

/// A value a control writes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scalar {
    /// A number (written as a TOML float).
    Float(f64),
    /// On / off.
    Bool(bool),
}

impl Scalar {
    /// As a TOML value.
    #[must_use]
    pub fn to_value(self) -> Value {
        match self {
            Self::Float(x) => float(x),
            Self::Bool(b) => Value::from(b),
        }
    }
}

/// A TOML float that prints as a float even when whole (`600.0`, not `600`).
#[must_use]
pub fn float(x: f64) -> Value {
    // Round to 6 significant decimals so that slider steps do not print binary noise.
    let r = (x * 1e6).round() / 1e6;
    Value::from(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "# a scenario\n[turntable]\ninstallation_x_arcsec = 0.0   # tilt, arcsec\n\n[[turntable.axis]]\nname = \"outer\"\nswing_half_angle_arcsec = 600.0 # alpha2\n\n[[turntable.axis]]\nname = \"inner\"\nswing_half_angle_arcsec = 300.0 # alpha1 - keep me\n";

    #[test]
    fn setting_a_value_keeps_comments_and_layout() {
        let key = KeyPath::parse("turntable.axis[1].swing_half_angle_arcsec");
        assert_eq!(key.to_string(), "turntable.axis[1].swing_half_angle_arcsec");
        let out = set_in_text(TEXT, &key, float(450.0)).expect("edit");
        assert!(out.contains("swing_half_angle_arcsec = 450.0 # alpha1 - keep me"), "{out}");
        assert!(out.contains("swing_half_angle_arcsec = 600.0 # alpha2"));
        assert!(out.starts_with("# a scenario\n"));
        // Nothing else changed.
        assert_eq!(out.replace("450.0", "300.0"), TEXT);
    }

    #[test]
    fn missing_tables_and_keys_are_created() {
        let out = set_in_text(TEXT, &KeyPath::parse("live.speed"), float(20.0)).expect("edit");
        let parsed: toml::Value = toml::from_str(&out).expect("valid");
        assert_eq!(parsed["live"]["speed"].as_float(), Some(20.0));
        let out = set_in_text(&out, &KeyPath::parse("compensation.enabled"), Value::from(false)).expect("edit");
        let parsed: toml::Value = toml::from_str(&out).expect("valid");
        assert_eq!(parsed["compensation"]["enabled"].as_bool(), Some(false));
    }

    #[test]
    fn broken_text_is_not_overwritten() {
        assert!(set_in_text("[turntable\nx = ", &KeyPath::parse("turntable.x"), float(1.0)).is_err());
    }
}
