#!/usr/bin/env bash
# cargo on the Bevy plugin (crates/bevy_snowprint, a workspace of its own): with the toolchain
# scripts/ensure-bevy-toolchain.sh picks (adding --ignore-rust-version on the nightly fallback)
# and its own target folder, target/bevy, so the main workspace's build is untouched.
#   scripts/bevy-cargo.sh test --release --locked
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
toolchain=$("$root/scripts/ensure-bevy-toolchain.sh")
command=$1
shift
extra=()
if [ "$toolchain" = nightly ]; then
  extra=(--ignore-rust-version)
fi
cd "$root/crates/bevy_snowprint"
CARGO_TARGET_DIR="${BEVY_TARGET_DIR:-$root/target/bevy}" exec cargo "+$toolchain" "$command" "${extra[@]}" "$@"
