//! A sphere table: `x, y, z, radius` per row (see the module docs of [`super`]).

use super::table::Table;
use super::{BodyFileError, SphereRow};

/// Every row of a sphere table.
pub(super) fn read(table: Table) -> Result<Vec<SphereRow>, BodyFileError> {
    let [x, y, z, radius] = table.required(["x", "y", "z", "radius"], "x, y, z, radius")?;
    let velocity_columns = table.triple(["vx", "vy", "vz"], "velocity")?;
    let id_column = table.column("id");
    table.rows(|k, row| {
        let position = row.vector([x, y, z], ["x", "y", "z"])?;
        let r = row.number(radius, "radius")?;
        if r <= 0.0 {
            return Err(row.error("radius", format!("must be positive, got {r}")));
        }
        let velocity = velocity_columns
            .map(|v| row.vector(v, ["vx", "vy", "vz"]))
            .transpose()?;
        Ok(SphereRow {
            id: row.id(id_column, k)?,
            position,
            radius: r,
            velocity,
        })
    })
}
