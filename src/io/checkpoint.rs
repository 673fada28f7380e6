//! Checkpoints: the complete state of a [`Simulation`] in a versioned binary file, from which a run
//! continues bit for bit as if it had never stopped.
//!
//! # File layout (all integers little-endian)
//! ```text
//! offset  size  field
//!      0     8  magic           b"PDEMCKPT"
//!      8     4  format version  u32 (this build writes and reads FORMAT_VERSION)
//!     12     4  reserved        u32, zero
//!     16     8  payload length  u64, bytes that follow the header
//!     24     4  checksum        u32, CRC-32 (IEEE, as in zip/PNG) of the payload
//!     28     n  payload         postcard encoding of [`CheckpointPayload`]
//! ```
//! The file ends exactly after the payload. Reading checks, in this order: the magic (else
//! [`CheckpointError::NotACheckpoint`]), the version ([`CheckpointError::UnsupportedVersion`]), the length
//! ([`CheckpointError::Truncated`] / [`CheckpointError::TrailingData`]), the checksum
//! ([`CheckpointError::Checksum`]), the decoding ([`CheckpointError::Decode`]) and the consistency of the
//! decoded state — array lengths and every index (bodies, shapes, materials, walls, contact pairs, polyhedron
//! topology) — so that a file that passes can never make a later step panic ([`CheckpointError::Invalid`]).
//!
//! # What is saved
//! The whole [`Simulation`]: every body (pose, velocity, angular momentum, mass properties, motion), the
//! shape table (polyhedra with their topology and principal frame), the material-pair laws, the walls at
//! their current (moved) poses, the contact store with each pair's tangential spring and GJK/EPA warm-start
//! cache, the broad phase's pair list and the centres it was built at (so it rebuilds at the same step), the
//! loads of the last evaluation (the next half kick uses them), the energy ledger, time and step count, step
//! parameters, the time-step derivation, end time, output interval, tracked bodies and input frames. Scratch
//! buffers (`StepScratch`, the broad phase's grid, the store's merge buffers) are not saved: nothing in them
//! survives a step. f64 values are stored as their 8 bytes, so the state read back is bitwise the state
//! written; `tests/io_checkpoint.rs` proves that a run interrupted and restarted ends bitwise where the
//! uninterrupted run does.
//!
//! # Versions
//! The payload is the serde layout of the engine's types: a change to any serialised type (a field added,
//! removed or reordered) changes the layout, and must bump [`FORMAT_VERSION`]. Version 10 added the run
//! identity to the payload; version 9 files (the same state without it) are still read. A file of any
//! other version is refused, never guessed at. The engine version that wrote a file is recorded in the
//! payload.
//!
//! Writing goes to `FILE.tmp` first and renames it, so a crash never leaves a half-written file under the
//! final name. The user documentation is `docs/checkpoint-format.md`.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::dynamics::RigidBody;
use crate::scene::Simulation;
use crate::shape::Shape;
use crate::world::{ContactKey, World};

/// The first eight bytes of every checkpoint.
pub const MAGIC: [u8; 8] = *b"PDEMCKPT";
/// The format version this build writes.
pub const FORMAT_VERSION: u32 = 10;
/// The earlier version this build still reads: its payload is version 10's without the run identity.
pub const PREVIOUS_VERSION: u32 = 9;
/// Bytes before the payload.
pub const HEADER_LEN: usize = 28;

/// What a checkpoint holds.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CheckpointPayload {
    /// `CARGO_PKG_VERSION` of the polydem that wrote the file (informative).
    pub engine_version: String,
    /// The identity of the run that wrote it ([`crate::io::run_identity`]); `None` for a file written
    /// outside a run or by a version-9 build.
    pub run: Option<u64>,
    /// The simulation: world, parameters and run state.
    pub simulation: Simulation,
}

/// The payload of a version-9 file.
#[derive(serde::Deserialize)]
struct PayloadV9 {
    engine_version: String,
    simulation: Simulation,
}

