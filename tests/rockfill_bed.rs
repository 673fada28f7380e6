//! The packed bed saved as an engine checkpoint ("the packed bed saved as a checkpoint so each
//! penetration run starts from it"): the penetration run from the saved bed is the run straight after
//! packing, every monitor row bitwise equal, and takes the experiment file's contact laws (a changed rock
//! density is refused); the study and convergence drivers write their tables; the ZY section of a cube is
//! its square.

use polydem::math::{Point, Pose};
use polydem_rockfill::bed::{has_checkpoint, load_bed_info};
use polydem_rockfill::convergence::{run_convergence, ConvergenceParams, Sequence};
use polydem_rockfill::experiment::{run_experiment_with, BedSource};
use polydem_rockfill::penetration::{MonitorRow, PenetrationOptions};
use polydem_rockfill::section::section_polygon;
use polydem_rockfill::study::{run_study, StudyParams, StudyRun};

#[path = "support/rockfill_small.rs"]
mod rockfill_small;
use rockfill_small::small;

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("polydem_{tag}_{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    dir
}

fn bits(row: &MonitorRow) -> Vec<u64> {
    let mut v: Vec<u64> = [
        row.time,
        row.axial_force,
        row.velocity_deflection,
        row.axis_deflection,
    ]
    .iter()
    .map(|x| x.to_bits())
    .collect();
    for p in [row.position.coords, row.tip.coords, row.velocity, row.force] {
        v.extend(p.iter().map(|x| x.to_bits()));
    }
    v.push(row.contacts as u64);
    v
}

