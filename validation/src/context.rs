//! What a running case writes to: its checks, its page (markdown), its tables and plots, its progress.
//!
//! With an output directory, tables and plots are written at once under `<out>/<case>/`; without one
//! (library use, `cargo test` gates) only the checks and the page text are kept.

use std::fmt::Write as _;
use std::path::PathBuf;

use crate::check::{format_value, Check, Target};
use crate::error::SuiteError;
use crate::plot::Plot;
use crate::progress::Progress;

/// The sink a case writes its results into.
pub struct CaseContext {
    case: String,
    out: Option<PathBuf>,
    checks: Vec<Check>,
    page: String,
    progress: Progress,
}

impl CaseContext {
    /// `out` is the report root (`reports/`); `None` keeps everything in memory.
    pub fn new(case: &str, out: Option<PathBuf>, progress: Progress) -> Self {
        CaseContext {
            case: case.to_string(),
            out,
            checks: Vec::new(),
            page: String::new(),
            progress,
        }
    }

    /// The case name.
    pub fn case(&self) -> &str {
        &self.case
    }

    /// Whether plots and tables are written to disk (false in gates).
    pub fn writes_files(&self) -> bool {
        self.out.is_some()
    }

    /// Records a checked quantity; pass/fail is computed here from the target, never given by the case.
    pub fn check(&mut self, metric: &str, value: f64, target: Target, unit: &str) -> bool {
        let pass = target.holds(value);
        self.checks.push(Check {
            case: self.case.clone(),
            metric: metric.to_string(),
            value,
            target,
            unit: unit.to_string(),
            pass,
        });
        pass
    }

    /// Appends a markdown heading (level 2) to the page.
    pub fn section(&mut self, title: &str) {
        let _ = write!(self.page, "\n## {title}\n\n");
    }

    /// Appends markdown text (a paragraph) to the page.
    pub fn text(&mut self, markdown: &str) {
        self.page.push_str(markdown.trim_end());
        self.page.push_str("\n\n");
    }

    /// Appends a table to the page; with `csv_name`, also writes it to `<case>/<csv_name>.csv`.
    pub fn table(
        &mut self,
        csv_name: Option<&str>,
        headers: &[&str],
        rows: &[Vec<String>],
    ) -> Result<(), SuiteError> {
        let _ = writeln!(self.page, "| {} |", headers.join(" | "));
        let _ = writeln!(self.page, "|{}", "---|".repeat(headers.len()));
        for row in rows {
            let _ = writeln!(self.page, "| {} |", row.join(" | "));
        }
        self.page.push('\n');
        if let (Some(name), Some(dir)) = (csv_name, self.case_dir()?) {
            let path = dir.join(format!("{name}.csv"));
            let mut w = csv::Writer::from_path(&path).map_err(SuiteError::csv(&path))?;
            w.write_record(headers).map_err(SuiteError::csv(&path))?;
            for row in rows {
                w.write_record(row).map_err(SuiteError::csv(&path))?;
            }
            w.flush().map_err(SuiteError::io(&path))?;
            let _ = writeln!(self.page, "Data: [{name}.csv]({}/{name}.csv)\n", self.case);
        }
        Ok(())
    }

    /// Renders a plot (SVG + CSV under `<case>/`) and links both from the page.
    pub fn plot(&mut self, plot: &Plot) -> Result<(), SuiteError> {
        let hidden: Vec<String> = plot
            .hidden_points()
            .into_iter()
            .filter(|(_, n)| *n > 0)
            .map(|(label, n)| format!("{n} point(s) of `{label}`"))
            .collect();
        if let Some(dir) = self.case_dir()? {
            plot.write_svg(&dir.join(format!("{}.svg", plot.name)))?;
            plot.write_csv(&dir.join(format!("{}.csv", plot.name)))?;
        }
        let _ = write!(
            self.page,
            "![{title}]({case}/{name}.svg)\n\n{caption}",
            title = plot.title,
            case = self.case,
            name = plot.name,
            caption = plot.caption.trim_end()
        );
        if !hidden.is_empty() {
            let _ = write!(
                self.page,
                " Not shown on the log axes (value ≤ 0): {}.",
                hidden.join(", ")
            );
        }
        let _ = writeln!(
            self.page,
            " Data: [{name}.csv]({case}/{name}.csv)\n",
            name = plot.name,
            case = self.case
        );
        Ok(())
    }

    /// The progress display of this case.
    pub fn progress(&mut self) -> &mut Progress {
        &mut self.progress
    }

    /// Formats a value the way the report does.
    pub fn fmt(value: f64) -> String {
        format_value(value)
    }

    /// The case's output directory `<out>/<case>/` (created), or `None` for an in-memory run.
    pub fn output_dir(&self) -> Result<Option<PathBuf>, SuiteError> {
        self.case_dir()
    }

    fn case_dir(&self) -> Result<Option<PathBuf>, SuiteError> {
        match &self.out {
            None => Ok(None),
            Some(root) => {
                let dir = root.join(&self.case);
                std::fs::create_dir_all(&dir).map_err(SuiteError::io(&dir))?;
                Ok(Some(dir))
            }
        }
    }

    /// Consumes the context: the checks, the page body and the progress display.
    pub fn finish(self) -> (Vec<Check>, String, Progress) {
        (self.checks, self.page, self.progress)
    }
}
