//! The CSV machinery both tables share: the header, columns by name, rows with their line numbers, and
//! numbers that must parse and be finite.

use std::path::{Path, PathBuf};

use csv::StringRecord;

use crate::math::{Real, Vector};

use super::BodyFileError;

/// A body file's text and header.
pub(super) struct Table {
    path: PathBuf,
    text: String,
    headers: StringRecord,
    /// The line of the header (after the leading comments).
    pub header_line: u64,
}

fn reader(text: &str) -> csv::Reader<&[u8]> {
    csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(text.as_bytes())
}

impl Table {
    /// Reads the file and its header.
    pub fn open(path: &Path) -> Result<Table, BodyFileError> {
        let text = std::fs::read_to_string(path).map_err(|source| BodyFileError::Io {
            path: path.to_owned(),
            source,
        })?;
        let header_line = text
            .lines()
            .position(|l| !l.trim_start().starts_with('#'))
            .map_or(1, |i| i as u64 + 1);
        let mut table = Table {
            path: path.to_owned(),
            text,
            headers: StringRecord::new(),
            header_line,
        };
        table.headers = reader(&table.text)
            .headers()
            .map_err(|e| table.error(header_line, "header", e.to_string()))?
            .clone();
        Ok(table)
    }

    pub fn error(&self, line: u64, column: &str, message: String) -> BodyFileError {
        BodyFileError::Invalid {
            path: self.path.clone(),
            line,
            column: column.to_owned(),
            message,
        }
    }

    /// The index of a column by name.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }

    /// The indices of the required columns `names`; `list` names them all in the message.
    pub fn required<const N: usize>(
        &self,
        names: [&str; N],
        list: &str,
    ) -> Result<[usize; N], BodyFileError> {
        let mut columns = [0usize; N];
        for (slot, name) in columns.iter_mut().zip(names) {
            *slot = self.column(name).ok_or_else(|| {
                self.error(
                    self.header_line,
                    name,
                    format!("the header has no column '{name}' (required: {list})"),
                )
            })?;
        }
        Ok(columns)
    }

    /// Three columns that come together (`vx, vy, vz`): all or none; `what` names them in the message.
    pub fn triple(
        &self,
        names: [&str; 3],
        what: &str,
    ) -> Result<Option<[usize; 3]>, BodyFileError> {
        match names.map(|n| self.column(n)) {
            [Some(a), Some(b), Some(c)] => Ok(Some([a, b, c])),
            [None, None, None] => Ok(None),
            _ => Err(self.error(
                self.header_line,
                names[0],
                format!(
                    "give all three {what} columns {}, {}, {} or none",
                    names[0], names[1], names[2]
                ),
            )),
        }
    }

    /// `row` applied to every row in order (with the row's index from 0); at least one row.
    pub fn rows<T>(
        &self,
        mut row: impl FnMut(usize, &Row) -> Result<T, BodyFileError>,
    ) -> Result<Vec<T>, BodyFileError> {
        let mut out = Vec::new();
        for (k, record) in reader(&self.text).records().enumerate() {
            let record = record.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line());
                self.error(line, "row", e.to_string())
            })?;
            let line = record.position().map_or(0, |p| p.line());
            if record.len() != self.headers.len() {
                return Err(self.error(
                    line,
                    "row",
                    format!(
                        "{} fields where the header has {} columns",
                        record.len(),
                        self.headers.len()
                    ),
                ));
            }
            out.push(row(
                k,
                &Row {
                    table: self,
                    record,
                    line,
                },
            )?);
        }
        if out.is_empty() {
            return Err(self.error(self.header_line, "row", "the file has no rows".to_owned()));
        }
        Ok(out)
    }
}

/// One row of a table.
pub(super) struct Row<'a> {
    table: &'a Table,
    record: StringRecord,
    /// The line of the file the row is on.
    pub line: u64,
}

impl Row<'_> {
    pub fn error(&self, column: &str, message: String) -> BodyFileError {
        self.table.error(self.line, column, message)
    }

    /// The text of a column.
    pub fn text(&self, column: usize) -> &str {
        self.record.get(column).unwrap_or("")
    }

    /// The number in column `column` (named `name`): it must parse and be finite.
    pub fn number(&self, column: usize, name: &str) -> Result<Real, BodyFileError> {
        let text = self.text(column);
        let value: Real = text
            .parse()
            .map_err(|_| self.error(name, format!("'{text}' is not a number")))?;
        if value.is_finite() {
            Ok(value)
        } else {
            Err(self.error(name, format!("must be finite, got {text}")))
        }
    }

    /// The vector of three columns.
    pub fn vector(&self, columns: [usize; 3], names: [&str; 3]) -> Result<Vector, BodyFileError> {
        Ok(Vector::new(
            self.number(columns[0], names[0])?,
            self.number(columns[1], names[1])?,
            self.number(columns[2], names[2])?,
        ))
    }

    /// The `id` column (non-empty, without commas or quotes), or the row number `k + 1`.
    pub fn id(&self, id_column: Option<usize>, k: usize) -> Result<String, BodyFileError> {
        let Some(c) = id_column else {
            return Ok((k + 1).to_string());
        };
        let id = self.text(c).to_owned();
        if id.is_empty() || id.contains(['"', ',']) {
            return Err(self.error(
                "id",
                format!("'{id}' must be non-empty without commas or quotes"),
            ));
        }
        Ok(id)
    }
}
