#!/usr/bin/env bash
# Install Debian's bare-metal ARM toolchain, the Cortex-M emulator and cppcheck for the target tests of
# the C packages (tests/test_codegen_targets.py): gcc-arm-none-eabi with newlib, qemu-system-arm (MPS2 boards).
# Needs root and apt-get; anywhere else it says why and does nothing, and those tests skip with the reason.
set -uo pipefail
PACKAGES="gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm cppcheck"
if command -v arm-none-eabi-gcc >/dev/null 2>&1 && command -v qemu-system-arm >/dev/null 2>&1 \
    && command -v cppcheck >/dev/null 2>&1; then
  exit 0
fi
if ! command -v apt-get >/dev/null 2>&1 || [ "$(id -u)" -ne 0 ]; then
  echo "install-arm-toolchain: no arm-none-eabi-gcc/qemu-system-arm/cppcheck, and no apt-get as root to install" \
       "Debian's $PACKAGES" >&2
  exit 0
fi
export DEBIAN_FRONTEND=noninteractive
# shellcheck disable=SC2086
apt-get install -y -q --no-install-recommends $PACKAGES >/dev/null 2>&1 \
  || { apt-get update -q >/dev/null 2>&1 && apt-get install -y -q --no-install-recommends $PACKAGES >/dev/null 2>&1; } \
  || echo "install-arm-toolchain: apt-get could not install $PACKAGES" >&2
exit 0
