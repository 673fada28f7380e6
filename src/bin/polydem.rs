//! The `polydem` command line.
//!
//! Subcommands:
//! - `polydem contact PAIRS.jsonl [--out FILE]`: the contact contract (format in `docs/contact-jsonl.md`):
//!   one JSON object per input line with two point clouds, one answer (or error record) per line.
//!   `-` reads standard input; output goes to standard output unless `--out` is given.

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
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Contact { pairs, out } => contact(&pairs, out.as_deref()),
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
