#!/usr/bin/env bash
# Set up on first use (venv, test extras, FFmpeg for the live-stream test), then run the test suite.
# Extra arguments go to pytest.
source "$(dirname "$0")/_venv.sh" test
if ! command -v ffmpeg >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "[setup] installing ffmpeg from Debian's packages" >&2
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ffmpeg >/dev/null
    else
        echo "[setup] ffmpeg not found and cannot install it: the live-stream test will fail" >&2
    fi
fi
cd "$ROOT"
exec "$VENV/bin/python" -m pytest "$@"
