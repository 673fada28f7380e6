//! The run summary of `polydem run`: what ran, how fast, where the time went, what the narrow phase did,
//! where the energy went and which files were written — as text (`summary.txt`, also printed) and as JSON
//! (`summary.json`, for scripts). The fields of the JSON are listed in `docs/output-formats.md`.

use std::time::Duration;

use serde_json::{json, Value};

use crate::math::Real;
use crate::scene::{RunSummary, Simulation};

/// One checkpoint written during the run.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CheckpointRecord {
    /// File name relative to the output directory.
    pub file: String,
    /// Step at which it was written.
    pub step: u64,
    /// Simulated time at which it was written (s).
    pub time: Real,
    /// Size of the file (bytes).
    pub bytes: u64,
    /// Wall time of encoding and writing (s).
    pub seconds: Real,
}

/// What the output side of a run did (timed outside the step).
#[derive(Clone, Debug, Default)]
pub struct OutputRecord {
    /// Steps between CSV rows.
    pub csv_every: u64,
    /// Steps between VTK frames (`None`: not written).
    pub vtk_every: Option<u64>,
    /// Steps between checkpoints (`None`: not written).
    pub checkpoint_every: Option<u64>,
    /// VTK frames written.
    pub vtk_frames: u64,
    /// Bytes of VTK frames written.
    pub vtk_bytes: u64,
    /// Steps between contact-network (`.vtp`) frames (`None`: not written).
    pub contacts_every: Option<u64>,
    /// Contact-network frames written.
    pub contact_frames: u64,
    /// Bytes of contact-network frames written.
    pub contact_bytes: u64,
    /// The checkpoints written, in order.
    pub checkpoints: Vec<CheckpointRecord>,
    /// Wall time of all output: CSV rows, VTK frames and checkpoints.
    pub time: Duration,
    /// Wall time of the VTK frames.
    pub vtk_time: Duration,
    /// Wall time of the checkpoints.
    pub checkpoint_time: Duration,
}

/// Where the run came from.
#[derive(Clone, Debug)]
pub struct RunOrigin {
    /// The scene file, or the checkpoint the run restarted from.
    pub source: String,
    /// Whether the run restarted from a checkpoint.
    pub restarted: bool,
    /// Step count at the start of this run.
    pub start_step: u64,
    /// Simulated time at the start of this run (s).
    pub start_time: Real,
}

/// Rates of a run: steps, particle-steps and contacts per second of wall time.
fn rates(sim: &Simulation, summary: &RunSummary) -> (Real, Real, Real) {
    let secs = summary.wall_time.as_secs_f64().max(1e-12);
    let steps = summary.steps as Real / secs;
    (
        steps,
        steps * sim.world.bodies().len() as Real,
        summary.counters.contacts as Real / secs,
    )
}

/// The summary as JSON.
pub fn summary_json(
    origin: &RunOrigin,
    sim: &Simulation,
    summary: &RunSummary,
    output: &OutputRecord,
) -> Value {
    let c = &summary.counters;
    let (steps_per_second, particle_steps_per_second, contacts_per_second) = rates(sim, summary);
    let secs = |d: Duration| d.as_secs_f64();
    json!({
        "polydem_version": env!("CARGO_PKG_VERSION"),
        "source": origin.source,
        "restarted": origin.restarted,
        "bodies": sim.world.bodies().len(),
        "walls": sim.world.walls().len(),
        "shapes": sim.world.shapes().len(),
        "time_step": {
            "dt": sim.time_step.dt,
            "derived": sim.time_step.derived,
            "contact_time": sim.time_step.contact_time,
            "stability_limit": sim.time_step.stability_limit,
        },
        "start_step": origin.start_step,
        "end_step": sim.world.step_index(),
        "steps_run": summary.steps,
        "start_time": origin.start_time,
        "end_time": sim.world.time(),
        "wall_time_s": secs(summary.wall_time),
        "steps_per_second": steps_per_second,
        "particle_steps_per_second": particle_steps_per_second,
        "contacts_per_second": contacts_per_second,
        "stage_seconds": {
            "broad": secs(c.broad),
            "narrow": secs(c.narrow),
            "laws": secs(c.laws),
            "accumulate": secs(c.accumulate),
            "integrate": secs(c.integrate),
            "checks": secs(c.checks),
            "output": secs(output.time),
        },
        "counters": {
            "steps": c.steps,
            "broad_rebuilds": c.broad_rebuilds,
            "body_pairs_tested": c.body_pairs_tested,
            "wall_pairs_tested": c.wall_pairs_tested,
            "wall_pairs_rejected": c.wall_pairs_rejected,
            "contacts": c.contacts,
            "contacts_created": c.contacts_created,
            "contacts_dropped": c.contacts_dropped,
            "contact_store_entries_at_end": sim.world.contacts().len(),
        },
        "queries": c.query,
        "max_overlap_ratio": summary.max_overlap_ratio,
        "steps_with_deep_overlap": summary.steps_with_deep_overlap,
        "first_deep_overlap_step": summary.first_deep_overlap_step,
        "energy": sim.world.energy(),
        "outputs": {
            "csv_every_steps": output.csv_every,
            "vtk_every_steps": output.vtk_every,
            "vtk_frames": output.vtk_frames,
            "vtk_bytes": output.vtk_bytes,
            "vtk_seconds": secs(output.vtk_time),
            "checkpoint_every_steps": output.checkpoint_every,
            "checkpoints": output.checkpoints,
            "checkpoint_seconds": secs(output.checkpoint_time),
            "contacts_every_steps": output.contacts_every,
            "contact_frames": output.contact_frames,
            "contact_bytes": output.contact_bytes,
        },
    })
}

/// The summary as text (the lines of [`RunSummary`]'s display plus rates, output and energy).
pub fn summary_text(
    origin: &RunOrigin,
    sim: &Simulation,
    summary: &RunSummary,
    output: &OutputRecord,
) -> String {
    let (steps_per_second, particle_steps_per_second, contacts_per_second) = rates(sim, summary);
    let energy = sim.world.energy();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let mut text = format!(
        "{} {}: steps {} → {} (t = {} → {} s)\n{summary}\n",
        if origin.restarted {
            "restart from"
        } else {
            "scene"
        },
        origin.source,
        origin.start_step,
        sim.world.step_index(),
        origin.start_time,
        sim.world.time(),
    );
    text.push_str(&format!(
        "rates: {steps_per_second:.3e} steps/s, particle-steps per second {particle_steps_per_second:.3e}, contacts per second {contacts_per_second:.3e}\n"
    ));
    text.push_str(&format!(
        "output (ms): total {:.1}, vtk {:.1} ({} frames, {} bytes), checkpoints {:.1} ({} files)\n",
        ms(output.time),
        ms(output.vtk_time),
        output.vtk_frames,
        output.vtk_bytes,
        ms(output.checkpoint_time),
        output.checkpoints.len()
    ));
    if output.contacts_every.is_some() {
        text.push_str(&format!(
            "contact network: {} frames, {} bytes of VTK lines\n",
            output.contact_frames, output.contact_bytes
        ));
    }
    text.push_str(&format!(
        "final energy balance {:e} J (mechanical energy {:e} J)\n",
        energy.balance,
        energy.mechanical()
    ));
    text
}
