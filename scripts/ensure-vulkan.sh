#!/usr/bin/env bash
# Make sure a Vulkan driver is present: when the machine has no Vulkan ICD at all, install Mesa's
# software one (lavapipe, Debian package mesa-vulkan-drivers) with the loader. Real GPUs with their
# own drivers are left alone.
set -euo pipefail

have_icd() {
  for d in /usr/share/vulkan/icd.d /etc/vulkan/icd.d /usr/local/share/vulkan/icd.d; do
    compgen -G "$d/*.json" >/dev/null 2>&1 && return 0
  done
  [ -n "${VK_ICD_FILENAMES:-}${VK_DRIVER_FILES:-}" ]
}
have_loader() { ldconfig -p 2>/dev/null | grep -q 'libvulkan\.so\.1'; }

if have_icd && have_loader; then
  exit 0
fi
if ! command -v apt-get >/dev/null 2>&1; then
  echo "snowprint: no Vulkan driver found and apt-get is unavailable: install a Vulkan driver (Mesa's lavapipe works without a GPU)" >&2
  exit 1
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "snowprint: no Vulkan driver found; installing Mesa's software Vulkan (mesa-vulkan-drivers)" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends mesa-vulkan-drivers libvulkan1 >/dev/null
