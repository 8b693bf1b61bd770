//! Exporters: turn measurement structs into files. Nothing here measures anything.

pub mod csv;
pub mod manifest;
pub mod png;
