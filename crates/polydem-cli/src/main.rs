//! The `polydem` command line.
//!
//! Subcommands:
//! - `polydem contact PAIRS.jsonl [--out FILE]`: the contact contract (format in `docs/contact-jsonl.md`):
//!   one JSON object per input line with two point clouds, one answer (or error record) per line.
//!   `-` reads standard input; output goes to standard output unless `--out` is given.
//! - `polydem run SCENE --out DIR [--vtk-interval T] [--contacts-interval T] [--checkpoint-interval T]
//!   [--end-time T] [--quiet]`: runs a scene file (format in `docs/scene-format.md`) and writes
//!   `DIR/bodies.csv`, `DIR/energy.csv`, `DIR/walls.csv`, VTK frames with `.pvd` collections, the contact
//!   network (`contacts.csv`, `contacts.pvd`), checkpoints in `DIR/checkpoints/`, and the run
//!   summary `DIR/summary.txt` (also printed) and `DIR/summary.json` (formats in `docs/output-formats.md`
//!   and `docs/checkpoint-format.md`). A progress bar with rates and ETA is drawn on standard error when it is
//!   a terminal, unless `--quiet`.
//! - `polydem run --restart FILE --out DIR [--end-time T] ...`: continues a checkpoint bit for bit; into the
//!   earlier run's directory it continues its CSV and VTK series (`polydem::io::csv_continue`).
//! - Built with the feature `mpi`, `mpirun -n P polydem run …` with P > 1 steps the scene split over the
//!   ranks (`mpi_run`); one rank runs as without MPI.
//! - `polydem rockfill [--full] [--out DIR] …`: the paper's rockfill experiment (`polydem_rockfill::cli`).

use std::fs::File;
use std::io::{self, BufReader, BufWriter, Write};
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};

use polydem::contact::query_polyhedra;
use polydem::io::pairs_jsonl::answer_stream;

#[cfg(feature = "mpi")]
mod mpi_run;

#[derive(Parser)]
#[command(
    name = "polydem",
    version,
    about = "Convex-polyhedral discrete element engine"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Minkowski contact features of point-cloud pairs (JSON Lines in, JSON Lines out, same order).
    Contact {
        /// Input file of pairs, one JSON object per line; `-` for standard input.
        pairs: PathBuf,
        /// Write the answers to this file instead of standard output.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run a scene file (or continue a checkpoint) and write CSV time series, optional VTK frames and
    /// checkpoints, and a run summary.
    Run(RunArgs),
    /// The paper's rockfill penetration experiment (quick variant by default; see `--help`).
    Rockfill(polydem_rockfill::cli::RockfillArgs),
}

fn main() -> std::process::ExitCode {
    let result = match Cli::parse().command {
        Command::Contact { pairs, out } => contact(&pairs, out.as_deref()),
        #[cfg(feature = "mpi")]
        Command::Run(args) => mpi_run::run(&args),
        #[cfg(not(feature = "mpi"))]
        Command::Run(args) => run(&args),
        Command::Rockfill(args) => polydem_rockfill::cli::run(&args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            std::process::ExitCode::FAILURE
        }
    }
}

/// The whole chain of `e` on one line ("what failed: why"), without a backtrace: these are user errors. A
/// cause that its parent's message already quotes is not repeated.
fn one_line(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if !line.contains(&text) {
            if !line.is_empty() {
                line.push_str(": ");
            }
            line.push_str(&text);
        }
    }
    line
}

fn contact(pairs: &std::path::Path, out: Option<&std::path::Path>) -> Result<()> {
    let input: Box<dyn io::BufRead> = if pairs.as_os_str() == "-" {
        Box::new(io::stdin().lock())
    } else {
        let file = File::open(pairs)
            .with_context(|| format!("cannot open pairs file {}", pairs.display()))?;
        Box::new(BufReader::new(file))
    };
    let output: Box<dyn Write> = match out {
        Some(path) => {
            Box::new(BufWriter::new(File::create(path).with_context(|| {
                format!("cannot create output file {}", path.display())
            })?))
        }
        // Answers reach a reader line by line (an interactive session or a driving program on a pipe)
        // unless standard output is a regular file, where one buffer is cheaper.
        None if stdout_is_regular_file() => Box::new(BufWriter::new(io::stdout().lock())),
        None => Box::new(io::LineWriter::new(io::stdout().lock())),
    };
    let summary = answer_stream(input, output, &query_polyhedra)
        .context("reading pairs or writing answers")?;
    eprintln!(
        "polydem contact: {} pairs answered, {} lines with errors, {} blank lines skipped",
        summary.answered, summary.errors, summary.blank
    );
    Ok(())
}

