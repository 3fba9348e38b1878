#!/usr/bin/env bash
# `rm3d view` end to end: without a display it explains itself and exits 2; a bad world file is
# reported with file:line before any window opens; under a virtual X server (xvfb-run) it renders
# frames of the snake and saves a screenshot of the window that has the window's size and shows
# the modules, with and without the inspector open. Usage: view_test.sh RM3D SRC OUT
set -u
rm3d=$1 src=$2 out=$3
dir="$out/view"
rm -rf "$dir" && mkdir -p "$dir"
fail=0
check() {  # check DESCRIPTION COMMAND...: runs the command, records a failure if it fails
  local what=$1
  shift
  "$@" || { echo "FAIL: $what"; fail=1; }
}

# No display: a clear message and exit 2, whatever is installed.
env -u DISPLAY -u WAYLAND_DISPLAY timeout 60 "$rm3d" view "$src/worlds/snake.lua" > "$dir/nodisplay.txt" 2>&1
rc=$?
cat "$dir/nodisplay.txt"
check "no display: exit code $rc, expected 2" test $rc -eq 2
check "no display: message" grep -q "no display available (DISPLAY is not set).*rm3d run WORLD --png" "$dir/nodisplay.txt"

# A bad world file: file:line and exit 2, before any window is needed.
printf 'world.ground{}\nworld.spawn("superbot", {at = {0, 0, 0.1}}\n' > "$dir/bad.lua"
env -u DISPLAY -u WAYLAND_DISPLAY timeout 60 "$rm3d" view "$dir/bad.lua" > "$dir/bad.txt" 2>&1
rc=$?
cat "$dir/bad.txt"
check "bad world: exit code $rc, expected 2" test $rc -eq 2
check "bad world: file:line" grep -q "bad.lua:3:" "$dir/bad.txt"

# --quiet is accepted; `--frames` is a folder in `run`, so `view --frames DIR` is refused naming
# --exit-after, and the old `view --frames N` still works with a deprecation warning.
env -u DISPLAY -u WAYLAND_DISPLAY timeout 60 "$rm3d" view "$src/worlds/snake.lua" --quiet --frames out > "$dir/frames.txt" 2>&1
rc=$?
check "view --frames DIR: exit code $rc, expected 2" test $rc -eq 2
check "view --frames DIR: names --exit-after" grep -q "writes no frame folders.*--exit-after N" "$dir/frames.txt"
env -u DISPLAY -u WAYLAND_DISPLAY timeout 60 "$rm3d" view "$src/worlds/snake.lua" --quiet --frames 3 > "$dir/frames_old.txt" 2>&1
check "view --frames N: deprecation warning" grep -q "\-\-frames N is deprecated, use --exit-after N" "$dir/frames_old.txt"
check "view --frames N: still reaches the viewer" grep -q "no display available" "$dir/frames_old.txt"

if ! command -v xvfb-run > /dev/null || ! command -v xauth > /dev/null; then
  # xvfb-run needs xauth too; .ci/install-deps installs both.
  echo "skipped: no xvfb-run (or no xauth for it): the window itself is not tested"
  [ $fail -eq 0 ] && echo "1 passed, 0 failed" || echo "0 passed, 1 failed"
  exit $fail
fi

# PNG width and height from the IHDR chunk (bytes 16-23, big-endian).
png_size() {
  od -An -tu1 -j16 -N8 "$1" | awk '{ printf "%d x %d", $1 * 16777216 + $2 * 65536 + $3 * 256 + $4, $5 * 16777216 + $6 * 65536 + $7 * 256 + $8 }'
}

# shot NAME ARGS...: renders 30 frames of the snake in a 1280x720 window and saves the last one.
# rm3d prints "screenshot: W x H, N module pixels, P of them picked as a module, ...": N counts
# pixels whose hue is a module link colour as the renderer shades it (the SuperBot's orange
# brackets), P those of them where a pick ray through the pixel hits a module.
shot() {
  local name=$1
  shift
  timeout 300 xvfb-run -a -s "-screen 0 1280x720x24" "$rm3d" view "$src/worlds/snake.lua" --exit-after 30 \
    --screenshot "$dir/$name.png" "$@" > "$dir/$name.txt" 2>&1
  local rc=$?
  grep -v "^\[" "$dir/$name.txt"  # the world's own progress lines are noise here
  check "$name: exit code $rc, expected 0" test $rc -eq 0
  check "$name: no $name.png" test -s "$dir/$name.png"
  [ -s "$dir/$name.png" ] || return
  local size
  size=$(png_size "$dir/$name.png")
  check "$name: PNG is $size, expected the window's 1280 x 720" test "$size" = "1280 x 720"
  local line n p
  line=$(grep "^screenshot: " "$dir/$name.txt")
  check "$name: screenshot line has the window size" grep -q "^screenshot: 1280 x 720," <<< "$line"
  n=$(sed -n 's/.*, \([0-9]*\) module pixels.*/\1/p' <<< "$line")
  p=$(sed -n 's/.*, \([0-9]*\) of them picked.*/\1/p' <<< "$line")
  n=${n:-0} p=${p:-0}
  check "$name: $n module pixels, expected at least 500" test "$n" -ge 500
  check "$name: only $p of $n module pixels picked as a module" test $((p * 10)) -ge $((n * 9))
}

shot view
shot inspector --select 8
# The connection-graph panel: shown by default with the snake's nine connections in one
# component (the screenshot line reports what the panel shows); --no-graph hides it.
check "view: graph panel with 9 connections" grep -q "graph: 9 connections, 1 component$" "$dir/view.txt"
shot nograph --no-graph
check "nograph: graph panel hidden" grep -q "graph: hidden$" "$dir/nograph.txt"
check "inspector: module 8 not selected" grep -q "selected: snake_8" "$dir/inspector.txt"

[ $fail -eq 0 ] && echo "1 passed, 0 failed" || echo "0 passed, 1 failed"
exit $fail
