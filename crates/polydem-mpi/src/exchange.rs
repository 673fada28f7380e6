//! The messages of a distributed run: ghost states after every step, bodies and contact entries at a cut.
//!
//! A ghost's state travels as 19 numbers (position, velocity, orientation quaternion, angular momentum,
//! force, torque), bit for bit; the receiver knows from the plan which ghost each block fills, so no index
//! travels. At a migration near ranks send each other the bodies and contact entries they take over, point
//! to point (after a re-bisection, from any rank to any rank). They are encoded with postcard, which keeps
//! each f64's bits.

use mpi::datatype::PartitionMut;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use mpi::Count;
use polydem::dynamics::RigidBody;
use polydem::math::{Real, Rotation, Vector};
use serde::{de::DeserializeOwned, Serialize};

use crate::error::DistributedError;

/// Numbers per ghost in the exchange after each step.
pub const GHOST_WORDS: usize = 19;

/// Bytes and messages a rank sent (payload only: MPI's own headers are not counted).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Traffic {
    /// Bytes sent.
    pub bytes: u64,
    /// Messages sent (one per destination rank with data).
    pub messages: u64,
}

impl std::ops::AddAssign for Traffic {
    fn add_assign(&mut self, other: Self) {
        self.bytes += other.bytes;
        self.messages += other.messages;
    }
}

/// What a rank sent, by kind of exchange.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RunTraffic {
    /// Ghost states and loads after each step.
    pub ghosts: Traffic,
    /// The rebuild agreements (an all-reduce of four numbers at each stage 3).
    pub agreements: Traffic,
    /// The whole state gathered at each cut.
    pub cuts: Traffic,
    /// The bodies gathered for the caller (outputs, checks).
    pub gathers: Traffic,
    /// What rank 0 received from the other ranks for the outputs ([`gather_to_root`]; zero elsewhere).
    pub received_at_root: Traffic,
}

/// Appends body `body`'s state with its loads to `out`.
pub fn pack_ghost(body: &RigidBody, force: &Vector, torque: &Vector, out: &mut Vec<Real>) {
    let (x, v, l) = (&body.position, &body.velocity, &body.angular_momentum);
    let q = &body.orientation.coords;
    // One slice of known length: the vector grows once per body, not once per number.
    let words: [Real; GHOST_WORDS] = [
        x.x, x.y, x.z, v.x, v.y, v.z, q[0], q[1], q[2], q[3], l.x, l.y, l.z, force.x, force.y,
        force.z, torque.x, torque.y, torque.z,
    ];
    out.extend_from_slice(&words);
}

/// The state of `template` (its mass properties and motion kept) with the block `w` written over it, and
/// the loads of the block.
pub fn unpack_ghost(template: &RigidBody, w: &[Real]) -> (RigidBody, Vector, Vector) {
    let v = |k: usize| Vector::new(w[k], w[k + 1], w[k + 2]);
    let mut body = *template;
    body.position = v(0).into();
    body.velocity = v(3);
    let q = nalgebra::Quaternion::from(nalgebra::Vector4::new(w[6], w[7], w[8], w[9]));
    body.orientation = Rotation::new_unchecked(q);
    body.angular_momentum = v(10);
    (body, v(13), v(16))
}

/// The tag of the ghost exchange's messages.
const GHOST_TAG: mpi::Tag = 16;

/// Sends `blocks[q]` to each rank q whose block is not empty and returns what each rank sent here
/// (`expected[q]` numbers from q, concatenated in rank order), point to point: a rank exchanges with the
/// ranks it shares ghosts with only. A rank expects numbers from q exactly when q's block for it is not
/// empty (the send and receive lists of a part are two views of one plan).
pub fn exchange_ghost_states(
    comm: &SimpleCommunicator,
    blocks: &[Vec<Real>],
    expected: &[usize],
    traffic: &mut Traffic,
) -> Vec<Real> {
    let me = comm.rank() as usize;
    let mut recv = vec![0.0; expected.iter().sum()];
    let messages = blocks.iter().filter(|b| !b.is_empty()).count()
        + expected.iter().filter(|&&n| n > 0).count();
    mpi::request::multiple_scope(messages, |scope, requests| {
        let mut rest = &mut recv[..];
        for (q, &n) in expected.iter().enumerate() {
            let (mine, others) = rest.split_at_mut(n);
            rest = others;
            if q != me && n > 0 {
                let from = comm.process_at_rank(q as i32);
                requests.add(from.immediate_receive_into_with_tag(scope, mine, GHOST_TAG));
            }
        }
        for (q, block) in blocks.iter().enumerate() {
            if q != me && !block.is_empty() {
                let to = comm.process_at_rank(q as i32);
                requests.add(to.immediate_send_with_tag(scope, &block[..], GHOST_TAG));
                traffic.bytes += (block.len() * std::mem::size_of::<Real>()) as u64;
                traffic.messages += 1;
            }
        }
        let mut done = Vec::new();
        requests.wait_all(&mut done);
    });
    recv
}