/// Whether standard output is redirected to a regular file.
fn stdout_is_regular_file() -> bool {
    use std::os::fd::AsFd;
    io::stdout()
        .as_fd()
        .try_clone_to_owned()
        .map(File::from)
        .and_then(|f| f.metadata())
        .is_ok_and(|m| m.file_type().is_file())
}

/// Options of `polydem run`.
#[derive(clap::Args, Clone)]
struct RunArgs {
    /// The scene file (TOML); omit it with --restart.
    #[arg(required_unless_present = "restart", conflicts_with = "restart")]
    scene: Option<PathBuf>,
    /// Output directory (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Continue the run saved in this checkpoint file instead of starting a scene.
    #[arg(long, value_name = "FILE")]
    restart: Option<PathBuf>,
    /// Simulated end time (s), replacing the scene's or the checkpoint's.
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    end_time: Option<f64>,
    /// The most steps the run may cover with --end-time (default 1e9; a scene sets its own with
    /// simulation.max_steps).
    #[arg(long, value_name = "N", requires = "end_time")]
    max_steps: Option<u64>,
    /// Write VTK frames every T seconds of simulated time (and at the start and the end).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    vtk_interval: Option<f64>,
    /// Write the VTK numbers as text instead of inline base64 binary (both exact; text is larger and slower).
    #[arg(long)]
    vtk_ascii: bool,
    /// Write the VTK coordinates and fields as Float32 (half the size, relative rounding ≤ 6e-8; for viewing).
    #[arg(long)]
    vtk_float32: bool,
    /// Write the binary VTK arrays uncompressed (by default they are zlib-compressed: lossless, ~7× smaller).
    #[arg(long, conflicts_with = "vtk_ascii")]
    vtk_uncompressed: bool,
    /// Write the contact network (every active contact's point, normal, depth and force: `contacts.csv`
    /// and VTK lines `contacts.pvd`) every T seconds of simulated time (and at the start and the end).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    contacts_interval: Option<f64>,
    /// Write a checkpoint every T seconds of simulated time (and at the end).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    checkpoint_interval: Option<f64>,
    /// No progress bar and no messages on standard error (errors excepted).
    #[arg(long, short)]
    quiet: bool,
}

fn run(args: &RunArgs) -> Result<()> {
    let (mut sim, origin, start) = load_run(args)?;
    let mut outputs = run_outputs(args, &sim, &start)?;
    if !args.quiet {
        eprintln!("{}", run_header(&origin, &sim));
    }
    let bar = progress_bar(args.quiet, &origin, &sim)?;
    let start_step = origin.start_step;
    let shown = bar.clone();
    outputs.on_progress(move |n| shown.set_position(n - start_step));
    let summary = sim
        .run_observed(&mut outputs)
        .with_context(|| format!("running {}", origin.source))?;
    let record = outputs.finish()?;
    bar.finish_and_clear();
    write_summaries(args, &origin, &sim, &summary, &record, "")
}

/// The simulation `polydem run` continues or starts, where it comes from, and how its outputs start.
fn load_run(
    args: &RunArgs,
) -> Result<(
    polydem::scene::Simulation,
    polydem::io::run_summary::RunOrigin,
    polydem::io::run_outputs::RunStart,
)> {
    use polydem::io::run_outputs::RunStart;
    use polydem::io::run_summary::RunOrigin;

    let (mut sim, source, run) = match (&args.restart, &args.scene) {
        (Some(file), _) => {
            let payload = polydem::io::checkpoint::load(file)
                .with_context(|| format!("cannot restart from checkpoint {}", file.display()))?;
            let run = RunStart::Restart {
                checkpoint: file.clone(),
                run: payload.run,
            };
            (payload.simulation, file.display().to_string(), run)
        }
        (None, Some(scene)) => (
            polydem::scene::load_scene(scene)?,
            scene.display().to_string(),
            RunStart::Fresh,
        ),
        (None, None) => bail!("give a scene file or --restart FILE"),
    };
    if let Some(t) = args.end_time {
        let limit = args.max_steps.unwrap_or(polydem::scene::DEFAULT_MAX_STEPS);
        sim.set_end_time_within(t, limit)
            .with_context(|| format!("--end-time {t}"))?;
    }
    let origin = RunOrigin {
        source,
        restarted: matches!(run, RunStart::Restart { .. }),
        start_step: sim.world.step_index(),
        start_time: sim.world.time(),
    };
    Ok((sim, origin, run))
}

