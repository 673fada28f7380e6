//! The rockfill penetration writes its files through the engine's `Output` trait: `monitors.csv` holds
//! the header and one row per step formatted by `MonitorRow::csv_row` (the format the study writes), is
//! not written by an interrupted run, and the VTK frames of the run are byte for byte the frames the
//! engine's `VtkWriter` writes of the same world.

use polydem::io::vtk::{VtkEncoding, VtkWriter};
use polydem_rockfill::config::ExperimentConfig;
use polydem_rockfill::experiment::{run_experiment_with, BedSource, ExperimentError};
use polydem_rockfill::penetration::{
    MonitorRow, PenetrationError, PenetrationFiles, PenetrationOptions,
};
use polydem_rockfill::stop::StopCheck;

const STEPS: u64 = 5;

fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("polydem_{tag}_{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    dir
}

fn quick() -> ExperimentConfig {
    ExperimentConfig::load(&root().join("scenes/rockfill/quick.toml"))
        .expect("scenes/rockfill/quick.toml loads")
}

#[test]
fn monitors_and_vtk_frames_of_the_quick_bed_go_through_the_engine_outputs() {
    let dir = temp_dir("rockfill_outputs");
    let options = PenetrationOptions {
        max_steps: Some(STEPS),
        files: Some(PenetrationFiles {
            vtk_every: Some(1),
            ..PenetrationFiles::monitors_in(&dir)
        }),
        ..Default::default()
    };
    let bed = root().join("reference/rockfill/quick_bed");
    let result = run_experiment_with(&quick(), BedSource::Load(&bed), &options, &mut |_, _| {})
        .expect("the quick penetration runs from the saved bed");
    let rows = &result.penetration.rows;
    assert_eq!(rows.len() as u64, STEPS, "one monitor row per step");
    let mut expected = format!("{}\n", MonitorRow::CSV_HEADER);
    for row in rows {
        expected.push_str(&row.csv_row());
        expected.push('\n');
    }
    let written = std::fs::read_to_string(dir.join("monitors.csv")).expect("monitors.csv written");
    assert!(
        written == expected,
        "monitors.csv in {}: {} bytes, expected the header and {} rows ({} bytes)",
        dir.display(),
        written.len(),
        rows.len(),
        expected.len()
    );

    // The last frame against the engine's writer on the world the run ended with.
    let reference = temp_dir("rockfill_outputs_reference");
    let world = &result.world;
    let mut writer = VtkWriter::new(&reference, world, VtkEncoding::default()).unwrap();
    writer.write_frame(world).unwrap();
    let kinds = writer.kinds();
    assert!(!kinds.is_empty(), "the bed has series to write");
    for kind in kinds {
        let frame = format!("vtk/{}_{:09}.vtu", kind.name(), world.step_index());
        let ours = std::fs::read(dir.join(&frame)).expect("the run wrote its last frame");
        let theirs = std::fs::read(reference.join(&frame)).unwrap();
        assert!(
            ours == theirs,
            "{frame}: {} bytes from the run, {} from VtkWriter on the same world",
            ours.len(),
            theirs.len()
        );
        let pvd = std::fs::read_to_string(dir.join(format!("{}.pvd", kind.name()))).unwrap();
        let frames = pvd.matches("<DataSet ").count() as u64;
        assert_eq!(
            frames,
            STEPS + 1,
            "{}.pvd: the start and every step",
            kind.name()
        );
    }
    std::fs::remove_dir_all(&dir).ok();
    std::fs::remove_dir_all(&reference).ok();
}

#[test]
fn an_interrupted_penetration_writes_no_monitors() {
    let dir = temp_dir("rockfill_outputs_interrupted");
    let steps = std::sync::atomic::AtomicU64::new(0);
    let stop = move || steps.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= 3;
    let options = PenetrationOptions {
        max_steps: Some(STEPS),
        stop: Some(StopCheck::new(stop)),
        files: Some(PenetrationFiles::monitors_in(&dir)),
        ..Default::default()
    };
    let bed = root().join("reference/rockfill/quick_bed");
    let err = run_experiment_with(&quick(), BedSource::Load(&bed), &options, &mut |_, _| {})
        .expect_err("the run is stopped after 3 steps");
    assert!(
        matches!(
            err,
            ExperimentError::Penetration(PenetrationError::Interrupted { steps: 3 })
        ),
        "stopped after 3 of {STEPS} steps: {err}"
    );
    assert!(
        !dir.join("monitors.csv").exists(),
        "{}: an interrupted run writes no monitors.csv",
        dir.display()
    );
    std::fs::remove_dir_all(&dir).ok();
}
