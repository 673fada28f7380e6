//! Bodies from a CSV file (`[[body_file]]` of a scene): one body per row, in one of two tables.
//!
//! The first line that is not a `#` comment is the header; columns are found by name, in any order, and
//! other columns are ignored. Lines starting with `#` are comments anywhere in the file (a provenance
//! header, for instance). Every row has as many fields as the header.
//!
//! - A **sphere table** ([`SphereRow`]; no `shape` column): `x, y, z, radius` (m) are required; each row
//!   is a sphere of its own radius centred at (x, y, z).
//! - A **shape table** ([`PoseRow`]; a `shape` column, no `radius` column): `shape, x, y, z, qw, qx, qy,
//!   qz` are required; each row places the scene's `[[shape]]` of that name with the pose of its own
//!   frame, as a `[[body]]`'s `shape`, `position` and `orientation` do. The quaternion must be unit within
//!   [`QUATERNION_NORM_TOLERANCE`] and is normalised.
//!
//! Optional in both: `id` (the body's name suffix; absent = the row number, from 1) and `vx, vy, vz`
//! (m/s, all three or none); in a shape table also `wx, wy, wz` (angular velocity, rad/s, world frame, all
//! three or none). Errors name the CSV file, its line and the column.

mod poses;
mod spheres;
mod table;

use std::path::{Path, PathBuf};

use crate::math::{Real, Rotation, Vector};

pub use super::orientation::QUATERNION_NORM_TOLERANCE;

/// One row of a sphere table.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereRow {
    /// The `id` column, or the row number (from 1).
    pub id: String,
    /// Position of the centre (world frame, m).
    pub position: Vector,
    /// Radius (m).
    pub radius: Real,
    /// `None` when the file has no velocity columns.
    pub velocity: Option<Vector>,
}

/// One row of a shape table: a named shape and the pose of its own frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseRow {
    /// The `id` column, or the row number (from 1).
    pub id: String,
    /// The line of the file the row is on (for the messages of later checks).
    pub line: u64,
    /// The `shape` column: the name of a `[[shape]]` of the scene.
    pub shape: String,
    /// Where the origin of the shape's own coordinates goes (m).
    pub position: Vector,
    /// The normalised `qw, qx, qy, qz` columns.
    pub orientation: Rotation,
    /// `None` when the file has no `vx, vy, vz` columns.
    pub velocity: Option<Vector>,
    /// `None` when the file has no `wx, wy, wz` columns.
    pub angular_velocity: Option<Vector>,
}

/// The rows of a body file, of either table.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyTable {
    /// A sphere table (a `radius` column).
    Spheres(Vec<SphereRow>),
    /// A shape table (a `shape` column and a pose).
    Poses(Vec<PoseRow>),
}

/// Why a body file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum BodyFileError {
    /// The file could not be read.
    #[error("{}: cannot read the body file: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A cell is missing or not valid.
    #[error("{}:{line}: {column}: {message}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Line of the file (1-based).
        line: u64,
        /// The column.
        column: String,
        /// What is wrong.
        message: String,
    },
}

/// Reads the table at `path`, a sphere table or a shape table (see the module docs).
pub fn read_body_table(path: &Path) -> Result<BodyTable, BodyFileError> {
    let table = table::Table::open(path)?;
    match (table.column("shape"), table.column("radius")) {
        (Some(_), Some(_)) => Err(table.error(
            table.header_line,
            "shape",
            "give either a radius column (a sphere table) or a shape column (a shape table), not both"
                .to_owned(),
        )),
        (Some(_), None) => poses::read(table).map(BodyTable::Poses),
        (None, _) => spheres::read(table).map(BodyTable::Spheres),
    }
}

/// Reads a sphere table at `path` (see the module docs); a `shape` column is ignored, as any other.
pub fn read_sphere_table(path: &Path) -> Result<Vec<SphereRow>, BodyFileError> {
    spheres::read(table::Table::open(path)?)
}

#[cfg(test)]
mod tests;