#[test]
fn penetration_from_the_saved_bed_equals_penetration_straight_after_packing() {
    let config = small();
    let dir = temp_dir("bed_checkpoint");
    let options = PenetrationOptions::default();
    let mut quiet = |_: &str, _: String| {};
    let straight = run_experiment_with(
        &config,
        BedSource::Generate { save: Some(&dir) },
        &options,
        &mut quiet,
    )
    .unwrap();
    assert!(
        has_checkpoint(&dir),
        "no bed checkpoint in {}",
        dir.display()
    );
    let info = load_bed_info(&dir).unwrap().expect("bed_info.json written");
    assert_eq!(info.rocks, straight.packing.as_ref().unwrap().rocks);
    let reloaded =
        run_experiment_with(&config, BedSource::Load(&dir), &options, &mut quiet).unwrap();
    assert!(reloaded.bed_from_checkpoint);
    let (a, b) = (&straight.penetration.rows, &reloaded.penetration.rows);
    assert_eq!(
        a.len(),
        b.len(),
        "steps: straight {} vs from the saved bed {}",
        a.len(),
        b.len()
    );
    for (k, (ra, rb)) in a.iter().zip(b).enumerate() {
        assert_eq!(
            bits(ra),
            bits(rb),
            "monitor row {k} differs: straight {ra:?}, from the saved bed {rb:?}"
        );
    }

    // The experiment file's contact laws apply to a bed read from its checkpoint (not the laws stored in
    // it), and say so; a changed rock density is refused.
    let mut stiffer = config;
    stiffer.contact.normal_stiffness *= 4.0;
    let mut notes = Vec::new();
    let mut record = |stage: &str, msg: String| notes.push(format!("{stage}: {msg}"));
    let stiff =
        run_experiment_with(&stiffer, BedSource::Load(&dir), &options, &mut record).unwrap();
    assert!(
        notes.iter().any(|n| n.contains("contact laws differ")),
        "no note of the changed laws among {notes:?}"
    );
    let energy =
        |r: &polydem_rockfill::experiment::ExperimentResult| r.penetration.projectile_energy_loss;
    assert!(
        energy(&stiff) != energy(&straight),
        "k_n x 4 from the saved bed: the projectile lost {} J, as with the bed's own laws ({} J): \
         the file's laws were not applied",
        energy(&stiff),
        energy(&straight)
    );
    let mut denser = config;
    denser.rock.density *= 1.5;
    match run_experiment_with(&denser, BedSource::Load(&dir), &options, &mut quiet) {
        Err(e) => assert!(
            e.to_string().contains("density"),
            "a changed rock density: expected an error naming the density, got '{e}'"
        ),
        Ok(_) => panic!(
            "a bed packed at {} kg/m³ ran with rock.density {} kg/m³",
            config.rock.density, denser.rock.density
        ),
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn study_and_convergence_write_their_tables() {
    // Two tiny sizes of one seed at a reduced cross-section of 2 rock sizes, then the time-step sequence
    // from the first run's bed.
    let mut base = small();
    base.layer.length = 0.9;
    let out = temp_dir("study");
    let params = StudyParams {
        base,
        sizes_mm: vec![290.0, 320.0],
        seeds: vec![3],
        section_sizes: Some(2.0),
        reuse_beds: false,
        out: out.clone(),
        label: "test".into(),
    };
    let mut lines = Vec::new();
    let runs = run_study(&params, &mut |l| lines.push(l)).unwrap();
    assert_eq!(runs.len(), 2, "runs {runs:?}");
    let csv = std::fs::read_to_string(out.join("runs.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "runs.csv:\n{csv}");
    assert!(csv.starts_with(StudyRun::CSV_HEADER));
    let table = std::fs::read_to_string(out.join("study.md")).unwrap();
    assert!(
        table.contains("| 290 |") && table.contains("| 320 |"),
        "{table}"
    );
    assert!(out.join("s290mm_seed3/section.svg").is_file());
    assert!(!lines.is_empty());
    for r in &runs {
        assert!(r.generation_s.is_finite() && r.packing_s.is_finite() && r.penetration_s > 0.0);
        assert!(
            (r.width - 2.0 * r.size_mm * 1e-3).abs() < 1e-12 * r.width,
            "width {} for {} mm",
            r.width,
            r.size_mm
        );
    }
    // Resuming reuses the saved beds: same residual speed bit for bit.
    let resumed = run_study(
        &StudyParams {
            reuse_beds: true,
            ..params.clone()
        },
        &mut |_| {},
    )
    .unwrap();
    for (a, b) in runs.iter().zip(&resumed) {
        assert_eq!(b.bed, "checkpoint");
        assert_eq!(
            a.residual_speed.to_bits(),
            b.residual_speed.to_bits(),
            "{} mm: residual {} vs resumed {}",
            a.size_mm,
            a.residual_speed,
            b.residual_speed
        );
    }
    let mut config = params.base;
    config.rock.mean_size = 0.29;
    config.layer.width = 0.58;
    config.layer.height = 0.58;
    let conv = run_convergence(
        &ConvergenceParams {
            base: config,
            dt_divisors: vec![1.0, 2.0],
            sections: Vec::new(),
            out: out.join("convergence"),
            bed: Some(out.join("s290mm_seed3")),
            label: "test".into(),
        },
        &mut |_| {},
    )
    .unwrap();
    let seq = conv.sequence(Sequence::TimeStep);
    assert_eq!(seq.len(), 2);
    assert!(
        (seq[0].dt / seq[1].dt - 2.0).abs() < 1e-12,
        "dt {} and {}",
        seq[0].dt,
        seq[1].dt
    );
    // The Δt run equals the study's run from the same bed.
    assert_eq!(
        seq[0].residual_speed.to_bits(),
        runs[0].residual_speed.to_bits()
    );
    assert!(out.join("convergence/work_precision.svg").is_file());
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn zy_section_of_a_cube_is_its_square() {
    use polydem::shape::{ConvexPolyhedron, Shape};
    use polydem::world::World;
    let half = 0.2;
    let corners: Vec<Point> = (0..8)
        .map(|k| {
            Point::new(
                if k & 1 == 0 { -half } else { half },
                if k & 2 == 0 { -half } else { half },
                if k & 4 == 0 { -half } else { half },
            )
        })
        .collect();
    let (cube, frame) = ConvexPolyhedron::from_points(&corners).unwrap();
    let config = small();
    let mut world: World = polydem_rockfill::packing::empty_world(&config, 0.01).unwrap();
    // The principal frame of the hull composed with the placement, as the bed loader does.
    let pose = Pose::translation(1.0, 2.0, 3.0) * frame;
    let body = polydem_rockfill::packing::body_for(&cube, &pose, config.rock.density).unwrap();
    let shape = world.add_shape(Shape::Polyhedron(std::sync::Arc::new(cube)));
    world.add_body("cube", shape, 0, body).unwrap();
    // Cut off-centre so that no vertex lies on the plane.
    let poly = section_polygon(&world, 0, &world.pose(0), 1.05);
    let area: f64 = (0..poly.len())
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            a.0 * b.1 - b.0 * a.1
        })
        .sum::<f64>()
        * 0.5;
    let expected = (2.0 * half) * (2.0 * half);
    assert!(
        (area - expected).abs() < 1e-12 * expected,
        "section area {area}, expected {expected} (polygon {poly:?})"
    );
    for (y, z) in &poly {
        assert!(
            ((y - 2.0).abs() - half).abs() < 1e-12 || ((z - 3.0).abs() - half).abs() < 1e-12,
            "point ({y}, {z}) not on the square's boundary"
        );
    }
}