/// Why a checkpoint could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// The file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The file does not start with the checkpoint magic bytes.
    #[error(
        "not a polydem checkpoint (the file does not start with the magic bytes \"PDEMCKPT\")"
    )]
    NotACheckpoint,
    /// The file's format version is not one this build reads.
    #[error("checkpoint format version {found} is not supported by this build (it reads versions 9 to {supported})")]
    UnsupportedVersion {
        /// Version found in the file.
        found: u32,
        /// Newest version this build reads.
        supported: u32,
    },
    /// The file is shorter than its header says.
    #[error("truncated checkpoint: {expected} bytes expected ({HEADER_LEN}-byte header + payload), the file has {actual}")]
    Truncated {
        /// Bytes the header announces (header and payload).
        expected: u64,
        /// Bytes the file has.
        actual: u64,
    },
    /// The file has bytes after the payload.
    #[error("corrupt checkpoint: {extra} bytes after the end of the payload")]
    TrailingData {
        /// Number of extra bytes.
        extra: u64,
    },
    /// The payload's CRC-32 does not match the one stored in the header.
    #[error("corrupt checkpoint: payload checksum {computed:#010x} does not match the stored {stored:#010x}")]
    Checksum {
        /// Checksum stored in the header.
        stored: u32,
        /// Checksum of the payload read.
        computed: u32,
    },
    /// The payload cannot be decoded.
    #[error("checkpoint payload cannot be decoded ({message}); it was written by a build with another layout or is damaged")]
    Decode {
        /// The decoder's message.
        message: String,
    },
    /// The decoded state is inconsistent (e.g. per-body arrays of different lengths).
    #[error("checkpoint state is inconsistent: {what}")]
    Invalid {
        /// Which invariant.
        what: String,
    },
    /// The state could not be encoded.
    #[error("cannot encode the checkpoint: {message}")]
    Encode {
        /// The encoder's message.
        message: String,
    },
}

/// Encodes `sim` into the checkpoint format (header + payload), with no run identity.
pub fn encode(sim: &Simulation) -> Result<Vec<u8>, CheckpointError> {
    encode_in_run(sim, None)
}

/// Encodes `sim` as a checkpoint of the run `run`.
pub fn encode_in_run(sim: &Simulation, run: Option<u64>) -> Result<Vec<u8>, CheckpointError> {
    let payload = CheckpointPayload {
        engine_version: env!("CARGO_PKG_VERSION").to_owned(),
        run,
        simulation: sim.clone(),
    };
    encode_payload(&payload)
}

fn encode_payload(payload: &CheckpointPayload) -> Result<Vec<u8>, CheckpointError> {
    let mut out = Vec::with_capacity(HEADER_LEN);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&[0; 12]); // length and checksum, filled below
    let mut out = postcard::to_extend(payload, out).map_err(|e| CheckpointError::Encode {
        message: e.to_string(),
    })?;
    let len = (out.len() - HEADER_LEN) as u64;
    let crc = crc32fast::hash(&out[HEADER_LEN..]);
    out[16..24].copy_from_slice(&len.to_le_bytes());
    out[24..28].copy_from_slice(&crc.to_le_bytes());
    Ok(out)
}

/// Decodes a checkpoint (see the module docs for the checks, in order).
pub fn decode(bytes: &[u8]) -> Result<CheckpointPayload, CheckpointError> {
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err(CheckpointError::NotACheckpoint);
    }
    let u32_at = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")))
    };
    let header_short = || CheckpointError::Truncated {
        expected: HEADER_LEN as u64,
        actual: bytes.len() as u64,
    };
    let version = u32_at(8).ok_or_else(header_short)?;
    if version != FORMAT_VERSION && version != PREVIOUS_VERSION {
        return Err(CheckpointError::UnsupportedVersion {
            found: version,
            supported: FORMAT_VERSION,
        });
    }
    if bytes.len() < HEADER_LEN {
        return Err(header_short());
    }
    let len = u64::from_le_bytes(bytes[16..24].try_into().expect("8 bytes"));
    let stored = u32_at(24).expect("header checked");
    let available = (bytes.len() - HEADER_LEN) as u64;
    if available < len {
        return Err(CheckpointError::Truncated {
            expected: HEADER_LEN as u64 + len,
            actual: bytes.len() as u64,
        });
    }
    if available > len {
        return Err(CheckpointError::TrailingData {
            extra: available - len,
        });
    }
    let payload = &bytes[HEADER_LEN..];
    let computed = crc32fast::hash(payload);
    if computed != stored {
        return Err(CheckpointError::Checksum { stored, computed });
    }
    let undecodable = |e: postcard::Error| CheckpointError::Decode {
        message: e.to_string(),
    };
    let decoded = if version == PREVIOUS_VERSION {
        let old: PayloadV9 = postcard::from_bytes(payload).map_err(undecodable)?;
        CheckpointPayload {
            engine_version: old.engine_version,
            run: None,
            simulation: old.simulation,
        }
    } else {
        postcard::from_bytes::<CheckpointPayload>(payload).map_err(undecodable)?
    };
    check_consistency(&decoded.simulation).map_err(|what| CheckpointError::Invalid { what })?;
    Ok(decoded)
}

