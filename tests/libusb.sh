#!/usr/bin/env bash
# Open3D's wheel (the metrics cross-check, the Draco anchor's measurements) links libusb; Debian
# ships it as libusb-1.0-0. Installs it when the machine lacks it.
set -euo pipefail
if ! ldconfig -p | grep -q 'libusb-1.0.so.0'; then
  as_root=""
  [ "$(id -u)" -eq 0 ] || as_root="sudo"
  $as_root apt-get update -qq
  $as_root apt-get install -y -qq libusb-1.0-0 >/dev/null
fi
