//! The results folder: its format written once (`files`), and the writers and readers of its files. Nothing
//! here measures anything.

pub mod answer;
pub mod clips;
pub mod csv;
pub mod engines;
pub mod files;
pub mod manifest;
pub mod png;
