#!/usr/bin/env bash
# Engaged docks are marked in every kind of picture: two SuperBots docked end to end against the
# same two only touching (tests/cli/dock_marks/pair.lua). Pixels of the engaged-dock green
# (linear 0.2, 0.8, 0.3; tests/tools/image_compare.cpp) are counted in `run --png`, a `run --frames`
# frame (the frames a --video is made of), `replay --png` and `replay --frames`: the docked pair
# shows at least 150 of them, the touching pair none. --labels writes the module names: the
# labelled picture differs from the plain one in white text pixels near the modules.
# Usage: dock_marks_test.sh RM3D SRC OUT IMAGE_COMPARE
set -u
rm3d=$1 src=$2 out=$3 cmp=$4
dir="$out/dock_marks"
rm -rf "$dir" && mkdir -p "$dir"
world="$src/tests/cli/dock_marks/pair.lua"
fail=0 passed=0
check() {  # check DESCRIPTION COMMAND...
  local what=$1
  shift
  if "$@"; then passed=$((passed + 1)); else echo "FAIL: $what"; fail=$((fail + 1)); fi
}
green=0.2,0.8,0.3
for docked in 1 0; do
  d="$dir/docked$docked"
  mkdir -p "$d"
  "$rm3d" run "$world" --quiet --param docked=$docked --size 640x360 --png "$d/run.png" --frames "$d/frames" \
    --record "$d/rec" > "$d/run.txt" 2>&1 || { cat "$d/run.txt"; echo "FAIL: run docked=$docked"; fail=$((fail + 1)); }
  "$rm3d" replay "$d/rec" --size 640x360 --png "$d/replay.png" --frames "$d/replay_frames" > /dev/null 2>&1
  for pic in run.png "frames/frame_000000.png" replay.png "replay_frames/frame_000000.png"; do
    n=$("$cmp" count "$d/$pic" $green)
    echo "docked=$docked $pic: ${n:-?} engaged-dock pixels"
    if [ $docked = 1 ]; then
      check "docked pair, $pic: ${n:-?} engaged-dock pixels, expected >= 150" test "${n:-0}" -ge 150
    else
      check "touching pair, $pic: ${n:-?} engaged-dock pixels, expected 0" test "${n:-1}" -eq 0
    fi
  done
done
# --labels: white glyph pixels appear (the plain picture's only white is its overlay line).
"$rm3d" run "$world" --quiet --param docked=1 --png "$dir/plain.png" > /dev/null 2>&1
"$rm3d" run "$world" --quiet --param docked=1 --png "$dir/labels.png" --labels > /dev/null 2>&1
plain=$("$cmp" white "$dir/plain.png")
labelled=$("$cmp" white "$dir/labels.png")
echo "white pixels: plain $plain, labelled $labelled"
check "--labels draws the names (${labelled:-?} white pixels, plain ${plain:-?})" \
  test "${labelled:-0}" -gt $((${plain:-0} + 100))
echo "$passed passed, $fail failed"
[ $fail -eq 0 ]
