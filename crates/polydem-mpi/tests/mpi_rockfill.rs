//! The quick rockfill penetration split over 1, 2, 3 and 4 MPI ranks gives the bits of one process
//! without MPI: every body's final state and every monitor row.
//!
//! Run by `cargo test`, this binary first runs the quick penetration (`scenes/rockfill/quick.toml` from the
//! saved bed `reference/rockfill/quick_bed/`, a fixed number of impact steps) in this process without
//! MPI, writes the bits of its final bodies and monitor rows to a file, then launches itself under
//! `mpirun -n P` (MPICH's `mpirun.mpich`, or `$POLYDEM_MPIRUN`; oversubscribed on a small machine) for each
//! P. Each launched copy runs the same penetration with `PenetrationOptions::distributed`, and rank 0
//! compares FNV-1a hashes of the positions, velocities, orientations and angular velocities of every body,
//! and every monitor row word for word, with the file. A mismatch names P and the first body or row that
//! differs, and aborts every rank. The energy terms at the end (added over the ranks, so one process's up
//! to rounding) must be within [`ENERGY_TOLERANCE`] of one process's. The files rank 0 writes (the monitor
//! series and VTK frames every [`FRAME_EVERY`] steps, gathered from every rank) must be one process's
//! byte for byte.

use std::path::{Path, PathBuf};
use std::time::Instant;

use polydem::dynamics::RigidBody;
use polydem_mpi::launch::launch_each;
use polydem_mpi::mpi::traits::*;
use polydem_rockfill::config::ExperimentConfig;
use polydem_rockfill::experiment::{run_experiment_with, BedSource, ExperimentResult};
use polydem_rockfill::penetration::{MonitorRow, Outcome, PenetrationFiles, PenetrationOptions};

/// Impact steps: the tip reaches the bed's face at step 103 (0.6 m at 5.8 mm per step) and five rocks press
/// on it by step 180; the projectile's travel rebuilds the broad phase (and the subdomains are cut again)
/// every third step; on 4 ranks the projectile's centre crosses the cut at x ≈ 0.96 m at step 351 and
/// another rank owns it from there. Each step of a run oversubscribed on a small machine waits for every
/// rank in a few collectives, so the steps are kept to what shows all of this.
const STEPS: u64 = 360;
const RANKS: [usize; 4] = [1, 2, 3, 4];
/// Steps between VTK frames (by step index, as the CLI's `--vtk-every`).
const FRAME_EVERY: u64 = 100;
/// The rank count whose run must see the projectile change owner.
const OWNER_CHANGE_RANKS: usize = 4;
/// How far an energy term added over the ranks may be from one process's, relative to the largest term:
/// the same contributions grouped by rank, whose rounding differs by at most about n ε of the sum of their
/// magnitudes (n: up to ~10^4 contributions per sum, ε = 1.1e-16).
const ENERGY_TOLERANCE: f64 = 1e-12;

fn main() {
    match std::env::var("POLYDEM_MPI_EXPECTED") {
        Ok(expected) => child(Path::new(&expected)),
        Err(_) => launch(),
    }
}

