#!/usr/bin/env bash
# Set up on first use, then show the loop closing: a virtual camera on the built-in simulated gimbal
# looks into the bundled wide clip, so the view answers the gimbal (gimbaltrack simulate, outputs in
# out/demo). `--open-loop` instead tracks the bundled 640x360 clip at file speed, whose picture cannot
# follow the gimbal (gimbaltrack track, outputs in out/demo-open-loop). Extra arguments go to gimbaltrack.
source "$(dirname "$0")/_venv.sh" ""  # no extras; our own arguments go to gimbaltrack
if [ "${1:-}" = "--open-loop" ]; then
    shift
    exec "$VENV/bin/gimbaltrack" track "$ROOT/samples/demo.mp4" --out "$ROOT/out/demo-open-loop" "$@"
fi
exec "$VENV/bin/gimbaltrack" simulate "$ROOT/samples/demo_wide.mp4" --out "$ROOT/out/demo" "$@"
