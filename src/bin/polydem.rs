//! The `polydem` command line.
//!
//! Subcommands:
//! - `polydem contact PAIRS.jsonl [--out FILE]`: the contact contract (format in `docs/contact-jsonl.md`):
//!   one JSON object per input line with two point clouds, one answer (or error record) per line.
//!   `-` reads standard input; output goes to standard output unless `--out` is given.
//! - `polydem run SCENE --out DIR`: runs a scene file (format in `docs/scene-format.md`) and writes
//!   `DIR/bodies.csv`, `DIR/energy.csv`, `DIR/walls.csv` and `DIR/summary.txt`; the summary is also printed. A progress bar
//!   is drawn on standard error when it is a terminal.
//! - `polydem rockfill [--full] [--out DIR] …`: the paper's rockfill experiment (`polydem::rockfill::cli`).

use std::fs::File;
use std::io::{self, BufReader, BufWriter, Write};
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};

use polydem::contact::query_polyhedra;
use polydem::io::pairs_jsonl::answer_stream;

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
    /// Run a scene file and write CSV time series (bodies, energy ledger) and a run summary.
    Run {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// The paper's rockfill penetration experiment (quick variant by default; see `--help`).
    Rockfill(polydem::rockfill::cli::RockfillArgs),
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Contact { pairs, out } => contact(&pairs, out.as_deref()),
        Command::Run { scene, out } => run(&scene, &out),
        Command::Rockfill(args) => polydem::rockfill::cli::run(&args),
    }
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
        None => Box::new(BufWriter::new(io::stdout().lock())),
    };
    let summary = answer_stream(input, output, &query_polyhedra)
        .context("reading pairs or writing answers")?;
    eprintln!(
        "polydem contact: {} pairs answered, {} lines with errors, {} blank lines skipped",
        summary.answered, summary.errors, summary.blank
    );
    Ok(())
}

fn run(scene: &std::path::Path, out_dir: &std::path::Path) -> Result<()> {
    use polydem::io::csv_output;
    let mut sim = polydem::scene::load_scene(scene)?;
    std::fs::create_dir_all(out_dir)
        .with_context(|| format!("cannot create output directory {}", out_dir.display()))?;
    let create = |name: &str| -> Result<BufWriter<File>> {
        let path = out_dir.join(name);
        Ok(BufWriter::new(File::create(&path).with_context(|| {
            format!("cannot create {}", path.display())
        })?))
    };
    let mut bodies = create("bodies.csv")?;
    let mut energy = create("energy.csv")?;
    csv_output::write_bodies_header(&mut bodies)?;
    csv_output::write_energy_header(&mut energy)?;
    let mut walls = create("walls.csv")?;
    csv_output::write_walls_header(&mut walls)?;

    let info = sim.time_step;
    let header = format!(
        "scene {}: {} bodies, {} walls, dt = {:e} s ({}), shortest contact time {:e} s, stability limit {:e} s, {} steps to t = {} s",
        scene.display(),
        sim.world.bodies.len(),
        sim.world.walls.len(),
        info.dt,
        if info.derived { "derived: t_c / steps_per_contact" } else { "given" },
        info.contact_time,
        info.stability_limit,
        sim.steps,
        sim.end_time
    );
    eprintln!("{header}");
    // Drawn only on a terminal: indicatif hides the bar when standard error is not one.
    let bar = indicatif::ProgressBar::new(sim.steps);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} steps  {per_sec}  eta {eta}")
            .context("progress bar template")?,
    );
    let summary = sim
        .run(
            |s| {
                csv_output::write_bodies_rows(&mut bodies, s)?;
                csv_output::write_walls_rows(&mut walls, s)?;
                csv_output::write_energy_row(&mut energy, s)
            },
            |n| {
                if n % 256 == 0 {
                    bar.set_position(n);
                }
            },
        )
        .with_context(|| format!("running scene {}", scene.display()))?;
    bar.finish_and_clear();
    bodies.flush()?;
    energy.flush()?;
    walls.flush()?;
    let body_steps = summary.steps as f64 * sim.world.bodies.len() as f64;
    let final_energy = sim.world.energy();
    let text = format!(
        "{header}\n{summary}\nparticle-steps per second {:.3e}\nfinal energy balance {:e} J (mechanical energy {:e} J)\n",
        body_steps / summary.wall_time.as_secs_f64().max(1e-12),
        final_energy.balance,
        final_energy.mechanical()
    );
    print!("{text}");
    std::fs::write(out_dir.join("summary.txt"), &text)
        .with_context(|| format!("cannot write {}", out_dir.join("summary.txt").display()))?;
    Ok(())
}
