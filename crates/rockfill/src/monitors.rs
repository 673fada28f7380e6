//! The projectile's monitor series (`monitors.csv`, one row per step of the penetration run) as an engine
//! [`Output`], the trait every output of `polydem run` and Python implements.
//!
//! # Columns ([`MonitorRow::CSV_HEADER`])
//! Time since the start of the run (s); the centre of mass and the tip (m); the velocity and the speed
//! (m/s); the resultant contact force on the projectile (N) and its component along the initial axis e₀
//! (negative = resisting); the deflection angles between the velocity and e₀ and between the current
//! axis and e₀ (degrees); the number of rocks touching it. Numbers in Rust's shortest round-trip form.
//!
//! The rows stay in memory (the run's statistics are computed from them) and the file is written whole
//! when the series is flushed, at the end of a completed run: an interrupted or failed run leaves no
//! `monitors.csv`.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use polydem::io::output::Output;
use polydem::io::run_summary::OutputRecord;
use polydem::math::{Point, Real, Vector};
use polydem::scene::Simulation;
use polydem::world::{ContactKey, World};

/// One row of the monitor time series (serialisable: a run split over MPI ranks hands it from the rank that
/// owns the projectile to the others).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MonitorRow {
    pub time: Real,
    pub position: Point,
    pub tip: Point,
    pub velocity: Vector,
    /// Resultant contact force on the projectile (N).
    pub force: Vector,
    /// Its component along e₀ (N).
    pub axial_force: Real,
    /// Angle between the velocity and e₀ (degrees).
    pub velocity_deflection: Real,
    /// Angle between the axis and e₀ (degrees).
    pub axis_deflection: Real,
    /// Rocks overlapping the projectile.
    pub contacts: usize,
}

impl MonitorRow {
    pub const CSV_HEADER: &'static str = "t,x,y,z,tip_x,tip_y,tip_z,vx,vy,vz,speed,fx,fy,fz,f_axial,velocity_deflection_deg,axis_deflection_deg,contacts";

    pub fn csv_row(&self) -> String {
        let (p, t, v, f) = (self.position, self.tip, self.velocity, self.force);
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            self.time,
            p.x,
            p.y,
            p.z,
            t.x,
            t.y,
            t.z,
            v.x,
            v.y,
            v.z,
            v.norm(),
            f.x,
            f.y,
            f.z,
            self.axial_force,
            self.velocity_deflection,
            self.axis_deflection,
            self.contacts
        )
    }
}

/// What a monitor row needs to know of the projectile and the run.
#[derive(Clone, Copy, Debug)]
pub struct ProjectileGauge {
    /// The projectile's body index.
    pub index: usize,
    /// Its axis (base → tip) in its body frame.
    pub axis_body: Vector,
    /// Distance from the centre of mass to the tip along the axis (m).
    pub tip_distance: Real,
    /// The initial axis e₀ (world frame).
    pub initial_axis: Vector,
    /// Simulated time at the start of the run (s).
    pub start_time: Real,
}

impl ProjectileGauge {
    /// The row of `world`'s current state.
    pub fn row(&self, world: &World) -> MonitorRow {
        let body = world.body(self.index);
        let axis = body.orientation * self.axis_body;
        let force = world.loads().forces()[self.index];
        let e0 = self.initial_axis;
        MonitorRow {
            time: world.time() - self.start_time,
            position: body.position,
            tip: body.position + axis * self.tip_distance,
            velocity: body.velocity,
            force,
            axial_force: force.dot(&e0),
            velocity_deflection: angle_deg(&body.velocity, &e0),
            axis_deflection: angle_deg(&axis, &e0),
            contacts: self.contacts(world),
        }
    }

    /// Rocks pressing on the projectile (contacts of the store with a nonzero force).
    fn contacts(&self, world: &World) -> usize {
        world
            .contacts()
            .keys()
            .iter()
            .zip(world.contacts().states())
            .filter(|(k, s)| {
                matches!(k, ContactKey::Body { b, .. } if *b as usize == self.index)
                    && s.force_on_b != Vector::zeros()
            })
            .count()
    }
}

fn angle_deg(a: &Vector, b: &Vector) -> Real {
    let c = a.dot(b) / (a.norm() * b.norm());
    c.clamp(-1.0, 1.0).acos().to_degrees()
}

/// The monitor series: a row after every step of the run (not of the state it starts from), kept in
/// memory and written to `path` (when given) at each flush.
#[derive(Debug)]
pub struct MonitorSeries {
    gauge: ProjectileGauge,
    start_step: u64,
    rows: Vec<MonitorRow>,
    path: Option<PathBuf>,
    time: Duration,
}

impl MonitorSeries {
    /// The series of a run that starts at step `start_step`, written to `path` if given.
    pub fn new(gauge: ProjectileGauge, start_step: u64, path: Option<PathBuf>) -> Self {
        Self {
            gauge,
            start_step,
            rows: Vec::new(),
            path,
            time: Duration::ZERO,
        }
    }

    /// What the rows are measured with.
    pub fn gauge(&self) -> &ProjectileGauge {
        &self.gauge
    }

    /// Appends the row of the state after a step of the run (a run whose world is not at hand in one
    /// piece computes it where the projectile is, with [`Self::gauge`]).
    pub fn push(&mut self, row: MonitorRow) {
        self.rows.push(row);
    }

    /// The rows so far.
    pub fn rows(&self) -> &[MonitorRow] {
        &self.rows
    }

    /// The rows, for the run's report.
    pub fn into_rows(self) -> Vec<MonitorRow> {
        self.rows
    }

    fn write_file(&self, path: &Path) -> io::Result<()> {
        let mut out = BufWriter::new(std::fs::File::create(path)?);
        writeln!(out, "{}", MonitorRow::CSV_HEADER)?;
        for row in &self.rows {
            writeln!(out, "{}", row.csv_row())?;
        }
        out.flush()
    }
}

impl Output for MonitorSeries {
    fn due(&self, step: u64) -> bool {
        step > self.start_step
    }

    fn write(&mut self, sim: &Simulation, _step: u64) -> io::Result<()> {
        self.push(self.gauge.row(&sim.world));
        Ok(())
    }

    fn flush(&mut self) -> io::Result<()> {
        let Some(path) = &self.path else {
            return Ok(());
        };
        let start = Instant::now();
        self.write_file(path)
            .map_err(|e| io::Error::new(e.kind(), format!("writing {}: {e}", path.display())))?;
        self.time += start.elapsed();
        Ok(())
    }

    fn record(&self, record: &mut OutputRecord) {
        record.csv_every = 1;
        record.time += self.time;
    }
}
