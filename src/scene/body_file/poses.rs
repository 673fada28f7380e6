//! A shape table: a `[[shape]]` name and a pose per row (see the module docs of [`super`]).

use super::super::orientation::{unit_quaternion, QUATERNION_NORM_TOLERANCE};
use super::table::{Row, Table};
use super::{BodyFileError, PoseRow};

/// Every row of a shape table.
pub(super) fn read(table: Table) -> Result<Vec<PoseRow>, BodyFileError> {
    let [shape, x, y, z, qw, qx, qy, qz] = table.required(
        ["shape", "x", "y", "z", "qw", "qx", "qy", "qz"],
        "shape, x, y, z, qw, qx, qy, qz",
    )?;
    let velocity_columns = table.triple(["vx", "vy", "vz"], "velocity")?;
    let angular_columns = table.triple(["wx", "wy", "wz"], "angular velocity")?;
    let id_column = table.column("id");
    table.rows(|k, row| {
        let name = row.text(shape);
        if name.is_empty() {
            return Err(row.error("shape", "empty: name a [[shape]] of the scene".to_owned()));
        }
        let position = row.vector([x, y, z], ["x", "y", "z"])?;
        let orientation = orientation(row, [qw, qx, qy, qz])?;
        let velocity = velocity_columns
            .map(|v| row.vector(v, ["vx", "vy", "vz"]))
            .transpose()?;
        let angular_velocity = angular_columns
            .map(|w| row.vector(w, ["wx", "wy", "wz"]))
            .transpose()?;
        Ok(PoseRow {
            id: row.id(id_column, k)?,
            line: row.line,
            shape: name.to_owned(),
            position,
            orientation,
            velocity,
            angular_velocity,
        })
    })
}

/// The unit quaternion of the `qw, qx, qy, qz` columns.
fn orientation(row: &Row, columns: [usize; 4]) -> Result<crate::math::Rotation, BodyFileError> {
    let names = ["qw", "qx", "qy", "qz"];
    let mut q = [0.0; 4];
    for ((value, column), name) in q.iter_mut().zip(columns).zip(names) {
        *value = row.number(column, name)?;
    }
    unit_quaternion(q).map_err(|norm| {
        row.error(
            "qw, qx, qy, qz",
            format!(
                "must be a unit quaternion (its norm within {QUATERNION_NORM_TOLERANCE:e} of 1; it is normalised), got norm {norm}"
            ),
        )
    })
}