/// Writes `sim` to `path` (through `path.tmp` and a rename), with no run identity; returns the number of
/// bytes written.
pub fn save(path: &Path, sim: &Simulation) -> Result<u64, CheckpointError> {
    save_in_run(path, sim, None)
}

/// [`save`] for a checkpoint of the run `run`.
pub fn save_in_run(
    path: &Path,
    sim: &Simulation,
    run: Option<u64>,
) -> Result<u64, CheckpointError> {
    let bytes = encode_in_run(sim, run)?;
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    let io = |path: &Path| {
        let path = path.to_owned();
        move |source| CheckpointError::Io { path, source }
    };
    // Synced before the rename and the directory after it: once this returns, the checkpoint survives a
    // crash of the machine, not only of the process.
    let mut file = std::fs::File::create(&tmp).map_err(io(&tmp))?;
    file.write_all(&bytes)
        .and_then(|()| file.sync_all())
        .map_err(io(&tmp))?;
    drop(file);
    std::fs::rename(&tmp, path).map_err(io(path))?;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::File::open(dir)
        .and_then(|d| d.sync_all())
        .map_err(io(dir))?;
    Ok(bytes.len() as u64)
}

/// Reads the checkpoint at `path`.
pub fn load(path: &Path) -> Result<CheckpointPayload, CheckpointError> {
    let bytes = std::fs::read(path).map_err(|source| CheckpointError::Io {
        path: path.to_owned(),
        source,
    })?;
    decode(&bytes)
}

/// Every length and index of a decoded simulation that a step relies on; the first problem found.
/// A body's state is finite, its mass positive and its orientation a unit quaternion (to rounding of the
/// products that built it: 1e-9 is far above the drift of a long run and far below any damage).
fn check_body_state(body: &RigidBody) -> Result<(), String> {
    let finite = |v: &crate::math::Vector| v.iter().all(|x| x.is_finite());
    let q = body.orientation.quaternion();
    let checks = [
        (finite(&body.position.coords), "position"),
        (finite(&body.velocity), "velocity"),
        (finite(&body.angular_momentum), "angular momentum"),
        (
            q.coords.iter().all(|x| x.is_finite()) && (q.norm() - 1.0).abs() <= 1e-9,
            "orientation",
        ),
        (body.mass.is_finite() && body.mass > 0.0, "mass"),
    ];
    match checks.iter().find(|(ok, _)| !ok) {
        Some((_, what)) => Err(format!(
            "{what} is not finite or not valid (position {:?}, velocity {:?}, orientation {:?}, mass {})",
            body.position.coords.as_slice(),
            body.velocity.as_slice(),
            q.coords.as_slice(),
            body.mass
        )),
        None => Ok(()),
    }
}

fn check_consistency(sim: &Simulation) -> Result<(), String> {
    let w = &sim.world;
    let n = w.bodies().len();
    check_lengths(sim)?;
    for (k, shape) in w.shapes().iter().enumerate() {
        if let Shape::Polyhedron(p) = shape {
            p.check_structure().map_err(|e| format!("shape {k}: {e}"))?;
        }
    }
    for i in 0..n {
        check_body(w, i)?;
    }
    if !(w.time().is_finite() && sim.params.dt.is_finite() && sim.params.dt > 0.0) {
        return Err(format!(
            "time {} s, time step {} s",
            w.time(),
            sim.params.dt
        ));
    }
    for (k, wall) in w.walls().iter().enumerate() {
        if wall.material as usize >= w.materials().len() {
            return Err(format!(
                "wall {k} ('{}'): material {} of {}",
                wall.name,
                wall.material,
                w.materials().len()
            ));
        }
    }
    if let Some(&t) = sim.tracked.iter().find(|&&t| t >= n) {
        return Err(format!("tracked body {t} of {n}"));
    }
    check_loads(w)?;
    check_contacts(w)?;
    if let Some(p) = w
        .broad_phase()
        .pairs()
        .iter()
        .find(|&&(i, j)| !(i < j && (j as usize) < n))
    {
        return Err(format!("broad-phase pair {p:?} out of range"));
    }
    if sim.output_every == 0 {
        return Err("output interval of 0 steps".into());
    }
    Ok(())
}

