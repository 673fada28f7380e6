//! Checkpoint/restart: a run of N steps and a run of N/2 steps, written to a checkpoint file, read
//! back and continued for N/2 steps end in the same state bit for bit — every body, the contact store with
//! its tangential springs, the walls, the broad phase and the energy ledger. Damaged, foreign and future
//! files are each refused with their own typed error.
//!
//! The scene is the settling box (20 polyhedra, friction, restitution, viscous damping, five fixed walls)
//! with three spheres added and a lid moving down, so that at the checkpoint there are polyhedron–polyhedron,
//! sphere and wall contacts with tangential history, and a wall pose that moved (the lid reaches the rocks
//! after the checkpoint, so its work enters the ledger in the compared part).

use polydem::dynamics::RigidBody;
use std::path::{Path, PathBuf};

use polydem::io::checkpoint::{self, CheckpointError, FORMAT_VERSION, HEADER_LEN, MAGIC};
use polydem::scene::{parse_scene, Simulation};
use polydem::world::ContactKey;

const EXTRA: &str = r#"
[[shape]]
name = "ball"
kind = "sphere"
radius = 0.02

[[body]]
name = "s0"
shape = "ball"
material = "rock"
position = [-0.05, 0.05, 0.13]
velocity = [0.3, 0.0, -0.5]

[[body]]
name = "s1"
shape = "ball"
material = "rock"
position = [0.05, -0.05, 0.13]
angular_velocity = [0.0, 5.0, 0.0]

[[body]]
name = "s2"
shape = "ball"
material = "rock"
position = [0.0, 0.1, 0.13]

[[wall]]
name = "lid"
material = "rock"
point = [0.0, 0.0, 0.2]
normal = [0.0, 0.0, -1.0]
velocity = [0.0, 0.0, -0.3]
"#;

fn scene() -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/settling_box.toml");
    let text = std::fs::read_to_string(&path).expect("settling_box.toml");
    // A pair-smoothing band other than the default, so that a non-default law parameter goes through the
    // checkpoint too; with it the rocks have 8 body–body contacts at the checkpoint (the count swings
    // between 3 and 11 over steps 5000–7000 as they bounce, whatever the band: 3 with the default band).
    let text = text.replacen(
        "[simulation]",
        "[simulation]\npair_smoothing_band = 1.0e-3",
        1,
    );
    parse_scene(&format!("{text}\n{EXTRA}"), &path).expect("scene with spheres and a lid")
}

fn run_to(sim: &mut Simulation, steps: u64) {
    sim.steps = steps;
    sim.run(|_| Ok(()), |_, _| Ok(())).expect("run");
}

