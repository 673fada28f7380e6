//! Continuing a CSV time series across a restart: a run restarted from a checkpoint into the directory of
//! the earlier run keeps the earlier rows up to its own start and appends after them, so `bodies.csv`,
//! `energy.csv` and `walls.csv` read as one series, as they would after an uninterrupted run.
//!
//! Rows are kept when their time (first column) is strictly before the restart's start time: the restart
//! writes its own first row at its start, and rows after it belong to the part of the earlier run the
//! restart replaces (a restart from an earlier checkpoint rewinds). Times are written in shortest
//! round-trip form and the checkpoint stores the time exactly, so the comparison is exact.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

use crate::math::Real;

/// Opens `path` for a restarted run that starts at `start_time`: the existing file's header must be
/// `header`; its rows before `start_time` are kept and the writer appends after them. A missing file is
/// created with the header. A file with another header or a row whose time is not a number is an error
/// naming the file and line (the file is then left as it was).
pub fn continue_csv(path: &Path, header: &str, start_time: Real) -> io::Result<BufWriter<File>> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            let mut out = BufWriter::new(File::create(path)?);
            writeln!(out, "{header}")?;
            return Ok(out);
        }
        Err(e) => return Err(e),
    };
    let kept = rows_before(&text, header, start_time).map_err(|(line, what)| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{}:{line}: {what}", path.display()),
        )
    })?;
    let mut out = BufWriter::new(File::create(path)?);
    writeln!(out, "{header}")?;
    for row in kept {
        writeln!(out, "{row}")?;
    }
    Ok(out)
}

/// The rows of a CSV `text` with header `header` whose time is before `start_time`; an error is the
/// 1-based line and what is wrong with it.
pub fn rows_before<'a>(
    text: &'a str,
    header: &str,
    start_time: Real,
) -> Result<Vec<&'a str>, (usize, String)> {
    let mut lines = text.lines();
    match lines.next() {
        Some(first) if first == header => {}
        Some(first) => {
            return Err((
                1,
                format!(
                "header \"{first}\" is not the expected \"{header}\": not an output of this run"
            ),
            ))
        }
        None => return Err((1, "empty file: no header".into())),
    }
    let mut kept = Vec::new();
    for (k, row) in lines.enumerate() {
        if row.is_empty() {
            continue;
        }
        let field = row.split(',').next().unwrap_or("");
        let t: Real = field
            .parse()
            .map_err(|_| (k + 2, format!("time \"{field}\" is not a number")))?;
        if t < start_time {
            kept.push(row);
        }
    }
    Ok(kept)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_before_the_start_are_kept_and_bad_files_named() {
        let text = "t,x\n0,1\n0.5,2\n1,3\n1.5,4\n";
        assert_eq!(rows_before(text, "t,x", 1.0).unwrap(), vec!["0,1", "0.5,2"]);
        assert_eq!(
            rows_before(text, "t,y", 1.0).unwrap_err().0,
            1,
            "another header is refused at line 1"
        );
        let (line, what) = rows_before("t,x\n0,1\nsoon,2\n", "t,x", 1.0).unwrap_err();
        assert_eq!(line, 3, "{what}");
        assert!(what.contains("soon"), "{what}");
    }
}
