//! Layer 0, files: writing outputs so that a reader never sees a half-written file.

pub mod files;
