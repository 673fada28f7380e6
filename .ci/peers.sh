#!/usr/bin/env bash
# The contact case with the C/C++ collision libraries as peers (validation feature `peers`): installs
# libccd and Bullet from Debian and coal from its wheels (`libcoal`, `cmeel-eigen`, into
# target/coal-wheel) when missing, then runs `validate contact` with the feature on. A peer that cannot be
# installed is left out, and the report says so. Exits non-zero when polydem has a wrong answer (any
# failed check of the case; the peers' own errors are reported, not checked). Prints its wall time.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS

missing=()
for pkg in libccd-dev libbullet-dev pkg-config; do
    dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" </dev/null
fi

# coal 3.0.3 and the Eigen headers its headers include, pinned; pip's wheels carry the shared libraries
# (boost, assimp, qhull, octomap) that libcoal.so finds through its own rpath. build.rs reads the prefix.
coal_dir="$PWD/target/coal-wheel"
if [ ! -d "$coal_dir/libcoal-3.0.3.dist-info" ]; then
    PIP_ROOT_USER_ACTION=ignore python3 -m pip install --quiet --disable-pip-version-check --target "$coal_dir" \
        libcoal==3.0.3 cmeel-eigen==3.4.1 ||
        echo "peers: pip could not install libcoal and cmeel-eigen: the coal peer is left out" >&2
fi
export POLYDEM_COAL_PREFIX="$coal_dir/cmeel.prefix"
echo "=== peers: packages ready after $((SECONDS - start)) s"

# The `validate` alias (.cargo/config.toml) with the feature: cargo's options go before `--`. The speed
# profile (the alias's) by default, for the report's timings; CI checks answers only and takes the release
# profile it has already built (POLYDEM_PEERS_PROFILE=release).
cargo run --profile "${POLYDEM_PEERS_PROFILE:-speed}" -p polydem-validation --features peers --bin validate -- contact "$@"
echo "=== peers: $((SECONDS - start)) s"
