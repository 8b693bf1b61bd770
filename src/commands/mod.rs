//! One file per subcommand: what `lodbench run`, `experiment`, `merge`, `compare`, `answer`, `clips`, `perceptual`,
//! `list`, `describe`, `export`, `tune`, `calibrate`, `score`, `probe` and `overhead` do, from the parsed flags to a results folder or a printed report. Each file's `execute` is what
//! the binary calls.

/// `print!` / `println!` to stdout that give up quietly when stdout is gone (`lodbench describe ... | head`):
/// a closed pipe is no error of lodbench's, and `print!` would panic on it.
macro_rules! out {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($t)*);
    }};
}
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}
// Defined before the modules, so every subcommand's file has them in scope.

pub mod answer;
pub mod calibrate;
pub mod clips;
pub mod compare;
pub mod describe;
pub mod experiment;
pub mod export;
pub mod list;
pub mod merge;
pub mod overhead;
pub mod perceptual;
pub mod probe;
pub mod run;
pub mod score;
pub mod tune;
