#!/usr/bin/env bash
# The viewer's frame rate against `pathlight bench`, interleaved, and the preview rate of a
# scripted drag: under Xvfb (packages xvfb, xdotool), on the default scene at 500x500.
#
#   bench/viewer-fps.sh [BACKEND] [FRAMES] [PAIRS]     # defaults: auto 30 3
#
# Each pair runs `pathlight bench --frames FRAMES`, then `pathlight view --frames-per-iter
# FRAMES --iters 1` (its `iter 1 finished, F fps` line), then drags the view for 150 pointer
# moves about 20 ms apart (its `preview: N frames at WxH, F fps` line). Build first:
# `cargo build --release`.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=target/release/pathlight
backend=${1:-auto}
frames=${2:-30}
pairs=${3:-3}
log=$(mktemp)
Xvfb -displayfd 3 -screen 0 800x600x24 -nolisten tcp 3>"$log.display" >/dev/null 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null; rm -f "$log" "$log.display"' EXIT
for _ in $(seq 1 100); do [ -s "$log.display" ] && break; sleep 0.1; done
export DISPLAY=":$(head -1 "$log.display")"
for _ in $(seq 1 "$pairs"); do
    "$BIN" bench --backend "$backend" --frames "$frames" --warmup 2 --time-limit 600 2>/dev/null |
        grep -E '^(device|fps)' | sed "s/^/bench: /"
    "$BIN" view --backend "$backend" --frames-per-iter "$frames" --iters 1 >"$log" 2>&1 &
    viewer=$!
    for _ in $(seq 1 1200); do grep -q "iter 1 finished" "$log" && break; sleep 0.5; done
    grep -E "^(backend|iter 1 finished)" "$log" | sed "s/^/view:  /"
    window=$(xdotool search --name '^pathlight' | head -1)
    xdotool mousemove --window "$window" 250 250 mousedown 1
    for s in $(seq 1 150); do
        xdotool mousemove --window "$window" $((250 + (s % 50) * 2)) $((250 + (s % 30)))
        sleep 0.01
    done
    xdotool mouseup 1
    for _ in $(seq 1 60); do grep -q "preview:" "$log" && break; sleep 0.5; done
    grep "preview:" "$log" | sed "s/^/view:  /"
    kill "$viewer"
    wait "$viewer" 2>/dev/null || true
done
