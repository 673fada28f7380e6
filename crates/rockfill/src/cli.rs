//! `polydem rockfill`: the paper's experiment from the command line.
//!
//! ```text
//! polydem rockfill [--config FILE | --full] [--size MM] [--seed N] [--bed DIR] [--out DIR] [--vtk-every N]
//! mpirun -n P polydem rockfill --mpi [--config FILE | --full] [--bed DIR] [--out DIR] [--vtk-every N]  (feature `mpi`)
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
//! With `--mpi` (a build with the `mpi` feature, launched under `mpirun`) the penetration runs split over
//! the job's ranks (the `distributed` module), with the bits of one process; rank 0 writes the files and
//! prints the summary.
//!
//! `study` runs the size study ([`super::study`]); `convergence` the time-step and rock-count sequences
//! ([`super::convergence`]); `sensitivity` the one-at-a-time contact-parameter runs from one bed
//! ([`super::sensitivity`]).

use std::path::PathBuf;

use anyhow::{Context, Result};

use super::config::ExperimentConfig;
use super::convergence::{run_convergence, ConvergenceParams};
use super::penetration::PenetrationFiles;
use super::sensitivity::{run_sensitivity, sensitivity_table, SensitivityParams, Variation};
use super::study::{run_one_with_files, run_study, StudyParams};
use super::summary::summary;

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
    /// Run the penetration split over the ranks of the MPI job this process is launched in
    /// (`mpirun -n P polydem rockfill --mpi …`; a build with the `mpi` feature): the same bits as one
    /// process; rank 0 writes the files and the summary. Without `--bed` every rank packs the same bed.
    #[arg(long)]
    pub mpi: bool,
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
    if args.mpi {
        return run_mpi(&config, files, bed, &title);
    }
    let result = run_one_with_files(&config, files, bed, &title, None, &mut progress)?;
    print!("{}", summary(&config, &result));
    Ok(())
}

/// `--mpi`: the experiment on every rank of the MPI job, its penetration split over them; rank 0
/// reports. A rank that fails aborts the job (the others would wait for it in the next exchange).
#[cfg(feature = "mpi")]
fn run_mpi(
    config: &ExperimentConfig,
    files: PenetrationFiles,
    bed: Option<&std::path::Path>,
    title: &str,
) -> Result<()> {
    use polydem_mpi::mpi::traits::Communicator;
    let universe = polydem_mpi::mpi::initialize()
        .context("--mpi: MPI was already initialised in this process")?;
    let world = universe.world();
    let root = world.rank() == 0;
    let mut progress = |stage: &str, text: String| {
        if root {
            eprintln!("[{stage}] {text}")
        }
    };
    let options = super::penetration::PenetrationOptions {
        distributed: true,
        ..Default::default()
    };
    match super::study::run_one_with_options(config, files, options, bed, title, &mut progress) {
        Ok(result) => {
            if root {
                print!("{}", summary(config, &result));
            }
            Ok(())
        }
        Err(e) => {
            eprintln!("rank {}: {e}", world.rank());
            world.abort(1)
        }
    }
}

/// `--mpi` in a build without MPI.
#[cfg(not(feature = "mpi"))]
fn run_mpi(
    _: &ExperimentConfig,
    _: PenetrationFiles,
    _: Option<&std::path::Path>,
    _: &str,
) -> Result<()> {
    Err(super::penetration::PenetrationError::NoMpi.into())
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
