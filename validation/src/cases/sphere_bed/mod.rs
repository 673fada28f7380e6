//! Case `sphere_bed`: the sphere-bed penetration of `reference/sphere_bed/` run by polydem from
//! the scene files `scenes/sphere_bed_*.toml`, compared with the recorded YADE 2023.02a and LIGGGHTS 3.8.0
//! outputs of the same scene (same settled bed, same laws, same time step, same sampling).
//!
//! The yardstick is the spread between the two reference codes on the same run: polydem's projectile depth
//! history must stay within the YADE–LIGGGHTS gap of the nearer code, and the impact quantities (peak force,
//! vertical contact impulse, time to lose 90 % of the speed) and the final depth within the tolerances of
//! `validation/cases/sphere_bed.toml`, which quote the yardstick proposed with the recorded runs
//! (`reference/sphere_bed/README.md`). The quick profile compares with the recorded outputs only (the
//! codes need not be installed) and reports speed against the recorded wall times. The full profile
//! re-runs each reference code that is on the PATH (`reference/<code>/run.sh VARIANT` with `OUT_DIR`
//! under the case's output directory, never over the recorded files, right after polydem's run of the same
//! variant), compares polydem with the fresh runs as well as with the recorded ones, and takes the fresh
//! wall times for the speed rows; a code that is not installed is said so on the page and on standard
//! error, and its recorded run stands in. The speed targets are checked in the full profile only
//! (speed never gates `cargo test`): against each reference code as the median over `speed_rounds` rounds
//! of timed runs (polydem, then the codes), and two threads against one as the median over the same
//! one-thread runs, each followed by the same run on two threads.

mod compare;
mod polydem_run;
mod recorded;
mod speed;

use std::path::{Path, PathBuf};

use polydem::math::Real;
use serde::Deserialize;

use crate::case::{Case, CaseData, Profile};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::provenance::workspace_root;

use compare::Comparison;
use polydem_run::{run_polydem, Run};
use recorded::{installed, read_recorded, rerun_reference, Recorded};
use speed::{SpeedRuns, ThreadRounds};

/// The case (registered in [`crate::cases::registry`]).
pub struct SphereBed;

const NAME: &str = "sphere_bed";

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Variant {
    /// Variant name, as in `reference/sphere_bed/scene.json` and the reference CSV files.
    name: String,
    /// Scene file, relative to the repository root.
    scene: String,
    /// Steps to run (at most the scene's); fewer steps compare the first part of the run.
    steps: Option<u64>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    variants: Vec<Variant>,
    /// Whether the speed targets are checked (full profile only).
    check_speed: bool,
    /// Whether the reference codes are re-run when installed (full profile only).
    rerun_references: bool,
    /// Rounds of timed runs (polydem, then each re-run reference code) per variant behind the speed
    /// ratios: the first round is the compared runs, the others are timed only; each ratio is the median
    /// of the rounds' (default 1: the compared runs alone).
    #[serde(default = "one")]
    speed_rounds: usize,
}

fn one() -> usize {
    1
}

fn fail(msg: String) -> SuiteError {
    SuiteError::case(NAME, msg)
}

/// The case's tolerances and targets (`validation/cases/sphere_bed.toml`).
struct Limits {
    impact_rel: Real,
    final_depth_rel: Real,
    speed_over_liggghts: Real,
    speed_over_yade: Real,
    two_threads_over_one: Real,
    mean_diameter: Real,
}

impl Limits {
    fn read(data: &CaseData) -> Result<Self, SuiteError> {
        let tolerance = |name: &str| data.tolerance(NAME, name).map(|t| t.value);
        Ok(Self {
            impact_rel: tolerance("impact_rel")?,
            final_depth_rel: tolerance("final_depth_rel")?,
            speed_over_liggghts: tolerance("speed_over_liggghts")?,
            speed_over_yade: tolerance("speed_over_yade")?,
            two_threads_over_one: tolerance("two_threads_over_one")?,
            mean_diameter: data.reference(NAME, "mean_bed_diameter")?.value,
        })
    }
}

impl Params {
    /// Whether `code` is re-run in this suite run.
    fn reruns(&self, code: &str) -> bool {
        self.rerun_references && installed(code)
    }
}

/// The page's opening: where the reference outputs come from, and whether the codes are re-run.
fn intro(p: &Params) -> String {
    let mut intro = String::from(
        "Reference outputs: the recorded runs in `reference/yade/out/` and `reference/liggghts/out/` \
         (produced by `reference/*/run.sh`; dates and machine below). polydem ran the scene files named \
         below in this process.",
    );
    for (code, label) in [("yade", "YADE"), ("liggghts", "LIGGGHTS")] {
        let date = read_recorded(&workspace_root().join(format!(
            "reference/{code}/out/{}.csv",
            p.variants.first().map_or("", |v| v.name.as_str())
        )))
        .map(|r| r.date)
        .unwrap_or_else(|_| "unknown date".into());
        let line = if p.reruns(code) {
            format!(
                "{label} is installed: re-run in this suite run, right after polydem's run of each \
                 variant, into `sphere_bed/rerun/{code}/` of the report directory (the recorded runs \
                 are compared too)."
            )
        } else if p.rerun_references {
            format!("{code} not installed: compared against recorded runs of {date}.")
        } else {
            format!(
                "{label}: compared against recorded runs of {date} (this profile does not re-run the \
                 reference codes; {code} {} here).",
                if installed(code) { "is installed" } else { "is not installed" }
            )
        };
        if p.rerun_references && !p.reruns(code) {
            eprintln!("sphere_bed: {line}");
        }
        intro.push_str("\n\n");
        intro.push_str(&line);
    }
    intro
}