/// Prints the run summary (with `extra` lines after it) and writes `summary.txt` and `summary.json`.
fn write_summaries(
    args: &RunArgs,
    origin: &polydem::io::run_summary::RunOrigin,
    sim: &polydem::scene::Simulation,
    summary: &polydem::scene::RunSummary,
    record: &polydem::io::run_summary::OutputRecord,
    extra: &str,
) -> Result<()> {
    use polydem::io::run_summary::{summary_json, summary_text};
    let text = summary_text(origin, sim, summary, record) + extra;
    print!("{text}");
    let write = |name: &str, contents: &str| -> Result<()> {
        let path = args.out.join(name);
        std::fs::write(&path, contents).with_context(|| format!("cannot write {}", path.display()))
    };
    write("summary.txt", &text)?;
    let json = summary_json(origin, sim, summary, record);
    write(
        "summary.json",
        &(serde_json::to_string_pretty(&json)? + "\n"),
    )?;
    Ok(())
}

/// The outputs of `polydem run`: the engine's [`open_outputs`](polydem::io::run_outputs::open_outputs)
/// with the command's flags.
fn run_outputs<'a>(
    args: &RunArgs,
    sim: &polydem::scene::Simulation,
    start: &polydem::io::run_outputs::RunStart,
) -> Result<polydem::io::output::OutputSet<'a>> {
    use polydem::io::run_outputs::{open_outputs, IntervalNames, OutputPlan};
    let plan = OutputPlan {
        vtk_interval: args.vtk_interval,
        vtk_encoding: vtk_encoding(args),
        contacts_interval: args.contacts_interval,
        checkpoint_interval: args.checkpoint_interval,
    };
    let names = IntervalNames {
        vtk: "--vtk-interval",
        contacts: "--contacts-interval",
        checkpoint: "--checkpoint-interval",
    };
    Ok(open_outputs(&args.out, &plan, names, sim, start)?)
}

fn vtk_encoding(args: &RunArgs) -> polydem::io::vtk::VtkEncoding {
    use polydem::io::vtk::{VtkCompression, VtkEncoding, VtkFormat, VtkPrecision};
    VtkEncoding {
        format: if args.vtk_ascii {
            VtkFormat::Ascii
        } else {
            VtkFormat::Binary
        },
        precision: if args.vtk_float32 {
            VtkPrecision::Float32
        } else {
            VtkPrecision::Float64
        },
        compression: if args.vtk_ascii || args.vtk_uncompressed {
            VtkCompression::None
        } else {
            VtkCompression::Zlib
        },
    }
}

/// The line printed before the run: what runs, its time step and its length.
fn run_header(
    origin: &polydem::io::run_summary::RunOrigin,
    sim: &polydem::scene::Simulation,
) -> String {
    let info = sim.time_step;
    format!(
        "{} {}: {} bodies, {} walls, dt = {:e} s ({}), shortest contact time {:e} s, stability limit {:e} s, steps {} → {} (t = {} s)",
        if origin.restarted { "restart from" } else { "scene" },
        origin.source,
        sim.world.bodies().len(),
        sim.world.walls().len(),
        info.dt,
        if info.derived { "derived: t_c / steps_per_contact" } else { "given" },
        info.contact_time,
        info.stability_limit,
        origin.start_step,
        sim.steps,
        sim.end_time
    )
}

/// The progress bar on standard error (indicatif draws nothing when it is not a terminal).
fn progress_bar(
    quiet: bool,
    origin: &polydem::io::run_summary::RunOrigin,
    sim: &polydem::scene::Simulation,
) -> Result<indicatif::ProgressBar> {
    let remaining = sim.steps.saturating_sub(origin.start_step);
    let bar = if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(remaining)
    };
    let particles = sim.world.bodies().len() as f64;
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:20} {pos}/{len} steps {step_rate} steps/s {particle_rate} particle-steps/s eta {eta}",
        )
        .context("progress bar template")?
        .with_key(
            "step_rate",
            |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = write!(w, "{:.0}", state.per_sec());
            },
        )
        .with_key(
            "particle_rate",
            move |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = write!(w, "{:.2e}", state.per_sec() * particles);
            },
        ),
    );
    Ok(bar)
}
