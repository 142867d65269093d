#!/usr/bin/env bash
# The viewer's browser test (web/test/viewer.test.mjs) drives Debian's Chromium headless through
# playwright-core; installs it when the machine lacks it.
set -euo pipefail
if [ ! -x /usr/bin/chromium ]; then
  as_root=""
  [ "$(id -u)" -eq 0 ] || as_root="sudo"
  $as_root apt-get update -qq
  $as_root apt-get install -y -qq chromium >/dev/null
fi