/// Where a run of `label` (`one`, or a rank count) writes its files, for the launch with files `base`.
fn files_dir(base: &str, label: &str) -> PathBuf {
    PathBuf::from(format!("{base}_{label}"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The quick penetration, in one process or split over the ranks, writing its monitors and VTK frames
/// into `out` (rank 0 only, split over ranks).
fn penetrate(distributed: bool, out: &Path) -> ExperimentResult {
    let config = ExperimentConfig::load(&root().join("scenes/rockfill/quick.toml"))
        .expect("scenes/rockfill/quick.toml loads");
    let _ = std::fs::remove_dir_all(out);
    let files = PenetrationFiles {
        vtk_every: Some(FRAME_EVERY),
        ..PenetrationFiles::monitors_in(out)
    };
    let options = PenetrationOptions {
        max_steps: Some(STEPS),
        distributed,
        files: Some(files),
        ..Default::default()
    };
    let bed = root().join("reference/rockfill/quick_bed");
    run_experiment_with(&config, BedSource::Load(&bed), &options, &mut |_, _| {})
        .unwrap_or_else(|e| panic!("the quick penetration (distributed: {distributed}): {e}"))
}

fn launch() {
    let start = Instant::now();
    let base = std::env::temp_dir().join(format!("polydem_mpi_rockfill_{}", std::process::id()));
    let base = base.display().to_string();
    let expected = penetrate(false, &files_dir(&base, "one"));
    let report = &expected.penetration;
    let contacts = report.rows.last().map_or(0, |r| r.contacts);
    assert_eq!(
        (report.outcome, report.steps),
        (Outcome::StepLimit, STEPS),
        "the quick penetration must stop at the step limit"
    );
    assert!(
        contacts >= 2,
        "after {STEPS} steps the projectile must be among the rocks: {contacts} rocks press on it, expected at \
         least 2"
    );
    println!(
        "one process, no MPI: {STEPS} steps in {:.1} s, {contacts} rocks on the projectile, {} broad-phase \
         rebuilds",
        start.elapsed().as_secs_f64(),
        report.counters.broad_rebuilds
    );
    let file =
        std::env::temp_dir().join(format!("polydem_mpi_rockfill_{}.txt", std::process::id()));
    let text = expected_text(
        expected.world.bodies(),
        &report.rows,
        &energy_terms(&expected),
    );
    std::fs::write(&file, text).unwrap_or_else(|e| panic!("writing {}: {e}", file.display()));

    let exe = std::env::current_exe().expect("the test binary's path");
    let failures = launch_each("rockfill quick", &RANKS, &exe, |c| {
        c.env("POLYDEM_MPI_EXPECTED", &file)
            .env("POLYDEM_MPI_FILES", &base);
    });
    let _ = std::fs::remove_file(&file);
    assert!(
        failures.is_empty(),
        "distributed runs that failed: {failures:?} (their files are kept in {base}_*)"
    );
    for label in ["one", "1", "2", "3", "4"] {
        let _ = std::fs::remove_dir_all(files_dir(&base, label));
    }
}

fn child(expected: &Path) {
    let universe = polydem_mpi::mpi::initialize().expect("MPI initialised once");
    let comm = universe.world();
    let start = Instant::now();
    let base = std::env::var("POLYDEM_MPI_FILES").expect("the launcher names the files' place");
    let out = files_dir(&base, &comm.size().to_string());
    let result = penetrate(true, &out);
    let elapsed = start.elapsed().as_secs_f64();
    let report = &result.penetration;
    let facts = report.ranks.expect("a distributed run reports its ranks");
    let per_step = |bytes: u64| bytes as f64 / STEPS as f64;
    println!(
        "rank {}/{}: {:.1} owned, {:.1} ghosts on average, {} cuts ({} bisections), {} projectile owner changes, {elapsed:.2} s; \
         sent per step: ghosts {:.0} B, agreements {:.0} B, cuts {:.0} B, gathers {:.0} B",
        facts.rank,
        facts.ranks,
        facts.mean_owned,
        facts.mean_ghosts,
        facts.cuts,
        facts.bisections,
        facts.projectile_owner_changes,
        per_step(facts.ghost_bytes),
        per_step(facts.agreement_bytes),
        per_step(facts.cut_bytes),
        per_step(facts.gather_bytes),
    );
    if comm.rank() == 0 {
        let text = std::fs::read_to_string(expected)
            .unwrap_or_else(|e| panic!("reading {}: {e}", expected.display()));
        let (bodies, rows, energy) = parse_expected(&text);
        let ranks = comm.size();
        let compared = compare(&bodies, result.world.bodies(), &rows, &report.rows)
            .and_then(|()| compare_files(&out, &files_dir(&base, "one")))
            .and_then(|()| compare_energy(&energy, &energy_terms(&result)));
        let worst = compared.unwrap_or_else(|message| {
            eprintln!("rockfill quick on {ranks} ranks after {STEPS} steps: {message}");
            comm.abort(1)
        });
        // The bits above must hold across a change of the projectile's owner (its row and contacts then
        // come from another rank), so the largest split must show one.
        if ranks as usize == OWNER_CHANGE_RANKS && facts.projectile_owner_changes == 0 {
            eprintln!(
                "rockfill quick on {ranks} ranks after {STEPS} steps: the projectile never changed owner \
                 (measured 0 changes, expected at least 1): the test would not check a hand-over"
            );
            comm.abort(1);
        }
        println!(
            "rockfill quick on {ranks} ranks after {STEPS} steps: the same bits as one process ({} bodies, {} \
             monitor rows, the same files); energy terms within {worst:.1e} of the largest",
            bodies.len(),
            rows.len()
        );
    }
}

/// One hashed quantity of a body, as its numbers.
type Quantity = fn(&RigidBody) -> Vec<f64>;

const QUANTITIES: [(&str, Quantity); 4] = [
    ("positions", |b| b.position.coords.iter().copied().collect()),
    ("velocities", |b| b.velocity.iter().copied().collect()),
    ("orientations", |b| {
        b.orientation.coords.iter().copied().collect()
    }),
    ("angular velocities", |b| {
        b.angular_velocity().iter().copied().collect()
    }),
];

/// The bodies (as their hashed quantities, in order), the rows (as their words) and the energy terms (as
/// their bits) of one process.
type Expected = (Vec<Vec<u64>>, Vec<Vec<u64>>, Vec<u64>);

/// The whole world's energy terms at the end of a run: time, kinetic, potential, ledger and balance.
fn energy_terms(result: &ExperimentResult) -> Vec<f64> {
    let e = result.world.energy();
    vec![
        e.time,
        e.translational_kinetic,
        e.rotational_kinetic,
        e.elastic_potential,
        e.gravitational_potential,
        e.dissipated_damping,
        e.dissipated_friction,
        e.dissipated_viscous,
        e.external_work,
        e.tangential_stiffness_work,
        e.balance,
    ]
}

/// The largest difference between `got` and one process's energy terms (`expected`, as bits) relative to
/// their largest magnitude; an error past [`ENERGY_TOLERANCE`].
fn compare_energy(expected: &[u64], got: &[f64]) -> Result<f64, String> {
    let expected: Vec<f64> = expected.iter().map(|&w| f64::from_bits(w)).collect();
    let scale = expected.iter().map(|v| v.abs()).fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    for (k, (a, b)) in got.iter().zip(&expected).enumerate() {
        let relative = (a - b).abs() / scale;
        if relative.is_nan() || relative > ENERGY_TOLERANCE {
            return Err(format!(
                "energy term {k} (time, kinetic ×2, elastic, gravity, damping, friction, viscous, external, \
                 stiffness, balance) {a:e}, one process {b:e}: {relative:.2e} of the largest term {scale:e} \
                 (tolerance {ENERGY_TOLERANCE:e})"
            ));
        }
        worst = worst.max(relative);
    }
    Ok(worst)
}

/// Every file under `expected` (one process's) against the one of the same path under `got`, byte for
/// byte, and no other file there.
fn compare_files(got: &Path, expected: &Path) -> Result<(), String> {
    let (mine, theirs) = (files_under(got), files_under(expected));
    if mine
        .iter()
        .map(|(p, _)| p)
        .ne(theirs.iter().map(|(p, _)| p))
    {
        let names = |f: &[(PathBuf, Vec<u8>)]| f.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>();
        return Err(format!(
            "files {:?} in {}, one process wrote {:?}",
            names(&mine),
            got.display(),
            names(&theirs)
        ));
    }
    if theirs
        .iter()
        .filter(|(p, _)| p.extension().is_some_and(|e| e == "vtu"))
        .count()
        < 3
    {
        return Err(format!(
            "fewer than 3 VTK frames in {}: nothing to compare",
            expected.display()
        ));
    }
    for ((path, a), (_, b)) in mine.iter().zip(&theirs) {
        if a != b {
            let at = a
                .iter()
                .zip(b)
                .position(|(x, y)| x != y)
                .unwrap_or(a.len().min(b.len()));
            return Err(format!(
                "{} differs from one process's (sizes {} and {}, first at byte {at})",
                got.join(path).display(),
                a.len(),
                b.len()
            ));
        }
    }
    Ok(())
}

/// The files under `dir` (relative paths, sorted) with their bytes.
fn files_under(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let entries = std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display()));
        for entry in entries {
            let path = entry.expect("a directory entry").path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let bytes =
                    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                let relative = path.strip_prefix(dir).expect("under dir").to_path_buf();
                files.push((relative, bytes));
            }
        }
    }
    files.sort();
    files
}

