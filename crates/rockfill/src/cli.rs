//! `polydem rockfill`: the paper's experiment from the command line.
//!
//! ```text
//! polydem rockfill [--config FILE | --full] [--size MM] [--seed N] [--bed DIR] [--out DIR] [--vtk-every N]
//! polydem rockfill study [--config FILE | --full] --sizes 100,130,175,200,290 --seeds 1,2,3
//!                        [--section-sizes K] [--reuse-beds] --out DIR
//! polydem rockfill convergence [--config FILE | --full] [--dt-divisors 1,2,4] [--sections 1.0,1.5,2.0]
//!                        [--no-time-step] [--bed DIR] --out DIR
//! polydem rockfill sensitivity [--config FILE | --full] [--size MM] [--seed N] --bed DIR
//!                        --vary contact.friction=0,0.4 [--vary ...] --out DIR
//! ```
//! Without a subcommand it runs one experiment: the quick variant (`scenes/rockfill/quick.toml`, compiled in)
//! or with `--full` the full-scale layer (`scenes/rockfill/paper.toml`). `--bed DIR` starts from a bed saved
//! by an earlier run (its checkpoint `bed.pdck` when there is one, else its CSV files; see
//! [`super::bed`]) instead of generating and packing. Writes into `--out` (default `out/rockfill`):
//! `monitors.csv` (the projectile's time series, columns in [`super::monitors::MonitorRow::CSV_HEADER`]), the packed bed
//! (`bed.pdck`, `bed_info.json`, `bed_*.csv`, when generated), `section.svg` (the paper's Fig. 7 picture)
//! and `summary.txt` (also printed); with `--vtk-every N`, VTK frames of the penetration (`vtk/`, `*.pvd`),
//! written by the engine's output as `polydem run` writes them.
//!
//! `study` runs the size study ([`super::study`]); `convergence` the time-step and rock-count sequences
//! ([`super::convergence`]); `sensitivity` the one-at-a-time contact-parameter runs from one bed
//! ([`super::sensitivity`]).

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result};

use super::config::ExperimentConfig;
use super::convergence::{run_convergence, ConvergenceParams};
use super::experiment::ExperimentResult;
use super::packing::STAGE_NAMES;
use super::penetration::PenetrationFiles;
use super::sensitivity::{run_sensitivity, sensitivity_table, SensitivityParams, Variation};
use super::study::{run_one_with_files, run_study, StudyParams};

/// Options of `polydem rockfill`.
#[derive(clap::Args, Debug, Clone)]
#[command(args_conflicts_with_subcommands = true)]
pub struct RockfillArgs {
    #[command(subcommand)]
    pub command: Option<RockfillCommand>,
    #[command(flatten)]
    pub experiment: ExperimentArgs,
    #[command(flatten)]
    pub sample: SampleArgs,
    /// Start from a bed saved by an earlier run (directory with bed.pdck or bed_*.csv).
    #[arg(long)]
    pub bed: Option<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "out/rockfill")]
    pub out: PathBuf,
    /// Write VTK frames of the penetration (OUT/vtk, with .pvd collections) at its start and at every
    /// step index that is a multiple of N (zlib-compressed binary, as `polydem run`).
    #[arg(long, value_name = "N")]
    pub vtk_every: Option<u64>,
}

/// The sample: the file's mean rock size and seed, or these (for a run from a saved bed, the bed's: the
/// size sets the time step and the disturbed zone's unit).
#[derive(clap::Args, Debug, Clone)]
pub struct SampleArgs {
    /// Override the mean rock size (mm).
    #[arg(long)]
    pub size: Option<f64>,
    /// Override the random seed of the sample.
    #[arg(long)]
    pub seed: Option<u64>,
}

impl SampleArgs {
    /// `--size MM` and `--seed N` applied to the file's sample.
    fn apply(&self, config: &mut ExperimentConfig) -> Result<()> {
        if let Some(mm) = self.size {
            anyhow::ensure!(
                mm.is_finite() && mm > 0.0,
                "--size {mm}: must be positive (mm)"
            );
            config.rock.mean_size = mm * 1e-3;
        }
        if let Some(seed) = self.seed {
            config.rock.seed = seed;
        }
        Ok(())
    }
}

