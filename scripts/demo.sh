#!/usr/bin/env bash
# Set up on first use, then track the bundled demo clip against the built-in simulated gimbal.
# Extra arguments go to `gimbaltrack track`.
source "$(dirname "$0")/_venv.sh" ""  # no extras; our own arguments go to gimbaltrack
exec "$VENV/bin/gimbaltrack" track "$ROOT/samples/demo.mp4" --out "$ROOT/out/demo" "$@"