/// One line per body (the bits of its four quantities), then one per row (the bits of its words), then
/// the energy terms' bits.
fn expected_text(bodies: &[RigidBody], rows: &[MonitorRow], energy: &[f64]) -> String {
    let line = |words: Vec<u64>| {
        let hex: Vec<String> = words.iter().map(|w| format!("{w:016x}")).collect();
        hex.join(" ")
    };
    let mut text = String::new();
    for body in bodies {
        text += &format!("body {}\n", line(body_words(body)));
    }
    for row in rows {
        text += &format!("row {}\n", line(row_words(row)));
    }
    text += &format!(
        "energy {}\n",
        line(energy.iter().map(|v| v.to_bits()).collect())
    );
    text
}

fn parse_expected(text: &str) -> Expected {
    let (mut bodies, mut rows, mut energy) = (Vec::new(), Vec::new(), Vec::new());
    for line in text.lines() {
        let (kind, words) = line.split_once(' ').expect("a kind and words");
        let words: Vec<u64> = words
            .split(' ')
            .map(|w| u64::from_str_radix(w, 16).expect("hex words"))
            .collect();
        match kind {
            "body" => bodies.push(words),
            "energy" => energy = words,
            _ => rows.push(words),
        }
    }
    (bodies, rows, energy)
}

