//! `cargo validate [--quick|--full] [CASE...]`: runs the validation suite and writes `reports/`.
//!
//! Exit status: 0 when every checked row passed, 1 when a row failed or a case could not complete,
//! 2 on usage errors.

use polydem_validation::provenance::workspace_root;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Parser;
use polydem_validation::case::{CaseData, Profile};
use polydem_validation::cases::registry;
use polydem_validation::progress::ProgressMode;
use polydem_validation::provenance::Provenance;
use polydem_validation::{report, runner};

#[derive(Parser, Debug)]
#[command(
    name = "cargo validate",
    about = "Run the polydem validation suite and write reports/"
)]
struct Cli {
    /// Quick profile (the default): the whole suite in minutes; what `cargo test` gates run.
    #[arg(long, conflicts_with = "full")]
    quick: bool,
    /// Full profile: everything at full scale (an estimate of the run time is printed first).
    #[arg(long)]
    full: bool,
    /// List the cases and exit.
    #[arg(long)]
    list: bool,
    /// Report directory (default: `reports/` at the workspace root).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write the contact pair sets as JSONL (the `polydem contact` input format) with a provenance README
    /// into this directory (e.g. `reference/contact`) and exit.
    #[arg(long, value_name = "DIR")]
    export_pairs: Option<PathBuf>,
    /// Cases to run (default: every case of the default run; see --list).
    cases: Vec<String>,
}

fn main() -> ExitCode {
    match run() {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run() -> anyhow::Result<bool> {
    let cli = Cli::parse();
    let profile = if cli.full {
        Profile::Full
    } else {
        Profile::Quick
    };
    let out = cli
        .out
        .clone()
        .unwrap_or_else(|| workspace_root().join("reports"));
    if cli.list {
        println!("{:<12} {:<8} title", "case", "default");
        for case in registry() {
            let data = CaseData::parse(case.name(), case.data())?;
            println!(
                "{:<12} {:<8} {}",
                case.name(),
                if case.in_default_run() { "yes" } else { "no" },
                data.title
            );
        }
        return Ok(true);
    }
    if let Some(dir) = &cli.export_pairs {
        polydem_validation::cases::contact::export_reference(dir, profile)?;
        println!("pair sets written to {}", dir.display());
        return Ok(true);
    }
    let cases = runner::select(&cli.cases)?;
    if profile == Profile::Full {
        let mut total = 0.0;
        for case in &cases {
            let data = CaseData::parse(case.name(), case.data())?;
            let est = report::last_wall_time(&out, case.name(), "full")
                .or(data.full_estimate_s)
                .unwrap_or(0.0);
            total += est;
        }
        eprintln!(
            "full profile: estimated run time {:.0} s ({:.1} min) for {} case(s)",
            total,
            total / 60.0,
            cases.len()
        );
    }
    let prov = Provenance::collect(&workspace_root());
    let mode = ProgressMode::detect();
    let mut reports = Vec::new();
    for case in cases {
        reports.push(
            runner::run_case(case, profile, Some(&out), mode)
                .with_context(|| format!("case {}", case.name()))?,
        );
    }
    report::write_report(&out, &reports, &prov)?;
    let failed: Vec<String> = reports
        .iter()
        .flat_map(|r| {
            let mut v: Vec<String> = r
                .checks
                .iter()
                .filter(|c| !c.pass)
                .map(|c| {
                    format!(
                        "{}: {} = {} (target {})",
                        r.case,
                        c.metric,
                        c.value,
                        c.target.render()
                    )
                })
                .collect();
            if let Some(e) = &r.error {
                v.push(format!("{}: did not complete: {e}", r.case));
            }
            v
        })
        .collect();
    let total: usize = reports.iter().map(|r| r.checks.len()).sum();
    println!(
        "{} case(s), {} checks, {} failed; report in {}",
        reports.len(),
        total,
        failed.len(),
        out.display()
    );
    for f in &failed {
        println!("FAIL {f}");
    }
    Ok(failed.is_empty())
}
