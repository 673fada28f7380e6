#!/usr/bin/env bash
# The MPI stage of CI: installs Debian's MPICH (and libclang for rsmpi's bindgen), builds polydem-mpi and the
# command line with `--features mpi` against MPICH, and runs their MPI tests; they launch `mpirun -n 1..4`
# themselves, oversubscribed on a small machine. Runs as root without standard input.
#
# Why MPICH: Open MPI (installed on this machine as a dependency of YADE) refuses to run as root unless
# OMPI_ALLOW_RUN_AS_ROOT and OMPI_ALLOW_RUN_AS_ROOT_CONFIRM are set, and oversubscription needs another
# flag; MPICH's Hydra launcher runs as root and oversubscribes without options. Both are installed side by
# side, so the build and the launcher are pinned to MPICH explicitly: `MPI_PKG_CONFIG=mpich` makes rsmpi
# link libmpich (otherwise it asks `mpicc`, which the alternatives system may point at Open MPI), and the
# test launches `mpirun.mpich`.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(libmpich-dev mpich libclang-dev)
missing=()
for pkg in "${packages[@]}"; do
    dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" </dev/null
fi

export MPI_PKG_CONFIG=mpich
export POLYDEM_MPIRUN=mpirun.mpich
# One rayon thread per rank: the ranks already oversubscribe the cores (the bits do not depend on it).
export RAYON_NUM_THREADS=1
cargo test --release -p polydem-mpi --features mpi
# `mpirun -n P polydem run`: outputs, restarts across rank counts, a failing rank.
cargo test --release -p polydem-cli --features mpi --test cli_mpi
# The workspace clippy stage builds without the features; the MPI code is linted here.
cargo clippy --release -p polydem-mpi -p polydem-cli -p polydem-rockfill --features polydem-mpi/mpi,polydem-cli/mpi \
    --all-targets -- -D warnings