/// The experiment file.
#[derive(clap::Args, Debug, Clone)]
pub struct ExperimentArgs {
    /// Experiment file (TOML, format of scenes/rockfill/paper.toml); default: the quick variant.
    #[arg(long, conflicts_with = "full")]
    pub config: Option<PathBuf>,
    /// Use the full-scale experiment (scenes/rockfill/paper.toml).
    #[arg(long)]
    pub full: bool,
    /// Override the file's `sleeping.penetration` (true: the bed starts asleep and wakes locally).
    #[arg(long, value_name = "true|false")]
    pub sleep_penetration: Option<bool>,
    /// Override the file's `sleeping.packing`.
    #[arg(long, value_name = "true|false")]
    pub sleep_packing: Option<bool>,
    /// The most rocks generation may make (the file's `limits.max_rocks`; default 200000): a larger sample
    /// is refused before generation with its rock count and memory estimate.
    #[arg(long, value_name = "N")]
    pub max_rocks: Option<usize>,
    /// The most steps of the packing and of the penetration run, each (the file's `limits.max_steps`;
    /// default 1e7): a longer stage is refused before it starts with its step count.
    #[arg(long, value_name = "N")]
    pub max_steps: Option<u64>,
}

impl ExperimentArgs {
    fn load(&self) -> Result<(ExperimentConfig, String)> {
        let (mut config, name) = self.load_file()?;
        if let Some(on) = self.sleep_penetration {
            config.sleeping.penetration = on;
        }
        if let Some(on) = self.sleep_packing {
            config.sleeping.packing = on;
        }
        if let Some(n) = self.max_rocks {
            anyhow::ensure!(n > 0, "--max-rocks {n}: must be at least 1");
            config.limits.max_rocks = n;
        }
        if let Some(n) = self.max_steps {
            anyhow::ensure!(n > 0, "--max-steps {n}: must be at least 1");
            config.limits.max_steps = n;
        }
        Ok((config, name))
    }

    fn load_file(&self) -> Result<(ExperimentConfig, String)> {
        Ok(match (&self.config, self.full) {
            (Some(path), _) => (ExperimentConfig::load(path)?, path.display().to_string()),
            (None, true) => (ExperimentConfig::paper(), "paper.toml (full scale)".into()),
            (None, false) => (
                ExperimentConfig::quick(),
                "quick.toml (quick variant)".into(),
            ),
        })
    }
}

/// Subcommands of `polydem rockfill`.
#[derive(clap::Subcommand, Debug, Clone)]
pub enum RockfillCommand {
    /// The five-size study: every size × seed, a table against the paper (OUT/study.md, OUT/runs.csv).
    Study(StudyArgs),
    /// Time-step and rock-count convergence with a work-precision plot (OUT/convergence.csv, .svg).
    Convergence(ConvergenceArgs),
    /// Contact-parameter sensitivity from one saved bed, one parameter at a time (OUT/sensitivity.md, .csv).
    Sensitivity(SensitivityArgs),
}

/// Options of `polydem rockfill sensitivity`.
#[derive(clap::Args, Debug, Clone)]
pub struct SensitivityArgs {
    #[command(flatten)]
    pub experiment: ExperimentArgs,
    /// The bed's sample, when the file's is another.
    #[command(flatten)]
    pub sample: SampleArgs,
    /// The saved bed every run starts from (directory with bed.pdck or bed_*.csv).
    #[arg(long)]
    pub bed: PathBuf,
    /// A parameter and its values, KEY=V1,V2,... (repeatable). Keys: contact.stiffness_factor (k_n and
    /// k_s together), contact.normal_stiffness, contact.tangential_stiffness, contact.friction,
    /// contact.restitution_rocks, contact.restitution_projectile.
    #[arg(long, required = true, value_parser = Variation::parse)]
    pub vary: Vec<Variation>,
    /// Output directory.
    #[arg(long, default_value = "out/rockfill_sensitivity")]
    pub out: PathBuf,
}

/// Options of `polydem rockfill study`.
#[derive(clap::Args, Debug, Clone)]
pub struct StudyArgs {
    #[command(flatten)]
    pub experiment: ExperimentArgs,
    /// Mean rock sizes (mm), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "100,130,175,200,290")]
    pub sizes: Vec<f64>,
    /// Seeds, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2,3")]
    pub seeds: Vec<u64>,
    /// Reduced scale: layer width and height in mean rock sizes (the length stays the file's).
    #[arg(long)]
    pub section_sizes: Option<f64>,
    /// Start each run from the bed an earlier study saved in its directory, when there is one.
    #[arg(long)]
    pub reuse_beds: bool,
    /// Output directory.
    #[arg(long, default_value = "out/rockfill_study")]
    pub out: PathBuf,
}

