//! frames.csv, summary.csv, transitions.csv, rounds.csv and pairs.csv: serialisation only (the records are `crate::measure::records`). frames.csv is written as
//! `frames.csv.partial`, flushed after each block, and renamed to `frames.csv` only when the run completes, so
//! an interrupted run keeps what it measured without leaving a file that looks complete.

use crate::error::{Error, Result};
use crate::measure::records::{
    EventRecord, FrameRecord, FrameTimes, PairRecord, RoundRecord, SummaryRecord, TransitionRecord,
};
use std::fs::File;
use std::path::{Path, PathBuf};

use super::files::partial;
pub use super::files::{
    EVENTS_CSV, FRAMES_CSV, PAIRS_CSV, PARTIAL_SUFFIX, ROUNDS_CSV, SUMMARY_CSV, TRANSITIONS_CSV,
};

/// Appends frame rows to `frames.csv.partial`; `finish` renames it to `frames.csv`.
pub struct FramesWriter {
    writer: ::csv::Writer<File>,
    partial: PathBuf,
    done: PathBuf,
}

impl FramesWriter {
    pub fn create(dir: &Path) -> Result<FramesWriter> {
        let done = dir.join(FRAMES_CSV);
        let partial = dir.join(partial(FRAMES_CSV));
        let file = File::create(&partial).map_err(|e| Error::io(&partial, e))?;
        Ok(FramesWriter {
            writer: ::csv::Writer::from_writer(file),
            partial,
            done,
        })
    }

    pub fn write_block(&mut self, rows: &[FrameRecord]) -> Result<()> {
        for r in rows {
            self.writer.serialize(r)?;
        }
        self.writer.flush().map_err(|e| Error::io(&self.partial, e))
    }

    pub fn finish(mut self) -> Result<PathBuf> {
        self.writer
            .flush()
            .map_err(|e| Error::io(&self.partial, e))?;
        drop(self.writer);
        std::fs::rename(&self.partial, &self.done).map_err(|e| Error::io(&self.done, e))?;
        Ok(self.done)
    }
}

/// Writes `rows` to `name` in `dir` through a temporary file, so it appears whole or not at all.
pub fn write_whole<T: serde::Serialize>(dir: &Path, name: &str, rows: &[T]) -> Result<PathBuf> {
    let path = dir.join(name);
    let tmp = dir.join(partial(name));
    {
        let file = File::create(&tmp).map_err(|e| Error::io(&tmp, e))?;
        let mut w = ::csv::Writer::from_writer(file);
        for r in rows {
            w.serialize(r)?;
        }
        w.flush().map_err(|e| Error::io(&tmp, e))?;
    }
    std::fs::rename(&tmp, &path).map_err(|e| Error::io(&path, e))?;
    Ok(path)
}

/// Writes summary.csv (whole or not at all).
pub fn write_summary(dir: &Path, rows: &[SummaryRecord]) -> Result<PathBuf> {
    write_whole(dir, SUMMARY_CSV, rows)
}

/// Writes events.csv (whole or not at all).
pub fn write_events(dir: &Path, rows: &[EventRecord]) -> Result<PathBuf> {
    write_whole(dir, EVENTS_CSV, rows)
}

/// Writes transitions.csv (whole or not at all).
pub fn write_transitions(dir: &Path, rows: &[TransitionRecord]) -> Result<PathBuf> {
    write_whole(dir, TRANSITIONS_CSV, rows)
}

/// The transitions.csv of the run folder `dir` (what `lodbench perceptual` and `lodbench clips` start from);
/// its absence is one error naming the folder.
pub fn read_transitions(dir: &Path) -> Result<Vec<TransitionRecord>> {
    let path = dir.join(TRANSITIONS_CSV);
    if !path.is_file() {
        return Err(Error::results(
            dir,
            "has no transitions.csv (a complete lodbench run, made with this version?)",
        ));
    }
    Ok(::csv::Reader::from_path(&path)?
        .deserialize::<TransitionRecord>()
        .collect::<std::result::Result<Vec<_>, _>>()?)
}

/// Writes rounds.csv (whole or not at all).
pub fn write_rounds(dir: &Path, rows: &[RoundRecord]) -> Result<PathBuf> {
    write_whole(dir, ROUNDS_CSV, rows)
}

/// Writes pairs.csv (whole or not at all).
pub fn write_pairs(dir: &Path, rows: &[PairRecord]) -> Result<PathBuf> {
    write_whole(dir, PAIRS_CSV, rows)
}

/// frames.csv of a run or experiment folder read back for its timing: the names of the columns before `scene`
/// (a merged or experiment folder's swept variable and `adapter`; none in a run folder) and, per row, their
/// values with the row's times. A folder without frames.csv is one error naming it.
pub struct FramesTimes {
    pub lead_header: Vec<String>,
    pub rows: Vec<(Vec<String>, FrameTimes)>,
}

