//! The latency and bandwidth of this machine's MPI: rank 0 sends a message to rank 1, which sends it back,
//! many times for each size; half the mean round trip is the one-way time of that size.

use std::path::Path;
use std::time::Instant;

use polydem_mpi::mpi::traits::*;

use crate::Error;

/// Message sizes (bytes) and round trips of each.
const SIZES: [(usize, u32); 7] = [
    (8, 2000),
    (64, 2000),
    (512, 2000),
    (4096, 1000),
    (32768, 400),
    (262144, 100),
    (1048576, 40),
];

/// The CSV header of `pingpong.csv`.
pub const HEADER: &str = "bytes,round_trips,one_way_s,load_before,load_after";

fn load_one() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|t| t.split_whitespace().next().and_then(|f| f.parse().ok()))
        .unwrap_or(f64::NAN)
}

/// Runs the ping-pong on ranks 0 and 1 (others wait); rank 0 writes `csv`.
pub fn pingpong(csv: &Path) -> Result<(), Error> {
    let universe = polydem_mpi::mpi::initialize().ok_or("MPI was already initialised")?;
    let comm = universe.world();
    if comm.size() < 2 {
        return Err("the ping-pong needs two ranks (mpirun -n 2)".into());
    }
    let rank = comm.rank();
    let mut text = format!("{HEADER}\n");
    for (bytes, trips) in SIZES {
        let mut buf = vec![0u8; bytes];
        comm.barrier();
        let load_before = load_one();
        let start = Instant::now();
        for _ in 0..trips {
            match rank {
                0 => {
                    comm.process_at_rank(1).send(&buf[..]);
                    comm.process_at_rank(1).receive_into(&mut buf[..]);
                }
                1 => {
                    comm.process_at_rank(0).receive_into(&mut buf[..]);
                    comm.process_at_rank(0).send(&buf[..]);
                }
                _ => {}
            }
        }
        let one_way = start.elapsed().as_secs_f64() / (2.0 * f64::from(trips));
        text.push_str(&format!(
            "{bytes},{trips},{one_way:e},{load_before},{}\n",
            load_one()
        ));
    }
    if rank == 0 {
        std::fs::write(csv, text).map_err(|e| format!("{}: {e}", csv.display()))?;
        println!("ping-pong written to {}", csv.display());
    }
    Ok(())
}
