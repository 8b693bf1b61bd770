//! The `lodbench` binary: parse flags, dispatch to `lodbench::commands`, print one line on error.

use lodbench::cli::{Cli, Command};
use lodbench::commands::{
    answer, calibrate, clips, compare, describe, experiment, export, list, merge, overhead,
    perceptual, probe, run, score, tune,
};
use lodbench::Error;
use std::process::ExitCode;

fn main() -> ExitCode {
    // Cli::parse, and the flags a subcommand hides refused (tune's, `Cli::try_parse_checked_from`).
    let cli = Cli::parse_checked();
    quiet_wayland_probe();
    let result = match cli.command {
        Command::Run(args) => run::execute(&args),
        Command::List => list::execute(),
        Command::Describe(args) => describe::execute(&args),
        Command::Export(args) => export::execute(&args),
        Command::Experiment(args) => experiment::execute(&args),
        Command::Merge(args) => merge::execute(&args),
        Command::Compare(args) => compare::execute(&args),
        Command::Answer(args) => answer::execute(&args),
        Command::Perceptual(args) => perceptual::execute(&args),
        Command::Clips(args) => clips::execute(&args),
        Command::Tune(args) => tune::execute(&args),
        Command::Calibrate(args) => calibrate::execute(&args),
        Command::Score(args) => score::execute(&args),
        Command::Probe(args) => probe::execute(&args),
        Command::Overhead(args) => overhead::execute(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Error::Interrupted) => {
            eprintln!("error: interrupted; run.json says so and frames.csv.partial keeps the finished blocks");
            ExitCode::from(130)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Mesa's Vulkan loader probes for a Wayland display and prints `error: XDG_RUNTIME_DIR is invalid...` when
/// the variable is unset (headless machines, CI), which reads like one of our errors. Point it at the temp
/// folder for this process only; nothing is created there.
fn quiet_wayland_probe() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
}