/// Every per-body table has one entry per body.
fn check_lengths(sim: &Simulation) -> Result<(), String> {
    let w = &sim.world;
    let n = w.bodies().len();
    let lengths = [
        ("shape_of", w.shape_indices().len()),
        ("material_of", w.body_materials().len()),
        ("radii", w.radii().len()),
        ("names", w.names().len()),
        ("frames", sim.frames.len()),
    ];
    for (what, len) in lengths {
        if len != n {
            return Err(format!("{n} bodies but {len} entries in {what}"));
        }
    }
    Ok(())
}

/// Body `i`'s shape and material exist, its shape is not a plane, its radius and state are valid.
fn check_body(w: &World, i: usize) -> Result<(), String> {
    let name = &w.names()[i];
    match w.shapes().get(w.shape_indices()[i] as usize) {
        None => {
            return Err(format!(
                "body {i} ('{name}'): shape {} of {}",
                w.shape_indices()[i],
                w.shapes().len()
            ))
        }
        Some(Shape::Plane(_)) => return Err(format!("body {i} ('{name}'): a plane shape")),
        Some(_) => {}
    }
    if w.body_materials()[i] as usize >= w.materials().len() {
        return Err(format!(
            "body {i} ('{name}'): material {} of {}",
            w.body_materials()[i],
            w.materials().len()
        ));
    }
    if !(w.radii()[i].is_finite() && w.radii()[i] >= 0.0) {
        return Err(format!(
            "body {i} ('{name}'): bounding radius {}",
            w.radii()[i]
        ));
    }
    check_body_state(&w.bodies()[i]).map_err(|what| format!("body {i} ('{name}'): {what}"))
}

/// Current loads, when stored, cover every body and wall.
fn check_loads(w: &World) -> Result<(), String> {
    let n = w.bodies().len();
    if w.loads().is_current()
        && (w.loads().forces().len() != n
            || w.loads().torques().len() != n
            || w.loads().wall_forces().len() != w.walls().len())
    {
        return Err(format!(
            "loads for {} / {} bodies and {} walls, world has {n} bodies and {} walls",
            w.loads().forces().len(),
            w.loads().torques().len(),
            w.loads().wall_forces().len(),
            w.walls().len()
        ));
    }
    Ok(())
}

/// The contact store has a state per key, its keys strictly sorted and naming existing bodies and walls.
fn check_contacts(w: &World) -> Result<(), String> {
    let n = w.bodies().len();
    let keys = w.contacts().keys();
    if keys.len() != w.contacts().states().len() {
        return Err(format!(
            "contact store: {} keys, {} states",
            keys.len(),
            w.contacts().states().len()
        ));
    }
    if !keys.windows(2).all(|k| k[0] < k[1]) {
        return Err("contact store keys are not strictly sorted".into());
    }
    let key_ok = |k: &ContactKey| match *k {
        ContactKey::Body { a, b } => a < b && (b as usize) < n,
        ContactKey::Wall { body, wall } => (body as usize) < n && (wall as usize) < w.walls().len(),
    };
    if let Some(k) = keys.iter().find(|k| !key_ok(k)) {
        return Err(format!("contact store key {k:?} out of range"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_inputs_are_refused_without_panicking() {
        for len in 0..HEADER_LEN {
            let mut bytes = MAGIC.to_vec();
            bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
            bytes.resize(HEADER_LEN, 0);
            bytes.truncate(len);
            let err = decode(&bytes).expect_err("a header alone is not a checkpoint");
            if len < MAGIC.len() {
                assert!(
                    matches!(err, CheckpointError::NotACheckpoint),
                    "{len}: {err}"
                );
            } else {
                assert!(
                    matches!(err, CheckpointError::Truncated { .. }),
                    "{len}: {err}"
                );
            }
        }
    }
}
