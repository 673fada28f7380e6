//! CSV time series of `polydem run`: tracked bodies and the energy ledger.
//!
//! - `bodies.csv`: `t,id,x,y,z,vx,vy,vz,qw,qx,qy,qz,wx,wy,wz`, one row per tracked body per output time;
//!   `id` is the body's name from the scene, (x, y, z) its centre of mass (m), v its velocity (m/s),
//!   q the unit quaternion of the body's own frame (as the scene gave it) in the world, ω its angular
//!   velocity (rad/s, world frame).
//! - `energy.csv`: the columns of [`crate::world::EnergyReport::CSV_HEADER`] (J).
//! - `walls.csv`: `t,wall,fx,fy,fz`, the total contact force on each wall (N, world frame), one row per wall
//!   per output time.
//!
//! Numbers are written with Rust's shortest round-trip formatting, so a value read back is bit-identical.

use std::io::{self, Write};

use crate::scene::Simulation;
use crate::world::EnergyReport;

/// Header of `bodies.csv`.
pub const BODIES_HEADER: &str = "t,id,x,y,z,vx,vy,vz,qw,qx,qy,qz,wx,wy,wz";

/// Writes the header of `bodies.csv`.
pub fn write_bodies_header(out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "{BODIES_HEADER}")
}

/// Writes one row per tracked body at the simulation's current time.
pub fn write_bodies_rows(out: &mut impl Write, sim: &Simulation) -> io::Result<()> {
    let t = sim.world.time();
    for &i in &sim.tracked {
        let b = &sim.world.bodies()[i];
        let q = sim.input_orientation(i);
        let w = b.angular_velocity();
        let (x, v) = (b.position, b.velocity);
        writeln!(
            out,
            "{t},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            sim.world.names()[i],
            x.x,
            x.y,
            x.z,
            v.x,
            v.y,
            v.z,
            q.w,
            q.i,
            q.j,
            q.k,
            w.x,
            w.y,
            w.z
        )?;
    }
    Ok(())
}

/// Writes the header of `energy.csv`.
pub fn write_energy_header(out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "{}", EnergyReport::CSV_HEADER)
}

/// Writes the ledger at the simulation's current time.
pub fn write_energy_row(out: &mut impl Write, sim: &Simulation) -> io::Result<()> {
    writeln!(out, "{}", sim.world.energy().csv_row())
}

/// Header of `walls.csv`: the total contact force each wall receives (N), world frame.
pub const WALLS_HEADER: &str = "t,wall,fx,fy,fz";

/// Writes the header of `walls.csv`.
pub fn write_walls_header(out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "{WALLS_HEADER}")
}

/// Writes one row per wall: the contact force on it from the last evaluation (zero before the first step).
pub fn write_walls_rows(out: &mut impl Write, sim: &Simulation) -> io::Result<()> {
    let t = sim.world.time();
    for (w, wall) in sim.world.walls().iter().enumerate() {
        let f = sim
            .world
            .loads()
            .wall_forces()
            .get(w)
            .copied()
            .unwrap_or_else(crate::math::Vector::zeros);
        writeln!(out, "{t},{},{},{},{}", wall.name, f.x, f.y, f.z)?;
    }
    Ok(())
}
