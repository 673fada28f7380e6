//! The text summary of one experiment (`summary.txt`, also printed by `polydem rockfill`): the layer,
//! and what generation, packing and penetration each did and measured.

use std::fmt::Write as _;

use super::config::ExperimentConfig;
use super::experiment::{ExperimentResult, GenerationSummary};
use super::packing::{PackingReport, STAGE_NAMES};
use super::penetration::PenetrationReport;
use super::projectile::Projectile;
use super::stepper::RankFacts;

/// The run summary as text.
pub fn summary(config: &ExperimentConfig, r: &ExperimentResult) -> String {
    let mut s = String::new();
    layer(&mut s, config);
    if let Some(g) = &r.generation {
        generation(&mut s, g);
    }
    if let Some(p) = &r.packing {
        packing(&mut s, p);
        packing_throughput(&mut s, p);
    }
    projectile(&mut s, &r.projectile);
    penetration(&mut s, &r.penetration);
    if let Some(f) = &r.penetration.ranks {
        ranks(&mut s, f, r.penetration.steps);
    }
    s
}

/// The layer's size, the mean rock size and the seed.
fn layer(s: &mut String, config: &ExperimentConfig) {
    let l = &config.layer;
    let _ = writeln!(
        s,
        "rockfill: layer {} × {} × {} m, mean rock size {} mm, seed {}",
        l.length,
        l.width,
        l.height,
        config.rock.mean_size * 1e3,
        config.rock.seed
    );
}

/// What the generation did: seeds, rocks, the size law asked for and the statistics got.
fn generation(s: &mut String, g: &GenerationSummary) {
    let _ = writeln!(
        s,
        "generation: {} seeds (r = {:.4} m, eq. 28), {} rocks, {} cells too small for their size; {:.2} s\n  requested size law (eq. 29 bins): mean {:.4} m, std {:.4} m\n{}",
        g.seeds,
        g.cell_radius,
        g.rocks,
        g.dropped_small_cells,
        g.wall_time.as_secs_f64(),
        g.requested_mean,
        g.requested_std,
        indent(&g.statistics.to_string())
    );
}

/// What the packing did: its stages, the bed it left, the pre-collapse and the density scaling.
fn packing(s: &mut String, p: &PackingReport) {
    let _ = writeln!(
        s,
        "packing: dt {:.3e} s (t_c {:.3e} s), deposition {} steps ({:.3} s), compaction {} steps ({:.3} s{}), hold {} steps\n  bed top after deposition {:.3} m, final {:.3} m, top wall {:.3} m, solid fraction {:.3}\n  final max rock speed {:.3e} m/s, max overlap/size {:.3e}, ledger balance/initial potential after deposition, compaction, hold {:.3e}, {:.3e}, {:.3e}; {:.1} s",
        p.dt,
        p.contact_time,
        p.deposition_steps,
        p.deposition_time,
        p.compaction_steps,
        p.compaction_time,
        if p.compaction_stalled { ", stalled at the pressure cap" } else { "" },
        p.hold_steps,
        p.deposited_top,
        p.final_top,
        p.top_wall,
        p.solid_fraction,
        p.final_max_speed,
        p.max_overlap_ratio,
        p.ledger_balance_relative[0],
        p.ledger_balance_relative[1],
        p.ledger_balance_relative[2],
        p.wall_time.as_secs_f64()
    );
    if let Some(c) = &p.collapse {
        let _ = writeln!(
            s,
            "  pre-collapse: top {:.3} m -> {:.3} m, descent mean {:.3} m, max {:.3} m, {} moves, {} of {} rocks held by three blockers, {} pairs, {} distance queries ({} capped); {:.2} s",
            c.top_before,
            c.top_after,
            c.mean_descent,
            c.max_descent,
            c.moves,
            c.held_by_three,
            c.rocks,
            c.pairs,
            c.queries,
            c.capped,
            c.wall_time.as_secs_f64()
        );
    }
    if p.density_scale != 1.0 {
        let _ = writeln!(
            s,
            "  density scale {} (packing dt = sqrt(s) x the true-mass dt {:.3e} s): restore {} steps at {:.3e} s, top wall {:.4} m up, its force {:.4e} N -> {:.4e} N\n  bed overlap / mean size: after the hold (scaled masses) max {:.3e}, mean {:.3e}; final max {:.3e}, mean {:.3e}",
            p.density_scale,
            p.restore_dt,
            p.restore_steps,
            p.restore_dt,
            p.restore_wall_rise,
            p.restore_wall_force[0],
            p.restore_wall_force[1],
            p.bed_overlap_after_hold[0],
            p.bed_overlap_after_hold[1],
            p.bed_overlap_final[0],
            p.bed_overlap_final[1]
        );
    } else {
        let _ = writeln!(
            s,
            "  bed overlap / mean size at the end: max {:.3e}, mean {:.3e}",
            p.bed_overlap_final[0], p.bed_overlap_final[1]
        );
    }
}

