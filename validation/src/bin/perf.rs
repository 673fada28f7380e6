//! `cargo perf`: instruction counts of the fixed benchmark set, the regression gate, the per-commit
//! history and its dashboard (`docs/perf.md`).
//!
//! Exit status: 0 when no figure regressed (or a record was written), 1 when a figure regressed past the
//! threshold without an acceptance, 2 when the command could not run (no valgrind, a failed benchmark, a
//! dirty tree for `record`, a malformed history or acceptance file).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context};
use clap::{Parser, Subcommand};
use polydem_validation::perf::gate::{self, Status, Verdict};
use polydem_validation::perf::history::{self, Row};
use polydem_validation::perf::key::MachineKey;
use polydem_validation::perf::{
    baseline, benches, by_figure, callgrind, count_all, page, peers, work_dir, CountOptions,
    FigureCounts,
};
use polydem_validation::provenance::{workspace_root, Provenance};

#[derive(Parser, Debug)]
#[command(
    name = "cargo perf",
    about = "Instruction counts per commit: gate, record, dashboard"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(clap::Args, Debug, Clone)]
struct Selection {
    /// Run only these benchmarks (default: the whole set; see `cargo perf list`).
    #[arg(long = "bench")]
    benches: Vec<String>,
    /// Growth of a count that fails, as a fraction.
    #[arg(long, default_value_t = gate::DEFAULT_THRESHOLD)]
    threshold: f64,
    /// Turn off a skip of the step in the step benchmarks: a planted regression the gate must catch.
    #[arg(long, hide = true)]
    plant_regression: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Count the current build and compare with the recorded baseline (the default command).
    Gate(Selection),
    /// Count the current build and print the figures.
    Count(Selection),
    /// From a clean tree: count, gate against the previous record, time the peers, append to the history
    /// and rewrite reports/perf.md.
    Record {
        /// The heavier wall-time peer run (more pairs, more passes).
        #[arg(long)]
        full: bool,
        #[arg(long, default_value_t = gate::DEFAULT_THRESHOLD)]
        threshold: f64,
    },
    /// Rewrite reports/perf.md and its plots from the history.
    Page,
    /// List the benchmarks.
    List {
        /// Names only, one per line.
        #[arg(long)]
        names: bool,
    },
    /// Run one benchmark in this process (what the counter runs under valgrind).
    #[command(hide = true)]
    Exec {
        bench: String,
        #[arg(long)]
        prepared: PathBuf,
        /// The repository whose scenes and saved states the benchmark reads (default: this build's).
        #[arg(long)]
        root: Option<PathBuf>,
        #[arg(long)]
        plant_regression: bool,
    },
    /// Prepare the benchmarks' starting states natively.
    #[command(hide = true)]
    Prepare {
        #[arg(long)]
        prepared: PathBuf,
        #[arg(long)]
        root: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

struct Paths {
    root: PathBuf,
    history: PathBuf,
    accepted: PathBuf,
    reports: PathBuf,
}

fn paths() -> Paths {
    let root = workspace_root();
    Paths {
        history: root.join("reports/perf/history.csv"),
        accepted: root.join("reports/perf/accepted.toml"),
        reports: root.join("reports"),
        root,
    }
}

fn run(cli: Cli) -> anyhow::Result<bool> {
    let default = Command::Gate(Selection {
        benches: Vec::new(),
        threshold: gate::DEFAULT_THRESHOLD,
        plant_regression: false,
    });
    match cli.command.unwrap_or(default) {
        Command::Exec {
            bench,
            prepared,
            root,
            plant_regression,
        } => {
            let inputs = benches::Inputs {
                root: root.unwrap_or_else(workspace_root),
                prepared,
                plant_regression,
            };
            for (figure, work) in benches::run(&bench, &inputs).map_err(anyhow::Error::msg)? {
                println!("figure {figure} {work}");
            }
            Ok(true)
        }
        Command::Prepare { prepared, root } => {
            let inputs = benches::Inputs {
                root: root.unwrap_or_else(workspace_root),
                prepared,
                plant_regression: false,
            };
            benches::prepare(&inputs).map_err(anyhow::Error::msg)?;
            Ok(true)
        }
        Command::List { names } => {
            for b in benches::all() {
                if names {
                    println!("{}", b.name);
                } else {
                    println!(
                        "{:<22} {}",
                        b.name,
                        b.what.split_whitespace().collect::<Vec<_>>().join(" ")
                    );
                }
            }
            Ok(true)
        }
        Command::Count(sel) => {
            let p = paths();
            let counts = count_here(&p, &sel)?;
            println!("{:<40} {:>16} {:>10}", "figure", "instructions", "work");
            for c in counts {
                println!("{:<40} {:>16} {:>10}", c.figure, c.instructions, c.work);
            }
            Ok(true)
        }
        Command::Gate(sel) => run_gate(&paths(), &sel),
        Command::Record { full, threshold } => record(&paths(), full, threshold),
        Command::Page => {
            let p = paths();
            page::write(
                &p.reports,
                &history::read(&p.history)?,
                gate::DEFAULT_THRESHOLD,
            )?;
            println!("wrote {}", p.reports.join("perf.md").display());
            Ok(true)
        }
    }
}

fn key_here(prov: &Provenance) -> anyhow::Result<MachineKey> {
    let valgrind = callgrind::valgrind_version().context(
        "valgrind is not installed (Debian: apt-get install valgrind); instruction counts need it",
    )?;
    Ok(MachineKey::here(prov, Some(valgrind), 1))
}

fn count_here(p: &Paths, sel: &Selection) -> anyhow::Result<Vec<callgrind::Count>> {
    let exe = std::env::current_exe().context("locating the perf binary")?;
    let options = CountOptions {
        benches: sel.benches.clone(),
        plant_regression: sel.plant_regression,
    };
    Ok(count_all(
        &exe,
        &p.root,
        &work_dir(&p.root).join("head"),
        &options,
    )?)
}

/// The counts a run is compared with.
struct Baseline {
    commit: String,
    counts: FigureCounts,
    /// Counted in this run from the commit's own tree (the history had none under this key).
    measured_now: bool,
}

/// The baseline of HEAD: its newest recorded ancestor, and that commit's counts under `key` — from the
/// history, or counted now from its own tree when the history has none under this key.
fn baseline_counts(
    p: &Paths,
    history: &[Row],
    key: &MachineKey,
    skip_commit: Option<&str>,
    benches: &[String],
) -> anyhow::Result<Option<Baseline>> {
    let ancestry: Vec<String> = baseline::git(&p.root, &["rev-list", "HEAD"])?
        .lines()
        .map(str::to_string)
        .collect();
    let recorded = gate::recorded_ancestors(history, &ancestry);
    let Some(commit) = recorded
        .into_iter()
        .find(|c| Some(c.as_str()) != skip_commit)
    else {
        return Ok(None);
    };
    let counts = gate::counts_of(history, &commit, key);
    if !counts.is_empty() {
        return Ok(Some(Baseline {
            commit,
            counts,
            measured_now: false,
        }));
    }
    let theirs = history
        .iter()
        .find(|r| r.is_count() && r.commit == commit)
        .map(|r| r.key.clone());
    if let Some(theirs) = theirs {
        eprintln!(
            "perf: the history's counts of {commit} were taken under another key ({}); counting {commit} here",
            key.differences(&theirs).join("; ")
        );
    }
    let counts = baseline::count_at(&p.root, &commit, &work_dir(&p.root), benches)?;
    Ok(Some(Baseline {
        commit,
        counts,
        measured_now: true,
    }))
}

fn print_verdicts(verdicts: &[Verdict], baseline: &str, measured_now: bool, threshold: f64) {
    println!(
        "baseline {baseline} ({}); threshold +{:.1} %",
        if measured_now {
            "counted now from its own tree"
        } else {
            "recorded in reports/perf/history.csv"
        },
        threshold * 100.0
    );
    println!(
        "{:<40} {:>14} {:>14} {:>9} {:>13}  status",
        "figure", "baseline", "now", "ratio", "work"
    );
    for v in verdicts {
        let num = |x: Option<(u64, u64)>, i: usize| {
            x.map_or("—".to_string(), |t| {
                if i == 0 { t.0 } else { t.1 }.to_string()
            })
        };
        let status = match &v.status {
            Status::Pass => "ok".to_string(),
            Status::Accepted(why) => format!("accepted: {why}"),
            Status::Regressed => "REGRESSED".to_string(),
            Status::New => "new".to_string(),
            Status::Missing => "missing now".to_string(),
        };
        println!(
            "{:<40} {:>14} {:>14} {:>9} {:>13}  {status}",
            v.figure,
            num(v.baseline, 0),
            num(v.now, 0),
            v.ratio().map_or("—".to_string(), |r| format!("{r:.5}")),
            format!("{}→{}", num(v.baseline, 1), num(v.now, 1)),
        );
    }
}

fn regressed(verdicts: &[Verdict]) -> Vec<&str> {
    verdicts
        .iter()
        .filter(|v| v.status == Status::Regressed)
        .map(|v| v.figure.as_str())
        .collect()
}

fn run_gate(p: &Paths, sel: &Selection) -> anyhow::Result<bool> {
    let history = history::read(&p.history)?;
    let accepted = gate::read_accepted(&p.accepted)?;
    let prov = Provenance::collect(&p.root);
    let key = key_here(&prov)?;
    let now = by_figure(&count_here(p, sel)?);
    let Some(Baseline {
        commit,
        counts: mut base,
        measured_now,
    }) = baseline_counts(p, &history, &key, None, &sel.benches)?
    else {
        println!("no recorded commit among the ancestors of HEAD: nothing to compare with (record one with `cargo perf record`)");
        return Ok(true);
    };
    if !sel.benches.is_empty() {
        base.retain(|figure, _| now.contains_key(figure));
    }
    let verdicts = gate::compare(&now, &base, &commit, sel.threshold, &accepted);
    print_verdicts(&verdicts, &commit, measured_now, sel.threshold);
    let bad = regressed(&verdicts);
    if bad.is_empty() {
        println!("perf gate: passed ({} figures)", verdicts.len());
        Ok(true)
    } else {
        println!(
            "perf gate: FAILED: {} figure(s) grew by more than {:.1} % against {commit}: {}. If the growth is \
             the price of a change you want, accept it in {} (figure, baseline = \"{commit}\", max_ratio, reason).",
            bad.len(),
            sel.threshold * 100.0,
            bad.join(", "),
            p.accepted.display()
        );
        Ok(false)
    }
}

fn record(p: &Paths, full: bool, threshold: f64) -> anyhow::Result<bool> {
    let prov = Provenance::collect(&p.root);
    if prov.commit.ends_with("-dirty") || prov.commit == "unknown" {
        bail!(
            "`cargo perf record` records figures of a commit, so it needs a clean tree (HEAD is {}); commit or stash first",
            prov.commit
        );
    }
    let history = history::read(&p.history)?;
    let accepted = gate::read_accepted(&p.accepted)?;
    let key = key_here(&prov)?;
    if !gate::counts_of(&history, &prov.commit, &key).is_empty() {
        bail!(
            "{} is recorded under this machine's key already",
            prov.commit
        );
    }
    let sel = Selection {
        benches: Vec::new(),
        threshold,
        plant_regression: false,
    };
    let counts = count_here(p, &sel)?;
    let now = by_figure(&counts);
    let mut rows: Vec<Row> = Vec::new();
    if let Some(Baseline {
        commit,
        counts: base,
        measured_now,
    }) = baseline_counts(p, &history, &key, Some(&prov.commit), &[])?
    {
        let verdicts = gate::compare(&now, &base, &commit, threshold, &accepted);
        print_verdicts(&verdicts, &commit, measured_now, threshold);
        let bad = regressed(&verdicts);
        if !bad.is_empty() {
            println!(
                "not recorded: {} grew by more than {:.1} % against {commit}; accept it in {} first",
                bad.join(", "),
                threshold * 100.0,
                p.accepted.display()
            );
            return Ok(false);
        }
        if measured_now {
            // The baseline counted under this key is a record of its own: the next gate on this machine
            // compares with it instead of building it again.
            rows.extend(
                base.iter()
                    .map(|(f, &(n, w))| Row::count(&commit, &prov.date, &key, f, n, w)),
            );
        }
    }
    rows.extend(counts.iter().map(|c| {
        Row::count(
            &prov.commit,
            &prov.date,
            &key,
            &c.figure,
            c.instructions,
            c.work,
        )
    }));
    eprintln!(
        "perf: timing the contact core against parry3d-f64 ({})",
        if full { "full" } else { "quick" }
    );
    let wall_key = MachineKey {
        valgrind: String::new(),
        ..key.clone()
    };
    let sizes = if full { peers::FULL } else { peers::QUICK };
    rows.extend(
        peers::contact_vs_parry(sizes, &prov.commit, &prov.date, &wall_key)
            .map_err(anyhow::Error::msg)?,
    );
    history::append(&p.history, &rows)?;
    let all = history::read(&p.history)?;
    page::write(&p.reports, &all, threshold)?;
    println!(
        "recorded {} rows of {} in {}; wrote {}",
        rows.len(),
        prov.commit,
        p.history.display(),
        p.reports.join("perf.md").display()
    );
    Ok(true)
}
