#!/usr/bin/env bash
# Retakes docs/viewer.png, the viewer as docs/viewer.md's caption says: the Wuson model's
# Dubois anaglyph at 640x480, zero parallax 3.8, keypad + pressed five times. The readouts show
# frame times, so take it on an idle machine. Needs Xvfb, xdotool, xwd (x11-apps) and netpbm
# (.ci/run installs them all).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --features viewer --bin stereolab
work=$(mktemp -d)
display=:97
Xvfb "$display" -screen 0 1280x800x24 -nolisten tcp >/dev/null 2>&1 &
xvfb=$!
trap 'kill "$viewer" "$xvfb" 2>/dev/null || true; rm -rf "$work"' EXIT
export DISPLAY=$display LIBGL_ALWAYS_SOFTWARE=1
until xdotool getdisplaygeometry >/dev/null 2>&1; do sleep 0.2; done
target/release/stereolab view assets/scenes/wuson.toml --size 640x480 \
    --output anaglyph_dubois --set stereo.zero_parallax=3.8 \
    --state-file "$work/state.json" >"$work/viewer.log" 2>&1 &
viewer=$!
until window=$(xdotool search --name "stereolab view" 2>/dev/null | head -n 1) && [ -n "$window" ]; do
    sleep 0.2
done
# The first frames, then the five key presses, then time for the frame rate to settle.
sleep 5
xdotool windowfocus --sync "$window"
for _ in 1 2 3 4 5; do xdotool key --clearmodifiers KP_Add; sleep 0.5; done
sleep 10
xwd -silent -id "$window" | xwdtopnm 2>/dev/null | pnmtopng > "$work/viewer.png"
mv "$work/viewer.png" docs/viewer.png
echo "wrote docs/viewer.png ($(cut -d' ' -f1-3 /proc/loadavg) load while taken)"
