#!/usr/bin/env bash
# Install Debian's chromium for the headless-browser test of report.html (tests/test_report_html.py).
# Needs root and apt-get; anywhere else it says why and does nothing, and that test skips with the reason.
set -uo pipefail
if command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1; then
  exit 0
fi
if ! command -v apt-get >/dev/null 2>&1 || [ "$(id -u)" -ne 0 ]; then
  echo "install-test-browser: no chromium, and no apt-get as root to install Debian's package" >&2
  exit 0
fi
export DEBIAN_FRONTEND=noninteractive
apt-get install -y -q chromium >/dev/null 2>&1 || { apt-get update -q >/dev/null 2>&1 && apt-get install -y -q chromium >/dev/null 2>&1; } \
  || echo "install-test-browser: apt-get could not install chromium" >&2
exit 0