/// Reads `dir/frames.csv` as [`FramesTimes`].
pub fn read_frame_times(dir: &Path) -> Result<FramesTimes> {
    if !dir.is_dir() {
        return Err(Error::results(dir, "does not exist or is not a folder"));
    }
    let path = dir.join(FRAMES_CSV);
    if !path.is_file() {
        return Err(Error::results(
            dir,
            "has no frames.csv (a complete lodbench run or merged experiment?)",
        ));
    }
    let mut r = ::csv::Reader::from_path(&path)?;
    let header = r.headers()?.clone();
    let lead = header.iter().position(|h| h == "scene").ok_or_else(|| {
        Error::results(
            dir,
            "frames.csv has no scene column (not lodbench's frames.csv?)",
        )
    })?;
    let mut rows = Vec::new();
    for rec in r.records() {
        let rec = rec?;
        let times: FrameTimes = rec.deserialize(Some(&header))?;
        rows.push((rec.iter().take(lead).map(str::to_string).collect(), times));
    }
    Ok(FramesTimes {
        lead_header: header.iter().take(lead).map(str::to_string).collect(),
        rows,
    })
}

/// One CSV row as its file holds it: (column, cell) in the header's order. The answer reads summary.csv,
/// pairs.csv, transitions.csv and perceptual.csv as these, swept columns included, and quotes the cells it shows.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CsvRow(pub Vec<(String, String)>);

impl CsvRow {
    /// The cell of column `col`; `""` where the row has none.
    pub fn text(&self, col: &str) -> &str {
        self.0
            .iter()
            .find(|(c, _)| c == col)
            .map_or("", |(_, v)| v.as_str())
    }

    /// The cell of column `col` as a number; None where it is empty, missing, not a number or NaN.
    pub fn num(&self, col: &str) -> Option<f64> {
        self.text(col).parse::<f64>().ok().filter(|x| !x.is_nan())
    }

    /// The row's cells of `cols`, in that order (a column it lacks as `""`).
    pub fn pick(&self, cols: &[&str]) -> CsvRow {
        CsvRow(
            cols.iter()
                .map(|c| (c.to_string(), self.text(c).to_string()))
                .collect(),
        )
    }
}

/// Written as a JSON object whose keys keep the row's order.
impl serde::Serialize for CsvRow {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

/// The rows of `path` ([`CsvRow`]s); an empty list where the file is absent.
pub fn read_rows(path: &Path) -> Result<Vec<CsvRow>> {
    if !path.is_file() {
        return Ok(Vec::new());
    }
    rows_from(::csv::Reader::from_path(path)?)
}

/// `records` as their CSV file would hold them: the same writer, read back as [`CsvRow`]s.
pub fn rows_of<T: serde::Serialize>(records: &[T]) -> Result<Vec<CsvRow>> {
    let mut w = ::csv::Writer::from_writer(Vec::new());
    for r in records {
        w.serialize(r)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::Csv(e.into_error().into()))?;
    rows_from(::csv::Reader::from_reader(bytes.as_slice()))
}

fn rows_from<R: std::io::Read>(mut r: ::csv::Reader<R>) -> Result<Vec<CsvRow>> {
    let header = r.headers()?.clone();
    let mut out = Vec::new();
    for rec in r.records() {
        let rec = rec?;
        out.push(CsvRow(
            header
                .iter()
                .zip(rec.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect(),
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::records::tests::row;

    #[test]
    fn frames_csv_appears_only_when_finished() {
        let dir = tempfile::tempdir().unwrap();
        let mut w = FramesWriter::create(dir.path()).unwrap();
        w.write_block(&[row(0, None, 0.5, 0.0)]).unwrap();
        assert!(!dir.path().join(FRAMES_CSV).exists());
        let partial = std::fs::read_to_string(dir.path().join("frames.csv.partial")).unwrap();
        assert!(partial.starts_with(
            "scene,method,count,frame,gpu_ms,cpu_ms,triangles,draw_calls,units_drawn,t_instances,lod_mean,k_mean,rmse,pop,lodpop,lodpop_coverage,lodpop_shading,de2000_mean,uncovered_px,crack_px,flip_mean,combine_gpu_ms,lag_rmse,shadow_rmse,shadow_lodpop,splits,merges,select_cpu_ms,round,fragments,view_pop\n"
        ));
        assert!(
            partial.contains("s,m,1,0,,2.0,100,1,1,0,0.0,,0.5,0.0"),
            "{partial}"
        );
        w.finish().unwrap();
        assert!(dir.path().join(FRAMES_CSV).exists());
        assert!(!dir.path().join("frames.csv.partial").exists());
    }

    #[test]
    fn csv_round_trips_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let mut w = FramesWriter::create(dir.path()).unwrap();
        let r = row(3, Some(0.1 + 0.2), 1.0 / 3.0, 2f64.sqrt());
        w.write_block(std::slice::from_ref(&r)).unwrap();
        let path = w.finish().unwrap();
        let mut rd = ::csv::Reader::from_path(path).unwrap();
        let rec = rd.records().next().unwrap().unwrap();
        assert_eq!(rec[4].parse::<f64>().unwrap(), 0.1 + 0.2);
        assert_eq!(rec[12].parse::<f64>().unwrap(), 1.0 / 3.0);
        assert_eq!(rec[13].parse::<f64>().unwrap(), 2f64.sqrt());
    }
}
