#!/usr/bin/env bash
# Install Debian's chromium for the browser test of `radar view` (tests/test_view_browser.py).
# Idempotent: does nothing when /usr/bin/chromium exists. Never fails the setup: without apt
# (or without root) it prints why and the browser test skips itself with the same reason.
set -u
if [ -x /usr/bin/chromium ]; then
    exit 0
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "install-chromium: apt-get not available; the radar view browser test will be skipped" >&2
    exit 0
fi
if [ "$(id -u)" != 0 ]; then
    echo "install-chromium: not root; run 'apt-get install -y chromium' as root for the browser test" >&2
    exit 0
fi
echo "install-chromium: apt-get install -y chromium (for the radar view browser test)"
export DEBIAN_FRONTEND=noninteractive
if ! apt-get install -y -q chromium >/dev/null; then
    apt-get update -q >/dev/null && apt-get install -y -q chromium >/dev/null \
        || echo "install-chromium: apt-get install chromium failed; the browser test will be skipped" >&2
fi
exit 0
