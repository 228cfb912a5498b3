#!/usr/bin/env bash
# Renders a GTKWave view of a trace to PNG (headless, under Xvfb), for docs/waveforms.md.
# Usage: scripts/waveform_screenshot.sh TRACE.fst SAVE.gtkw OUT.png [START END]
#   START END: time range to show (default: the whole trace).
set -euo pipefail
if [[ $# -lt 3 || "${1:-}" == "--help" ]]; then
  sed -n 2,4p "$0"; exit 2
fi
trace=$1 save=$2 out=$3 start=${4:-} end=${5:-}
for f in "$trace" "$save"; do [[ -f "$f" ]] || { echo "waveform_screenshot: no such file: $f" >&2; exit 2; }; done
command -v Xvfb >/dev/null || { echo "waveform_screenshot: needs xvfb (apt-get install xvfb x11-apps imagemagick)" >&2; exit 2; }
tcl=$(mktemp --suffix .tcl)
if [[ -n "$start" ]]; then
  echo "gtkwave::setZoomRangeTimes $start $end" > "$tcl"
else
  echo "gtkwave::/Time/Zoom/Zoom_Best_Fit" > "$tcl"
fi
display=:$((90 + RANDOM % 9))
Xvfb "$display" -screen 0 1600x1000x24 >/dev/null 2>&1 &
xvfb=$!
trap 'kill $gw $xvfb 2>/dev/null; rm -f "$tcl"' EXIT
sleep 1
DISPLAY=$display gtkwave -a "$save" "$trace" --script "$tcl" >/dev/null 2>&1 &
gw=$!
sleep 8
DISPLAY=$display import -window root "$out"
echo "wrote $out"
