#!/usr/bin/env bash
# Set up on first use (venv, test extras, FFmpeg for the live-stream test, Chromium and its driver
# for the console's browser test), then run the test suite on every core. Extra arguments go to pytest.
source "$(dirname "$0")/_venv.sh" test
missing=()
command -v ffmpeg >/dev/null 2>&1 || missing+=(ffmpeg)
command -v chromium >/dev/null 2>&1 || missing+=(chromium)
command -v chromedriver >/dev/null 2>&1 || missing+=(chromium-driver)
if [ "${#missing[@]}" -gt 0 ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "[setup] installing ${missing[*]} from Debian's packages" >&2
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
    else
        echo "[setup] ${missing[*]} not found and cannot install: the live-stream and console browser" \
             "tests will skip (fail under CI)" >&2
    fi
fi
cd "$ROOT"
exec "$VENV/bin/python" -m pytest -n auto "$@"  # one worker per core; `-n 0` after it wins