/// The tag of the messages of a migration (the only point-to-point messages of a run).
const MIGRATION_TAG: mpi::Tag = 17;

/// Sends the bytes `blocks[q]` to each rank q of `near` other than this one, and returns what each of them
/// sent here (empty for the other ranks), in rank order: one message each way per pair of near ranks, an
/// empty one included, so no count travels. `near` must be symmetric (q is near p where p is near q).
pub fn exchange_with_near(
    comm: &SimpleCommunicator,
    near: &[usize],
    blocks: &[Vec<u8>],
    traffic: &mut Traffic,
) -> Vec<Vec<u8>> {
    let me = comm.rank() as usize;
    let others: Vec<usize> = near.iter().copied().filter(|&q| q != me).collect();
    let mut received = vec![Vec::new(); blocks.len()];
    mpi::request::multiple_scope(others.len(), |scope, sends| {
        for &q in &others {
            let to = comm.process_at_rank(q as i32);
            sends.add(to.immediate_send_with_tag(scope, &blocks[q][..], MIGRATION_TAG));
            traffic.bytes += blocks[q].len() as u64;
            traffic.messages += 1;
        }
        for &q in &others {
            let from = comm.process_at_rank(q as i32);
            received[q] = from.receive_vec_with_tag::<u8>(MIGRATION_TAG).0;
        }
        let mut done = Vec::new();
        sends.wait_all(&mut done);
    });
    received
}

/// Gathers `value` from every rank, in rank order.
pub fn all_gather<T: Serialize + DeserializeOwned>(
    comm: &SimpleCommunicator,
    value: &T,
    traffic: &mut Traffic,
) -> Result<Vec<T>, DistributedError> {
    let bytes = postcard::to_allocvec(value).expect("encoding to memory does not fail");
    let size = comm.size() as usize;
    let mut counts = vec![0 as Count; size];
    comm.all_gather_into(&(bytes.len() as Count), &mut counts[..]);
    let mut all = vec![0u8; counts.iter().map(|&c| c as usize).sum()];
    let displs = displacements(&counts);
    comm.all_gather_varcount_into(
        &bytes[..],
        &mut PartitionMut::new(&mut all[..], counts.clone(), displs.clone()),
    );
    traffic.bytes += (bytes.len() * (size - 1)) as u64;
    traffic.messages += (size - 1) as u64;
    (0..size)
        .map(|q| {
            let (start, len) = (displs[q] as usize, counts[q] as usize);
            postcard::from_bytes(&all[start..start + len]).map_err(|e| DistributedError::Decode {
                rank: q,
                message: e.to_string(),
            })
        })
        .collect()
}

/// Gathers `value` from every rank on rank 0, in rank order (`None` on the other ranks); `traffic` counts
/// what this rank sent, `received` what rank 0 received.
pub fn gather_to_root<T: Serialize + DeserializeOwned>(
    comm: &SimpleCommunicator,
    value: &T,
    traffic: &mut Traffic,
    received: &mut Traffic,
) -> Result<Option<Vec<T>>, DistributedError> {
    let bytes = postcard::to_allocvec(value).expect("encoding to memory does not fail");
    let root = comm.process_at_rank(0);
    if comm.rank() != 0 {
        root.gather_into(&(bytes.len() as Count));
        root.gather_varcount_into(&bytes[..]);
        traffic.bytes += bytes.len() as u64;
        traffic.messages += 1;
        return Ok(None);
    }
    let mut counts = vec![0 as Count; comm.size() as usize];
    root.gather_into_root(&(bytes.len() as Count), &mut counts[..]);
    let mut all = vec![0u8; counts.iter().map(|&c| c as usize).sum()];
    received.bytes += (all.len() - bytes.len()) as u64;
    received.messages += counts.len() as u64 - 1;
    let displs = displacements(&counts);
    root.gather_varcount_into_root(
        &bytes[..],
        &mut PartitionMut::new(&mut all[..], counts.clone(), displs.clone()),
    );
    let decoded = (0..counts.len()).map(|q| {
        let (start, len) = (displs[q] as usize, counts[q] as usize);
        postcard::from_bytes(&all[start..start + len]).map_err(|e| DistributedError::Decode {
            rank: q,
            message: e.to_string(),
        })
    });
    decoded.collect::<Result<Vec<T>, _>>().map(Some)
}

fn displacements(counts: &[Count]) -> Vec<Count> {
    counts
        .iter()
        .scan(0, |offset, &c| {
            let start = *offset;
            *offset += c;
            Some(start)
        })
        .collect()
}
