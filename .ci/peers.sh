#!/usr/bin/env bash
# The contact case with the C/C++ collision libraries as peers (validation feature `peers`): installs
# libccd and Bullet from Debian when missing, then runs `validate contact` with the feature on. Exits
# non-zero when polydem has a wrong answer (any failed check of the case; the peers' own errors are
# reported, not checked). Prints its wall time.
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

# The `validate` alias (.cargo/config.toml) with the feature: cargo's options go before `--`. The speed
# profile (the alias's) by default, for the report's timings; CI checks answers only and takes the release
# profile it has already built (POLYDEM_PEERS_PROFILE=release).
cargo run --profile "${POLYDEM_PEERS_PROFILE:-speed}" -p polydem-validation --features peers --bin validate -- contact "$@"
echo "=== peers: $((SECONDS - start)) s"