fn temp_dir(case: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "polydem-io-checkpoint-{}-{case}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// First body whose state differs bitwise, with both values.
fn first_body_difference(a: &Simulation, b: &Simulation) -> Option<String> {
    for (i, (x, y)) in a.world.bodies().iter().zip(b.world.bodies()).enumerate() {
        let bits = |s: &polydem::dynamics::RigidBody| -> Vec<u64> {
            let q = s.orientation.quaternion();
            [
                s.position.x,
                s.position.y,
                s.position.z,
                s.velocity.x,
                s.velocity.y,
                s.velocity.z,
                q.w,
                q.i,
                q.j,
                q.k,
                s.angular_momentum.x,
                s.angular_momentum.y,
                s.angular_momentum.z,
            ]
            .iter()
            .map(|v| v.to_bits())
            .collect()
        };
        if bits(x) != bits(y) {
            return Some(format!("body {i}: {x:?}\n vs {y:?}"));
        }
    }
    None
}

const N: u64 = 12000;

#[test]
fn restarted_run_continues_bit_for_bit() {
    let mut straight = scene();
    run_to(&mut straight, N);

    let mut first_half = scene();
    run_to(&mut first_half, N / 2);
    // The checkpoint must carry real per-contact history, or this test would prove little.
    let store = &first_half.world.contacts();
    let sliding_history = store
        .states()
        .iter()
        .filter(|s| s.is_active() && s.history.displacement.norm() > 0.0)
        .count();
    let body_contacts = store
        .keys()
        .iter()
        .zip(store.states())
        .filter(|(k, s)| matches!(k, ContactKey::Body { .. }) && s.is_active())
        .count();
    let lid_moved = first_half.world.walls()[5].pose.translation.vector.z - 0.2;
    assert!(
        sliding_history >= 5 && body_contacts >= 5 && lid_moved < -0.05,
        "at the checkpoint (step {}): {sliding_history} active contacts with tangential history, \
         {body_contacts} body–body contacts, lid moved by {lid_moved} m; expected ≥ 5, ≥ 5, < −0.05 m",
        N / 2
    );

    let dir = temp_dir("restart");
    let file = dir.join("half.pdck");
    let bytes = checkpoint::save(&file, &first_half).expect("save");
    assert_eq!(bytes, std::fs::metadata(&file).unwrap().len());
    let mut restarted = checkpoint::load(&file).expect("load").simulation;
    assert_eq!(restarted.world.step_index(), N / 2);
    run_to(&mut restarted, N);

    assert_eq!(restarted.world.step_index(), N);
    if let Some(diff) = first_body_difference(&straight, &restarted) {
        panic!(
            "after {N} steps, straight vs restarted at step {}: {diff}",
            N / 2
        );
    }
    assert_eq!(
        straight.world.ledger(),
        restarted.world.ledger(),
        "energy ledger after {N} steps"
    );
    assert_eq!(
        straight.world.time().to_bits(),
        restarted.world.time().to_bits()
    );
    assert_eq!(
        straight.world.walls(),
        restarted.world.walls(),
        "wall poses"
    );
    assert_eq!(
        straight.world.contacts(),
        restarted.world.contacts(),
        "contact store (keys, tangential springs, warm starts, geometry)"
    );
    // The whole state, every byte: the checkpoints of both end states are identical.
    let a = checkpoint::encode(&straight).unwrap();
    let b = checkpoint::encode(&restarted).unwrap();
    assert!(
        a == b,
        "checkpoints of the straight and the restarted end states differ ({} vs {} bytes)",
        a.len(),
        b.len()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The comparison above can fail: restarting with the tangential history and warm starts dropped (an empty
/// contact store, as a checkpoint of the bodies alone would give) ends elsewhere.
#[test]
fn restart_without_the_contact_store_diverges() {
    let mut straight = scene();
    run_to(&mut straight, N);
    let mut half = scene();
    run_to(&mut half, N / 2);
    let mut bytes_restored = checkpoint::decode(&checkpoint::encode(&half).unwrap())
        .unwrap()
        .simulation;
    bytes_restored.world.clear_contacts();
    run_to(&mut bytes_restored, N);
    assert!(
        first_body_difference(&straight, &bytes_restored).is_some(),
        "dropping the contact store at step {} left every body bitwise unchanged after {N} steps",
        N / 2
    );
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn damaged_foreign_and_future_files_are_refused_with_typed_errors() {
    let mut sim = scene();
    run_to(&mut sim, 50);
    let good = checkpoint::encode(&sim).unwrap();
    assert_eq!(&good[..8], &MAGIC);
    let dir = temp_dir("refused");

    // Truncated anywhere in the payload, or inside the header.
    for cut in [good.len() - 1, good.len() / 2, HEADER_LEN, HEADER_LEN - 3] {
        let p = write(&dir, "truncated.pdck", &good[..cut]);
        match checkpoint::load(&p) {
            Err(CheckpointError::Truncated { expected, actual }) => {
                assert_eq!(actual, cut as u64);
                assert!(expected > actual, "expected {expected} > actual {actual}");
            }
            other => panic!("file cut to {cut} of {} bytes: {other:?}", good.len()),
        }
    }
    // Appended bytes.
    let mut longer = good.clone();
    longer.extend_from_slice(b"xx");
    let p = write(&dir, "longer.pdck", &longer);
    assert!(
        matches!(
            checkpoint::load(&p),
            Err(CheckpointError::TrailingData { extra: 2 })
        ),
        "{:?}",
        checkpoint::load(&p)
    );
    // One flipped bit at several places of the payload: the checksum catches each.
    for at in [HEADER_LEN, HEADER_LEN + 100, good.len() / 2, good.len() - 1] {
        let mut bad = good.clone();
        bad[at] ^= 0x10;
        let p = write(&dir, "flipped.pdck", &bad);
        match checkpoint::load(&p) {
            Err(e @ CheckpointError::Checksum { .. }) => {
                assert!(e.to_string().contains("checksum"), "message: {e}")
            }
            other => panic!("bit flipped at byte {at}: {other:?}"),
        }
    }
    // A flipped checksum byte itself.
    let mut bad = good.clone();
    bad[HEADER_LEN - 1] ^= 1;
    let p = write(&dir, "flipped_crc.pdck", &bad);
    assert!(matches!(
        checkpoint::load(&p),
        Err(CheckpointError::Checksum { .. })
    ));
    // Foreign files: a scene file, an empty file, a PNG signature.
    let scene_text =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/settling_box.toml"))
            .unwrap();
    for (name, bytes) in [
        ("scene.toml", scene_text.as_slice()),
        ("empty", &[][..]),
        ("image.png", &b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR"[..]),
    ] {
        let p = write(&dir, name, bytes);
        let err = checkpoint::load(&p).expect_err(name);
        assert!(
            matches!(err, CheckpointError::NotACheckpoint),
            "{name}: {err:?}"
        );
        assert!(
            err.to_string().contains("not a polydem checkpoint"),
            "{err}"
        );
    }
    // A future format version.
    let mut future = good.clone();
    future[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    let p = write(&dir, "future.pdck", &future);
    match checkpoint::load(&p) {
        Err(CheckpointError::UnsupportedVersion { found, supported }) => {
            assert_eq!((found, supported), (FORMAT_VERSION + 1, FORMAT_VERSION))
        }
        other => panic!("future version: {other:?}"),
    }
    // A missing file.
    assert!(matches!(
        checkpoint::load(&dir.join("missing.pdck")),
        Err(CheckpointError::Io { .. })
    ));
    // The good bytes still load.
    assert_eq!(
        checkpoint::decode(&good)
            .unwrap()
            .simulation
            .world
            .step_index(),
        50
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A payload that passes the checksum but describes an impossible state (here: a body referring to a shape
/// that does not exist) is refused before any step could index out of range.
#[test]
fn inconsistent_state_with_a_valid_checksum_is_refused() {
    let mut sim = scene();
    run_to(&mut sim, 10);
    // The API keeps shape indices valid: the impossible state is written into the serialised world.
    let mut state = serde_json::to_value(&sim.world).expect("world to JSON");
    state["shape_of"][3] = 99.into();
    sim.world = serde_json::from_value(state).expect("world from JSON");
    let bytes = checkpoint::encode(&sim).unwrap();
    match checkpoint::decode(&bytes) {
        Err(CheckpointError::Invalid { what }) => {
            assert!(
                what.contains("body 3") && what.contains("shape 99"),
                "{what}"
            )
        }
        other => panic!("body with shape 99: {other:?}"),
    }
}

/// Format version 10 added the run identity (an `Option<u64>` after the engine version); a version-9 file
/// — the same payload without it — still reads, as the same simulation with no identity.
#[test]
fn a_version_9_checkpoint_reads_as_the_same_state_without_a_run_identity() {
    let mut sim = scene();
    run_to(&mut sim, 50);
    let v10 = checkpoint::encode_in_run(&sim, Some(0x1234)).unwrap();
    let back = checkpoint::decode(&v10).unwrap();
    assert_eq!(back.run, Some(0x1234), "the run identity round-trips");
    // Rebuild the version-9 layout: drop the identity (a postcard `None` is one zero byte) that follows the
    // engine version (a one-byte length and its bytes).
    let none = checkpoint::encode(&sim).unwrap();
    let payload = &none[HEADER_LEN..];
    let version_len = payload[0] as usize;
    assert!(version_len < 128, "a one-byte varint length");
    assert_eq!(payload[1 + version_len], 0, "the None of the run identity");
    let mut v9_payload = payload[..1 + version_len].to_vec();
    v9_payload.extend_from_slice(&payload[2 + version_len..]);
    let mut v9 = none[..HEADER_LEN].to_vec();
    v9[8..12].copy_from_slice(&9u32.to_le_bytes());
    v9[16..24].copy_from_slice(&(v9_payload.len() as u64).to_le_bytes());
    v9[24..28].copy_from_slice(&crc32fast::hash(&v9_payload).to_le_bytes());
    v9.extend_from_slice(&v9_payload);
    let old = checkpoint::decode(&v9).expect("a version-9 file reads");
    assert_eq!(old.run, None);
    assert_eq!(
        checkpoint::encode(&old.simulation).unwrap(),
        none,
        "the version-9 file's state re-encodes to the same bytes"
    );
}

/// A checkpoint whose stored state is not finite (a NaN quaternion, an infinite velocity) is refused
/// naming the body and the quantity, instead of being stepped into NaN output.
#[test]
fn a_checkpoint_with_a_non_finite_body_state_is_refused() {
    let mut sim = scene();
    run_to(&mut sim, 10);
    let good = sim.clone();
    type Damage = fn(&mut Simulation);
    let cases: [(&str, Damage); 3] = [
        ("orientation", |s| {
            let q = s.world.bodies()[2].orientation.quaternion().coords;
            let nan = nalgebra::Quaternion::new(f64::NAN, q.x, q.y, q.z);
            let edit =
                |b: &mut RigidBody| b.orientation = nalgebra::UnitQuaternion::new_unchecked(nan);
            s.world.edit_body(2, edit).expect("body 2");
        }),
        ("velocity", |s| {
            let edit = |b: &mut RigidBody| b.velocity.y = f64::INFINITY;
            s.world.edit_body(2, edit).expect("body 2")
        }),
        ("position", |s| {
            let edit = |b: &mut RigidBody| b.position.z = f64::NAN;
            s.world.edit_body(2, edit).expect("body 2")
        }),
    ];
    for (what, damage) in cases {
        let mut bad = good.clone();
        damage(&mut bad);
        let bytes = checkpoint::encode(&bad).unwrap();
        match checkpoint::decode(&bytes) {
            Err(CheckpointError::Invalid { what: message }) => assert!(
                message.contains("body 2") && message.contains(what),
                "{what}: {message}"
            ),
            other => panic!("{what} damaged: {other:?}"),
        }
    }
    checkpoint::decode(&checkpoint::encode(&good).unwrap()).expect("the undamaged state reads");
}
