//! One file per subcommand: what `lodbench run`, `experiment`, `merge`, `clips` and `perceptual` do, from a
//! checked configuration to a results folder.

pub mod clips;
pub mod experiment;
pub mod merge;
pub mod perceptual;
pub mod run;
