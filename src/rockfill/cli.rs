//! `polydem rockfill`: the paper's experiment from the command line.
//!
//! ```text
//! polydem rockfill [--config FILE | --full] [--size MM] [--seed N] [--bed DIR] [--out DIR]
//! ```
//! Without options it runs the quick variant (`scenes/rockfill/quick.toml`, compiled in); `--full` the
//! full-scale layer (`scenes/rockfill/paper.toml`). `--bed DIR` starts from a bed saved by an earlier run
//! instead of generating and packing. Writes into `--out` (default `out/rockfill`): `monitors.csv` (the
//! projectile's time series, columns in [`MonitorRow::CSV_HEADER`]), the packed bed (`bed_*.csv`, when
//! generated) and `summary.txt` (also printed).

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result};

use super::config::ExperimentConfig;
use super::experiment::{run_experiment, BedSource, ExperimentResult};
use super::penetration::MonitorRow;

/// Options of `polydem rockfill`.
#[derive(clap::Args, Debug, Clone)]
pub struct RockfillArgs {
    /// Experiment file (TOML, format of scenes/rockfill/paper.toml); default: the quick variant.
    #[arg(long, conflicts_with = "full")]
    pub config: Option<PathBuf>,
    /// Use the full-scale experiment (scenes/rockfill/paper.toml).
    #[arg(long)]
    pub full: bool,
    /// Override the mean rock size (mm).
    #[arg(long)]
    pub size: Option<f64>,
    /// Override the random seed of the sample.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Start from a bed saved by an earlier run (directory with bed_*.csv).
    #[arg(long)]
    pub bed: Option<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "out/rockfill")]
    pub out: PathBuf,
}

/// Runs the subcommand.
pub fn run(args: &RockfillArgs) -> Result<()> {
    let mut config = match (&args.config, args.full) {
        (Some(path), _) => ExperimentConfig::load(path)?,
        (None, true) => ExperimentConfig::paper(),
        (None, false) => ExperimentConfig::quick(),
    };
    if let Some(mm) = args.size {
        anyhow::ensure!(
            mm.is_finite() && mm > 0.0,
            "--size {mm}: must be positive (mm)"
        );
        config.rock.mean_size = mm * 1e-3;
    }
    if let Some(seed) = args.seed {
        config.rock.seed = seed;
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let bed = match &args.bed {
        Some(dir) => BedSource::Load(dir),
        None => BedSource::Generate {
            save: Some(&args.out),
        },
    };
    let mut progress = |stage: &str, text: String| eprintln!("[{stage}] {text}");
    let result = run_experiment(&config, bed, &mut progress)?;
    let mut csv = String::with_capacity(result.penetration.rows.len() * 200);
    csv.push_str(MonitorRow::CSV_HEADER);
    csv.push('\n');
    for row in &result.penetration.rows {
        csv.push_str(&row.csv_row());
        csv.push('\n');
    }
    let path = args.out.join("monitors.csv");
    std::fs::write(&path, csv).with_context(|| format!("writing {}", path.display()))?;
    let text = summary(&config, &result);
    let path = args.out.join("summary.txt");
    std::fs::write(&path, &text).with_context(|| format!("writing {}", path.display()))?;
    print!("{text}");
    Ok(())
}

/// The run summary as text.
pub fn summary(config: &ExperimentConfig, r: &ExperimentResult) -> String {
    let mut s = String::new();
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
    if let Some(g) = &r.generation {
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
    if let Some(p) = &r.packing {
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
    }
    let pr = &r.projectile;
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
    let p = &r.penetration;
    let _ = writeln!(
        s,
        "penetration: {:?} after {} steps of {:.3e} s ({} rocks); {:.1} s wall time\n  residual speed {:.1} m/s (axial {:.1} m/s; paper: 1000–1025 m/s for 100–200 mm, ≈1100 m/s for 290 mm)\n  deflection at the end: velocity {:.2}°, axis {:.2}° (max {:.2}°, {:.2}°; paper: 10°–20°)\n  max axial resistance {:.3e} N; disturbed rocks {}, zone width {:.3} m = {:.2} mean sizes (paper: 6–7)\n  energy: projectile lost {:.4e} J, damping {:.4e} J, friction {:.4e} J; ledger balance / initial projectile energy {:.3e}\n  max overlap/size {:.3}, steps with overlap warnings {}",
        p.outcome,
        p.steps,
        p.dt,
        p.rocks,
        p.wall_time.as_secs_f64(),
        p.residual_speed,
        p.residual_axial_velocity,
        p.final_velocity_deflection,
        p.final_axis_deflection,
        p.max_velocity_deflection,
        p.max_axis_deflection,
        p.max_axial_force,
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
    s
}

fn indent(text: &str) -> String {
    text.lines()
        .map(|l| format!("  {l}"))
        .collect::<Vec<_>>()
        .join("\n")
}
