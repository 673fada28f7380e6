//! Spherical bodies from a CSV file (`[[body_file]]` of a scene): one sphere per row.
//!
//! The first line that is not a `#` comment is the header; columns are found by name, in any order:
//! `x, y, z, radius` (m) are required, `id` (the body's name suffix; absent = the row number, from 1) and
//! `vx, vy, vz` (m/s, all three or none) are optional, and other columns are ignored. Lines starting with
//! `#` are comments anywhere in the file (a provenance header, for instance). Errors name the CSV file, its
//! line and the column.

use std::path::{Path, PathBuf};

use crate::math::{Real, Vector};

/// One row of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereRow {
    /// The `id` column, or the row number (from 1).
    pub id: String,
    pub position: Vector,
    pub radius: Real,
    /// `None` when the file has no velocity columns.
    pub velocity: Option<Vector>,
}

/// Why a body file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum BodyFileError {
    #[error("{}: cannot read the body file: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}:{line}: {column}: {message}", path.display())]
    Invalid {
        path: PathBuf,
        line: u64,
        column: String,
        message: String,
    },
}

/// Reads the table at `path` (see the module docs).
pub fn read_sphere_table(path: &Path) -> Result<Vec<SphereRow>, BodyFileError> {
    let text = std::fs::read_to_string(path).map_err(|source| BodyFileError::Io {
        path: path.to_owned(),
        source,
    })?;
    let invalid = |line: u64, column: &str, message: String| BodyFileError::Invalid {
        path: path.to_owned(),
        line,
        column: column.to_owned(),
        message,
    };
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header_line = text
        .lines()
        .position(|l| !l.trim_start().starts_with('#'))
        .map_or(1, |i| i as u64 + 1);
    let headers = reader
        .headers()
        .map_err(|e| invalid(header_line, "header", e.to_string()))?
        .clone();
    let find = |name: &str| headers.iter().position(|h| h == name);
    let mut required = [0usize; 4];
    for (slot, name) in required.iter_mut().zip(["x", "y", "z", "radius"]) {
        *slot = find(name).ok_or_else(|| {
            invalid(
                header_line,
                name,
                format!("the header has no column '{name}' (required: x, y, z, radius)"),
            )
        })?;
    }
    let velocity_columns = [find("vx"), find("vy"), find("vz")];
    let velocity_columns = match velocity_columns {
        [Some(a), Some(b), Some(c)] => Some([a, b, c]),
        [None, None, None] => None,
        _ => {
            return Err(invalid(
                header_line,
                "vx",
                "give all three velocity columns vx, vy, vz or none".to_owned(),
            ))
        }
    };
    let id_column = find("id");
    let mut rows = Vec::new();
    for (k, record) in reader.records().enumerate() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            invalid(line, "row", e.to_string())
        })?;
        let line = record.position().map_or(0, |p| p.line());
        let number = |column: usize, name: &str| -> Result<Real, BodyFileError> {
            let text = record.get(column).unwrap_or("");
            let value: Real = text
                .parse()
                .map_err(|_| invalid(line, name, format!("'{text}' is not a number")))?;
            if value.is_finite() {
                Ok(value)
            } else {
                Err(invalid(line, name, format!("must be finite, got {text}")))
            }
        };
        let position = Vector::new(
            number(required[0], "x")?,
            number(required[1], "y")?,
            number(required[2], "z")?,
        );
        let radius = number(required[3], "radius")?;
        if radius <= 0.0 {
            return Err(invalid(
                line,
                "radius",
                format!("must be positive, got {radius}"),
            ));
        }
        let velocity = velocity_columns
            .map(|[a, b, c]| -> Result<Vector, BodyFileError> {
                Ok(Vector::new(
                    number(a, "vx")?,
                    number(b, "vy")?,
                    number(c, "vz")?,
                ))
            })
            .transpose()?;
        let id = match id_column {
            Some(c) => {
                let id = record.get(c).unwrap_or("").to_owned();
                if id.is_empty() || id.contains(['"', ',']) {
                    return Err(invalid(
                        line,
                        "id",
                        format!("'{id}' must be non-empty without commas or quotes"),
                    ));
                }
                id
            }
            None => (k + 1).to_string(),
        };
        rows.push(SphereRow {
            id,
            position,
            radius,
            velocity,
        });
    }
    if rows.is_empty() {
        return Err(invalid(
            header_line,
            "row",
            "the file has no rows".to_owned(),
        ));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("polydem-body-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn reads_columns_by_name_and_skips_comments() {
        let path = write(
            "ok.csv",
            "# provenance\n# more\nradius,z,y,x,id,extra\n0.002,0.3,0.2,0.1,7,foo\n# mid comment\n0.001,0.6,0.5,0.4,9,bar\n",
        );
        let rows = read_sphere_table(&path).unwrap();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[0].id, "7");
        assert_eq!(rows[0].position, Vector::new(0.1, 0.2, 0.3));
        assert_eq!(rows[1].radius, 0.001);
        assert_eq!(rows[1].velocity, None);
    }

    #[test]
    fn a_bad_number_names_file_line_and_column() {
        let path = write(
            "bad.csv",
            "# header comment\nx,y,z,radius,vx,vy,vz\n0,0,0,0.001,0,0,0\n0,0,abc,0.001,0,0,0\n",
        );
        let message = read_sphere_table(&path).unwrap_err().to_string();
        let expected = format!("{}:4: z:", path.display());
        assert!(
            message.starts_with(&expected),
            "message {message:?} does not start with {expected:?}"
        );
        let path = write("neg.csv", "x,y,z,radius\n0,0,0,-1\n");
        let message = read_sphere_table(&path).unwrap_err().to_string();
        assert!(
            message.contains("neg.csv:2: radius:"),
            "message {message:?} does not name line 2, column radius"
        );
        let path = write("nocol.csv", "x,y,radius\n0,0,1\n");
        let message = read_sphere_table(&path).unwrap_err().to_string();
        assert!(message.contains("nocol.csv:1: z:"), "{message}");
    }
}
