//! `lodbench answer DIR`: a results folder's answer (`results::answer`) written as answer.json from its CSVs and
//! printed: for a folder made before answer.json was, or after its perceptual.csv changed.

use crate::cli::AnswerArgs;
use crate::error::Result;
use crate::results::answer::{sentences_text, write};
use crate::results::files::ANSWER_JSON;

/// `lodbench answer`.
pub fn execute(args: &AnswerArgs) -> Result<()> {
    let answer = write(&args.dir)?;
    out!("{}", sentences_text(&answer).trim_start());
    outln!("answer in {}", args.dir.join(ANSWER_JSON).display());
    Ok(())
}