/// Rock-steps per second and contacts per rock of each packing stage, with its stage timers.
fn packing_throughput(s: &mut String, p: &PackingReport) {
    for (stage, c) in STAGE_NAMES.iter().zip(&p.counters) {
        if c.steps == 0 && *stage == "restore" {
            continue;
        }
        let time = c.total_time().as_secs_f64();
        let _ = writeln!(
            s,
            "  {stage}: {:.3e} rock-steps/s in the step's stages ({:.1} s), {:.2} contacts per rock\n    {}",
            (c.steps as f64 * p.rocks as f64) / time,
            time,
            c.contacts as f64 / (c.steps.max(1) as f64 * p.rocks as f64),
            indent(&c.to_string()).trim_start().replace('\n', "\n  ")
        );
    }
}

/// The projectile's hull, mass, inertia and cavity.
fn projectile(s: &mut String, pr: &Projectile) {
    let _ = writeln!(
        s,
        "projectile: {} vertices, {} faces, mass {:.2} kg (solid {:.2} kg), principal moments {:.4?} kg m², cavity radius {:.4} m over x ∈ [{:.4}, {:.4}] m",
        pr.shape.vertices().len(),
        pr.shape.num_faces(),
        pr.mass,
        pr.solid_mass,
        pr.inertia.0.as_slice(),
        pr.cavity_radius,
        pr.cavity_x.0,
        pr.cavity_x.1
    );
}

/// What the penetration measured: outcome, residual speed, deflections, resistance, disturbed zone,
/// energies.
fn penetration(s: &mut String, p: &PenetrationReport) {
    let _ = writeln!(
        s,
        "penetration: {:?} after {} steps of {:.3e} s ({} rocks); {:.1} s wall time, {:.1} s in the step's stages; rock-steps asleep {:.1} %\n  residual speed {:.1} m/s (axial {:.1} m/s; paper: 1000–1025 m/s for 100–200 mm, ≈1100 m/s for 290 mm)\n  deflection at the end: velocity {:.2}°, axis {:.2}° (max {:.2}°, {:.2}°; paper: 10°–20°)\n  max axial resistance {:.3e} N; in the layer: mean {:.3e} N, CV per step {:.3}, CV over windows of one rock size {:.3} ({} windows)\n  disturbed rocks {}, zone width {:.3} m = {:.2} mean sizes (paper: 6–7)\n  energy: projectile lost {:.4e} J, damping {:.4e} J, friction {:.4e} J; ledger balance / initial projectile energy {:.3e}\n  max overlap/size {:.3}, steps with overlap warnings {}",
        p.outcome,
        p.steps,
        p.dt,
        p.rocks,
        p.wall_time.as_secs_f64(),
        p.counters.total_time().as_secs_f64(),
        100.0 * p.asleep_fraction,
        p.residual_speed,
        p.residual_axial_velocity,
        p.final_velocity_deflection,
        p.final_axis_deflection,
        p.max_velocity_deflection,
        p.max_axis_deflection,
        p.max_axial_force,
        p.resistance.mean,
        p.resistance.cv,
        p.resistance.cv_window,
        p.resistance.windows,
        p.disturbed_rocks,
        p.disturbed_width,
        p.disturbed_width_sizes,
        p.projectile_energy_loss,
        p.dissipated_damping,
        p.dissipated_friction,
        p.ledger_balance_relative,
        p.max_overlap_ratio,
        p.steps_with_overlap_warnings
    );
    let zones: Vec<String> = p
        .disturbed_by_threshold
        .iter()
        .map(|(f, n, w)| format!("{f}: {n} rocks, {w:.2} sizes"))
        .collect();
    let _ = writeln!(
        s,
        "  disturbed zone by displacement threshold (mean sizes): {}",
        zones.join("; ")
    );
    let _ = writeln!(s, "  {}", indent(&p.counters.to_string()).trim_start());
}

/// How the penetration was split over MPI ranks and what it sent per step (over `steps` steps).
fn ranks(s: &mut String, f: &RankFacts, steps: u64) {
    let per_step = |bytes: u64| bytes as f64 / steps.max(1) as f64;
    let _ = writeln!(
        s,
        "  split over {} MPI ranks (the stage times and counters above are rank {}'s part's, ghosts \
         included): {:.1} bodies owned and {:.1} ghosts on average, {} cuts ({} of them bisections); \
         sent per step: ghost states {:.0} B, rebuild agreements {:.0} B, bodies and contact entries at \
         the cuts {:.0} B, the run's gathers {:.0} B",
        f.ranks,
        f.rank,
        f.mean_owned,
        f.mean_ghosts,
        f.cuts,
        f.bisections,
        per_step(f.ghost_bytes),
        per_step(f.agreement_bytes),
        per_step(f.cut_bytes),
        per_step(f.gather_bytes)
    );
}

fn indent(text: &str) -> String {
    text.lines()
        .map(|l| format!("  {l}"))
        .collect::<Vec<_>>()
        .join("\n")
}