fn body_words(body: &RigidBody) -> Vec<u64> {
    QUANTITIES
        .iter()
        .flat_map(|(_, of)| of(body))
        .map(f64::to_bits)
        .collect()
}

/// Every number of a monitor row, bit for bit (the count of touching rocks as an integer).
fn row_words(row: &MonitorRow) -> Vec<u64> {
    let mut numbers = vec![row.time];
    numbers.extend(row.position.coords.iter());
    numbers.extend(row.tip.coords.iter());
    numbers.extend(row.velocity.iter());
    numbers.extend(row.force.iter());
    numbers.extend([
        row.axial_force,
        row.velocity_deflection,
        row.axis_deflection,
    ]);
    let mut words: Vec<u64> = numbers.into_iter().map(f64::to_bits).collect();
    words.push(row.contacts as u64);
    words
}

/// The first difference between one process's bodies and rows and the distributed run's, if any.
fn compare(
    bodies: &[Vec<u64>],
    got: &[RigidBody],
    rows: &[Vec<u64>],
    got_rows: &[MonitorRow],
) -> Result<(), String> {
    if got.len() != bodies.len() || got_rows.len() != rows.len() {
        return Err(format!(
            "{} bodies and {} rows, one process {} and {}",
            got.len(),
            got_rows.len(),
            bodies.len(),
            rows.len()
        ));
    }
    let got_words: Vec<Vec<u64>> = got.iter().map(body_words).collect();
    let mut offset = 0;
    for (name, of) in QUANTITIES {
        let width = of(&got[0]).len();
        let slice = |w: &[Vec<u64>]| -> Vec<Vec<u64>> {
            w.iter()
                .map(|b| b[offset..offset + width].to_vec())
                .collect()
        };
        let (expected, measured) = (slice(bodies), slice(&got_words));
        let (h_expected, h_got) = (hash(&expected), hash(&measured));
        if h_expected != h_got {
            let i = (0..expected.len())
                .find(|&i| expected[i] != measured[i])
                .expect("different hashes of different words");
            return Err(format!(
                "{name} hash {h_got:#018x}, one process {h_expected:#018x}; first at body {i}: {:?} against {:?}",
                of(&got[i]),
                expected[i].iter().map(|&w| f64::from_bits(w)).collect::<Vec<_>>()
            ));
        }
        offset += width;
    }
    for (k, (expected, row)) in rows.iter().zip(got_rows).enumerate() {
        if *expected != row_words(row) {
            let (numbers, contacts) = expected.split_at(expected.len() - 1);
            let numbers: Vec<f64> = numbers.iter().map(|&w| f64::from_bits(w)).collect();
            return Err(format!(
                "monitor row {k} (after step {}): {:?} and {} contacts, one process {numbers:?} and {} contacts \
                 (time, position, tip, velocity, force, axial force, deflections)",
                k + 1,
                &row_words(row)[..numbers.len()]
                    .iter()
                    .map(|&w| f64::from_bits(w))
                    .collect::<Vec<_>>(),
                row.contacts,
                contacts[0]
            ));
        }
    }
    Ok(())
}

/// 64-bit FNV-1a over the little-endian bytes of the words, in order.
fn hash(words: &[Vec<u64>]) -> u64 {
    let mut h: u64 = 0xcbf29ce484222325;
    for x in words.iter().flatten() {
        for byte in x.to_le_bytes() {
            h = (h ^ byte as u64).wrapping_mul(0x100000001b3);
        }
    }
    h
}
