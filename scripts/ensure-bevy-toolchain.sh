#!/usr/bin/env bash
# Print the Rust toolchain that builds crates/bevy_snowprint (Bevy 0.20 declares rustc 1.97.1;
# the main workspace stays on the machine's default). In order:
#   1. 1.97.1 when rustup has it, or when `rustup toolchain install 1.97.1` succeeds within
#      BEVY_TOOLCHAIN_TIMEOUT seconds (60 by default), with clippy for `make lint`;
#   2. the preinstalled `nightly` when its rustc is 1.97.0 or newer (cargo then needs
#      --ignore-rust-version: the Makefile adds it, see BEVY_CARGO_FLAGS there);
#   3. otherwise one sentence on stderr saying what is missing, and exit 1.
# Only the toolchain's name goes to stdout, so `make` can call it as $(shell ...).
set -euo pipefail

WANT=1.97.1
TIMEOUT="${BEVY_TOOLCHAIN_TIMEOUT:-60}"

has() { rustup run "$1" rustc --version >/dev/null 2>&1; }

if ! command -v rustup >/dev/null 2>&1; then
  echo "snowprint: rustup is not installed, so no toolchain for Bevy 0.20 (rustc $WANT) can be chosen: install rustup" >&2
  exit 1
fi
if ! has "$WANT"; then
  echo "snowprint: installing Rust $WANT for the Bevy plugin (Bevy 0.20 needs it)" >&2
  # RUSTUP_AUTO_INSTALL=0 on some machines only stops implicit installs; this one is explicit.
  { timeout "$TIMEOUT" rustup toolchain install "$WANT" --profile minimal --component clippy 2>&1 || true; } |
    tail -n 2 >&2
fi
if has "$WANT"; then
  # clippy for `make lint`: a toolchain installed before without it gets it now (quietly failing
  # offline; `make lint` then says clippy is missing).
  rustup run "$WANT" cargo clippy --version >/dev/null 2>&1 ||
    timeout "$TIMEOUT" rustup component add clippy --toolchain "$WANT" >&2 || true
  echo "$WANT"
  exit 0
fi
if has nightly; then
  version=$(rustup run nightly rustc --version | awk '{print $2}' | cut -d- -f1)
  if printf '1.97.0\n%s\n' "$version" | sort -V -C; then
    echo "snowprint: Rust $WANT could not be installed; building the Bevy plugin with nightly $version" >&2
    echo nightly
    exit 0
  fi
  echo "snowprint: Rust $WANT could not be installed and the nightly toolchain is $version, older than the 1.97.0 Bevy 0.20 needs: install Rust $WANT (rustup toolchain install $WANT)" >&2
  exit 1
fi
echo "snowprint: Rust $WANT could not be installed and there is no nightly toolchain: install Rust $WANT (rustup toolchain install $WANT) to build the Bevy plugin" >&2
exit 1