/// The recorded run of `code` for `variant`.
fn recorded(code: &str, variant: &str) -> Result<Recorded, SuiteError> {
    read_recorded(&workspace_root().join(format!("reference/{code}/out/{variant}.csv")))
}

/// One variant: polydem's run (and, in the full profile, its two-thread twin), the reference codes re-run
/// where installed, the comparison, the plots and the speed rows. Returns the variant's summary row.
fn run_variant(
    variant: &Variant,
    p: &Params,
    limits: &Limits,
    rerun_dir: &Path,
    ctx: &mut CaseContext,
    speed_rows: &mut Vec<Vec<String>>,
) -> Result<Vec<String>, SuiteError> {
    let yade = recorded("yade", &variant.name)?;
    let liggghts = recorded("liggghts", &variant.name)?;
    let ours = run_polydem(variant, ctx, 1)?;
    let mut threads = ThreadRounds::default();
    if p.check_speed {
        threads.round(variant, &ours, ctx)?;
    }
    // The reference codes right after polydem, on the same machine in the same suite run.
    let mut fresh: [Option<Recorded>; 2] = [None, None];
    for (slot, code) in fresh.iter_mut().zip(["yade", "liggghts"]) {
        if p.reruns(code) {
            eprintln!("sphere_bed: re-running {code} {} ...", variant.name);
            *slot = Some(rerun_reference(code, &variant.name, &rerun_dir.join(code))?);
        }
    }
    let [fresh_yade, fresh_liggghts] = &fresh;
    let t_end = *ours
        .history
        .t
        .last()
        .ok_or_else(|| fail("no samples".into()))?;
    window_text(variant, &ours, &liggghts, t_end, ctx);
    let comparison = Comparison {
        variant: &variant.name,
        ours: &ours,
        yade: &yade,
        liggghts: &liggghts,
        fresh_yade: fresh_yade.as_ref(),
        fresh_liggghts: fresh_liggghts.as_ref(),
        t_end,
    };
    let summary = comparison.against_recorded(ctx, limits)?;
    comparison.against_fresh(ctx, limits)?;
    comparison.plots(ctx)?;
    let runs = SpeedRuns {
        variant,
        runs: &comparison,
    };
    runs.report(p, limits, threads, ctx, speed_rows)?;
    Ok(summary)
}

/// The variant's section heading and what window of the run it compares.
fn window_text(
    variant: &Variant,
    ours: &Run,
    liggghts: &Recorded,
    t_end: Real,
    ctx: &mut CaseContext,
) {
    let recorded_end = *liggghts.history.t.last().unwrap_or(&0.0);
    ctx.section(&format!("{} (t ≤ {:.4} ms)", variant.name, t_end * 1e3));
    let window = if t_end < recorded_end * (1.0 - 1e-9) {
        format!(
            "This profile runs the first {} of the recorded {} steps (t ≤ {:.4} ms); every \
             quantity below is taken over that window in all three codes.",
            ours.steps,
            liggghts.steps,
            t_end * 1e3
        )
    } else {
        format!("The whole recorded run ({} steps).", ours.steps)
    };
    ctx.text(&format!(
        "Scene `{}`. {window} Largest overlap in polydem's run: {:.3} of the smaller particle's \
         diameter.",
        variant.scene, ours.max_overlap_ratio
    ));
}

impl Case for SphereBed {
    fn name(&self) -> &'static str {
        NAME
    }

    fn data(&self) -> &'static str {
        include_str!("../../../cases/sphere_bed.toml")
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(NAME, profile)?;
        let limits = Limits::read(data)?;
        let rerun_dir: PathBuf = match ctx.output_dir()? {
            Some(dir) => dir.join("rerun"),
            None => std::env::temp_dir().join(format!("polydem-sphere-bed-{}", std::process::id())),
        };
        ctx.text(&intro(&p));
        let mut speed_rows = Vec::new();
        let mut summary_rows = Vec::new();
        for variant in &p.variants {
            let row = run_variant(variant, &p, &limits, &rerun_dir, ctx, &mut speed_rows)?;
            summary_rows.push(row);
        }
        ctx.section("Summary");
        ctx.table(
            Some("summary"),
            &[
                "variant",
                "final depth polydem [mm]",
                "YADE",
                "LIGGGHTS",
                "final v_z polydem [m/s]",
                "YADE",
                "LIGGGHTS",
                "peak force polydem [N]",
                "YADE",
                "LIGGGHTS",
            ],
            &summary_rows,
        )?;
        speed::section(ctx, &speed_rows)
    }
}
