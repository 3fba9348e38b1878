#!/usr/bin/env bash
# Record, replay, fork end to end (README "Record, replay, fork"):
# - a replayed last frame is the live run's --png byte for byte (two worlds: one with a body and
#   the automatic camera, one with range sensors), and so is a frame picked with --at;
# - a fork of a recording at t = 1 s, run from a copy of the world folder whose behaviour sets
#   another joint target, has at t = 1 s the recorded state bit for bit (link poses and joint
#   angles, compared through `replay --json`, which prints doubles round-trip exact), and after
#   it the joint goes to the edited target;
# - bad recordings (wrong magic, truncated, another version, empty, missing) and bad flags exit 2
#   with a message naming the file and what was expected;
# - `replay --view` under xvfb-run draws the recording in a window.
# Usage: replay_test.sh RM3D SRC OUT
set -u
rm3d=$1 src=$2 out=$3
dir="$out/replay"
rm -rf "$dir" && mkdir -p "$dir"
fail=0 passed=0
check() {  # check DESCRIPTION COMMAND...
  local what=$1
  shift
  if "$@"; then passed=$((passed + 1)); else echo "FAIL: $what"; fail=$((fail + 1)); fi
}
expect_error() {  # expect_error DESCRIPTION PATTERN COMMAND...: exit 2 and PATTERN in the output
  local what=$1 pattern=$2
  shift 2
  "$@" > "$dir/err.txt" 2>&1
  local rc=$?
  if [ $rc -ne 2 ] || ! grep -q -- "$pattern" "$dir/err.txt"; then
    echo "FAIL: $what: exit $rc, output:"
    cat "$dir/err.txt"
    fail=$((fail + 1))
  else
    passed=$((passed + 1))
  fi
}

# 1. Pixel identity of the last frame, and of a frame in the middle.
for w in "$src/tests/cli/fork/world.lua" "$src/worlds/wheelbot.lua"; do
  n=$(basename "$(dirname "$w")")_$(basename "$w" .lua)
  "$rm3d" run "$w" --quiet --seconds 1.5 --record "$dir/$n.bin" --png "$dir/$n-live.png" --size 320x240 \
    > "$dir/$n-run.txt" 2>&1
  check "$n: run with --record (exit $?)" grep -q "wrote 91 frames (.*) to .* (the recording)" "$dir/$n-run.txt"
  "$rm3d" replay "$dir/$n.bin" --png "$dir/$n-replay.png" --size 320x240 > /dev/null
  check "$n: replay exit code" test $? -eq 0
  check "$n: the replayed last frame is the live one byte for byte" cmp "$dir/$n-live.png" "$dir/$n-replay.png"
  "$rm3d" run "$w" --quiet --seconds 0.5 --png "$dir/$n-half.png" --size 320x240 > /dev/null 2>&1
  "$rm3d" replay "$dir/$n.bin" --at 0.5 --png "$dir/$n-half-replay.png" --size 320x240 > /dev/null
  check "$n: the frame at t=0.5 replayed is the live one" cmp "$dir/$n-half.png" "$dir/$n-half-replay.png"
done
check "different frames differ" bash -c "! cmp -s '$dir/fork_world-live.png' '$dir/fork_world-half.png'"
# Particles (fluid) are recorded and drawn again: the replayed last frame is the live one.
"$rm3d" run "$src/worlds/fluid.lua" --param particles=3000 --quiet --seconds 0.5 --record "$dir/fluid.bin" \
  --png "$dir/fluid-live.png" --size 320x240 > "$dir/fluid-run.txt" 2>&1
check "fluid: run with --record" grep -q "wrote 31 frames (.*) to .* (the recording)" "$dir/fluid-run.txt"
"$rm3d" replay "$dir/fluid.bin" --png "$dir/fluid-replay.png" --size 320x240 > /dev/null
check "fluid: the replayed last frame (particles drawn) is the live one byte for byte" cmp "$dir/fluid-live.png" "$dir/fluid-replay.png"

# 2. Fork: the recorded sources up to T, the edited behaviour after it.
"$rm3d" run "$src/tests/cli/fork/world.lua" --quiet --record "$dir/a.bin" --json "$dir/a.json" > /dev/null 2>&1
rm -rf "$dir/copy" && cp -r "$src/tests/cli/fork" "$dir/copy"
sed -i 's/math.rad(30)/math.rad(-45)/' "$dir/copy/target.lua"
"$rm3d" run "$dir/copy/world.lua" --quiet --fork "$dir/a.bin" --at 1 --record "$dir/b.bin" --json "$dir/b.json" \
  > "$dir/fork.txt" 2>&1