/// Options of `polydem rockfill convergence`.
#[derive(clap::Args, Debug, Clone)]
pub struct ConvergenceArgs {
    #[command(flatten)]
    pub experiment: ExperimentArgs,
    /// Divisors k of the penetration time step (Δt/k), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2,4")]
    pub dt_divisors: Vec<f64>,
    /// Skip the time-step sequence (run only the cross-sections).
    #[arg(long)]
    pub no_time_step: bool,
    /// Layer widths = heights (m) of the rock-count sequence, comma-separated; empty to skip.
    #[arg(long, value_delimiter = ',')]
    pub sections: Vec<f64>,
    /// Bed directory for the time-step sequence (default: generate and pack one into OUT/bed).
    #[arg(long)]
    pub bed: Option<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "out/rockfill_convergence")]
    pub out: PathBuf,
}

/// Runs the subcommand.
pub fn run(args: &RockfillArgs) -> Result<()> {
    match &args.command {
        Some(RockfillCommand::Study(a)) => return study(a),
        Some(RockfillCommand::Convergence(a)) => return convergence(a),
        Some(RockfillCommand::Sensitivity(a)) => return sensitivity(a),
        None => {}
    }
    let (mut config, _) = args.experiment.load()?;
    args.sample.apply(&mut config)?;
    let mut progress = |stage: &str, text: String| eprintln!("[{stage}] {text}");
    let title = format!(
        "{} mm rocks, seed {}",
        config.rock.mean_size * 1e3,
        config.rock.seed
    );
    if args.vtk_every == Some(0) {
        anyhow::bail!("--vtk-every 0: must be at least 1 step");
    }
    let files = PenetrationFiles {
        vtk_every: args.vtk_every,
        ..PenetrationFiles::monitors_in(&args.out)
    };
    let bed = args.bed.as_deref();
    let result = run_one_with_files(&config, files, bed, &title, None, &mut progress)?;
    print!("{}", summary(&config, &result));
    Ok(())
}

fn sensitivity(a: &SensitivityArgs) -> Result<()> {
    let (mut base, label) = a.experiment.load()?;
    a.sample.apply(&mut base)?;
    let params = SensitivityParams {
        base,
        bed: a.bed.clone(),
        variations: a.vary.clone(),
        out: a.out.clone(),
        label,
    };
    let runs = run_sensitivity(&params, &mut |line| eprintln!("{line}"))?;
    print!("{}", sensitivity_table(&params, &runs));
    eprintln!(
        "wrote {}/sensitivity.md and sensitivity.csv",
        a.out.display()
    );
    Ok(())
}

fn study(a: &StudyArgs) -> Result<()> {
    let (base, label) = a.experiment.load()?;
    let params = StudyParams {
        base,
        sizes_mm: a.sizes.clone(),
        seeds: a.seeds.clone(),
        section_sizes: a.section_sizes,
        reuse_beds: a.reuse_beds,
        out: a.out.clone(),
        label,
    };
    if let Some(k) = a.section_sizes {
        anyhow::ensure!(
            k.is_finite() && k > 0.0,
            "--section-sizes {k}: must be positive"
        );
    }
    let runs = run_study(&params, &mut |line| eprintln!("{line}"))?;
    print!("{}", super::study::study_table(&params, &runs));
    eprintln!("wrote {}/study.md and runs.csv", a.out.display());
    Ok(())
}

fn convergence(a: &ConvergenceArgs) -> Result<()> {
    let (base, label) = a.experiment.load()?;
    let params = ConvergenceParams {
        base,
        dt_divisors: if a.no_time_step {
            Vec::new()
        } else {
            a.dt_divisors.clone()
        },
        sections: a.sections.clone(),
        out: a.out.clone(),
        bed: a.bed.clone(),
        label,
    };
    let result = run_convergence(&params, &mut |line| eprintln!("{line}"))
        .with_context(|| "convergence study".to_string())?;
    print!("{}", result.csv());
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
    s
}

fn indent(text: &str) -> String {
    text.lines()
        .map(|l| format!("  {l}"))
        .collect::<Vec<_>>()
        .join("\n")
}
