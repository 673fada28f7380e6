//! The reference codes' outputs: the recorded runs of `reference/<code>/out/` and fresh re-runs of
//! `reference/<code>/run.sh`, with the provenance lines of their headers.

use std::path::Path;

use polydem::math::Real;

use super::fail;
use crate::cases::projectile_history::History;
use crate::error::SuiteError;
use crate::provenance::workspace_root;

/// The `# key: value` provenance lines of a recorded output.
#[derive(Clone, Debug, Default)]
pub(super) struct Recorded {
    pub(super) history: History,
    pub(super) date: String,
    pub(super) machine: String,
    pub(super) wall_time_s: Real,
    pub(super) steps: Real,
    pub(super) particles: Real,
}

/// Reads `reference/<code>/out/<variant>.csv`.
pub(super) fn read_recorded(path: &Path) -> Result<Recorded, SuiteError> {
    let text = std::fs::read_to_string(path).map_err(SuiteError::io(path))?;
    let mut rec = Recorded::default();
    for line in text.lines().filter(|l| l.starts_with('#')) {
        let body = line.trim_start_matches('#').trim();
        let Some((key, value)) = body.split_once(':') else {
            continue;
        };
        let value = value.trim();
        let number = || {
            value.parse::<Real>().map_err(|_| {
                fail(format!(
                    "{}: {key}: '{value}' is not a number",
                    path.display()
                ))
            })
        };
        match key {
            "date" => rec.date = value.to_owned(),
            "machine" => rec.machine = value.to_owned(),
            "wall_time_s" => rec.wall_time_s = number()?,
            "steps" => rec.steps = number()?,
            "particles" => rec.particles = number()?,
            _ => {}
        }
    }
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let headers = reader.headers().map_err(SuiteError::csv(path))?.clone();
    let col = |name: &str| {
        headers
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| fail(format!("{}: no column '{name}'", path.display())))
    };
    let (ct, cz, cvz, cfz) = (col("t")?, col("z")?, col("vz")?, col("fz")?);
    for record in reader.records() {
        let record = record.map_err(SuiteError::csv(path))?;
        let get = |c: usize| -> Result<Real, SuiteError> {
            record
                .get(c)
                .and_then(|s| s.parse().ok())
                .ok_or_else(|| fail(format!("{}: bad row {:?}", path.display(), record)))
        };
        rec.history.t.push(get(ct)?);
        rec.history.z.push(get(cz)?);
        rec.history.vz.push(get(cvz)?);
        rec.history.fz.push(get(cfz)?);
    }
    if rec.wall_time_s <= 0.0 || rec.steps <= 0.0 || rec.particles <= 0.0 {
        return Err(fail(format!(
            "{}: the header lacks wall_time_s, steps or particles",
            path.display()
        )));
    }
    Ok(rec)
}

/// Whether `code` is an executable on the PATH.
pub(super) fn installed(code: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join(code).is_file()))
}

/// Re-runs `reference/<code>/run.sh VARIANT` with its outputs in `dir` (at the priority of this process:
/// `NICE=0`) and reads the fresh output.
pub(super) fn rerun_reference(
    code: &str,
    variant: &str,
    dir: &Path,
) -> Result<Recorded, SuiteError> {
    std::fs::create_dir_all(dir).map_err(SuiteError::io(dir))?;
    let script = workspace_root().join(format!("reference/{code}/run.sh"));
    let output = std::process::Command::new("sh")
        .arg(&script)
        .arg(variant)
        .env("OUT_DIR", dir)
        .env("NICE", "0")
        .output()
        .map_err(SuiteError::io(&script))?;
    if !output.status.success() {
        let tail = |b: &[u8]| {
            let text = String::from_utf8_lossy(b);
            let lines: Vec<&str> = text.lines().collect();
            lines[lines.len().saturating_sub(10)..].join("\n")
        };
        return Err(fail(format!(
            "{} {variant} failed ({}): {}\n{}",
            script.display(),
            output.status,
            tail(&output.stdout),
            tail(&output.stderr)
        )));
    }
    read_recorded(&dir.join(format!("{variant}.csv")))
}