check "fork: exit code $?" test $? -eq 0
cat "$dir/fork.txt"
check "fork: reports the match" grep -q "the state matches the recording bit for bit" "$dir/fork.txt"
check "fork: reloads the edited behaviour" grep -q "reloaded .*copy/target.lua into 2 modules at t=1.0000 s" "$dir/fork.txt"
"$rm3d" replay "$dir/a.bin" --at 1 --json "$dir/a1.json" > /dev/null
"$rm3d" replay "$dir/b.bin" --at 1 --json "$dir/b1.json" > /dev/null
check "fork: the state at T is the recorded one bit for bit" cmp "$dir/a1.json" "$dir/b1.json"
check "fork: the state at T has the joint at the old target" \
  jq -e '.modules[0].joints.pitch > 0.45 and .modules[0].joints.pitch < 0.6' "$dir/b1.json"
check "original: pitch stays at +30 deg" jq -e '.modules[0].joints.pitch > 0.45' "$dir/a.json"
check "fork: pitch goes to the edited -45 deg" \
  jq -e '.modules | all(.joints.pitch < -0.7 and .joints.pitch > -0.87)' "$dir/b.json"
"$rm3d" replay "$dir/a.bin" --at 1.5 --json "$dir/a15.json" > /dev/null
"$rm3d" replay "$dir/b.bin" --at 1.5 --json "$dir/b15.json" > /dev/null
check "fork: after T the runs differ" bash -c "! cmp -s '$dir/a15.json' '$dir/b15.json'"

# 3. Bad recordings and flags.
head -c 5000 "$dir/a.bin" > "$dir/truncated.bin"
printf 'PNG-not-a-recording-at-all' > "$dir/magic.bin"
: > "$dir/empty.bin"
{ printf 'RM3DREC\n'; printf '\x07\x00\x00\x00\x00\x00\x00\x00'; } > "$dir/version.bin"
head -c 20 "$dir/a.bin" > "$dir/header.bin"
expect_error "truncated" "truncated.bin: truncated recording" "$rm3d" replay "$dir/truncated.bin" --png "$dir/x.png"
expect_error "wrong magic" "magic.bin: not an RM3D recording (expected a file written by .rm3d run --record" \
  "$rm3d" replay "$dir/magic.bin"
expect_error "empty" "empty.bin: not an RM3D recording" "$rm3d" replay "$dir/empty.bin"
expect_error "version" "version.bin: recording format version 7 (this rm3d reads version 1)" \
  "$rm3d" replay "$dir/version.bin"
expect_error "cut in a chunk header" "header.bin: truncated recording (the file ends inside a chunk header" \
  "$rm3d" replay "$dir/header.bin"
expect_error "missing" "nothere.bin: cannot read the recording" "$rm3d" replay "$dir/nothere.bin"
expect_error "fork from a truncated file" "--fork .*truncated.bin: truncated recording" \
  "$rm3d" run "$dir/copy/world.lua" --fork "$dir/truncated.bin" --at 1
expect_error "fork past the end" "--at 5: expected a time from 0 to 2 s" \
  "$rm3d" run "$dir/copy/world.lua" --fork "$dir/a.bin" --at 5
expect_error "fork without --at" "--fork FILE needs --at T" "$rm3d" run "$dir/copy/world.lua" --fork "$dir/a.bin"
expect_error "--at without --fork" "--at T needs --fork FILE" "$rm3d" run "$dir/copy/world.lua" --at 1
expect_error "fork with --seed" "drop --seed and --param" \
  "$rm3d" run "$dir/copy/world.lua" --fork "$dir/a.bin" --at 1 --seed 3
expect_error "bad --eye" "--eye 1,2: expected three numbers X,Y,Z" "$rm3d" replay "$dir/a.bin" --eye 1,2
expect_error "bad --fov" "--fov 0: expected a vertical field of view" "$rm3d" run "$dir/copy/world.lua" --fov 0
expect_error "replay --at past the end" "--at 9: the recording ends at t=2" "$rm3d" replay "$dir/a.bin" --at 9 --png "$dir/x.png"
expect_error "record into a folder" "--record $dir: is a folder" "$rm3d" run "$dir/copy/world.lua" --record "$dir"

# 4. The window, under a virtual X server.
if command -v xvfb-run > /dev/null && command -v xauth > /dev/null; then
  timeout 120 xvfb-run -a -s "-screen 0 1280x720x24" "$rm3d" replay "$dir/a.bin" --view --view-frames 5 \
    --screenshot "$dir/view.png" > "$dir/view.txt" 2>&1
  check "replay --view: exit code $?" test $? -eq 0
  check "replay --view: screenshot written" test -s "$dir/view.png"
else
  echo "skipped: no xvfb-run: the replay window is not tested"
fi
env -u DISPLAY -u WAYLAND_DISPLAY "$rm3d" replay "$dir/a.bin" --view > "$dir/nodisplay.txt" 2>&1
check "replay --view without a display: exit 2" test $? -eq 2
check "replay --view without a display: message" grep -q "no display available" "$dir/nodisplay.txt"

echo "$passed passed, $fail failed"
[ $fail -eq 0 ]
