#!/usr/bin/env bash
# Chromium (the Debian package `chromium`), for the published page's browser test
# (tests/suite/publish.rs): installed with apt when missing and this runs as root; otherwise it
# stops with the command to run (exit 2). Idempotent.
set -euo pipefail

if command -v chromium >/dev/null 2>&1 || [ -n "${NBODY_BENCH_CHROMIUM:-}" ]; then
    exit 0
fi
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "installing chromium"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium >/dev/null
else
    echo "Chromium is missing; install it with: sudo apt-get install -y chromium" >&2
    exit 2
fi
