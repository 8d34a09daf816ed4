#!/usr/bin/env bash
# Make sure an X server without a display (Xvfb) is present for the test that opens a real window
# (`snowprint play` under Xvfb, crates/snowprint-cli/tests/play.rs): when `Xvfb` is not on the
# PATH, install Debian's package `xvfb`, the way ensure-vulkan.sh installs Mesa. A machine that has
# it is left alone.
set -euo pipefail

if command -v Xvfb >/dev/null 2>&1; then
  exit 0
fi
if ! command -v apt-get >/dev/null 2>&1; then
  echo "snowprint: Xvfb not found and apt-get is unavailable: install Xvfb to run the window test (it is skipped without it)" >&2
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "snowprint: Xvfb not found; installing Debian's xvfb for the window test" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends xvfb xauth >/dev/null
