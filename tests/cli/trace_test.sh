#!/usr/bin/env bash
# `rm3d run --trace` and `rm3d plot`, end to end: the CSV's header, widths and values (joint
# targets, dock states, module.trace and world.trace series with the "latest since the last row"
# rule), metrics and the run's identity in the JSON summary, output folders made, and a plot of
# the trace as PNG and SVG through gnuplot. Usage: trace_test.sh RM3D SRC OUT
set -u
rm3d=$1 src=$2 out=$3
dir="$out/trace"
rm -rf "$dir" && mkdir -p "$dir"
fail=0
check() {  # check DESCRIPTION TEST...
  local what=$1
  shift
  if "$@"; then echo "ok: $what"; else echo "FAIL: $what"; fail=1; fi
}

cat > "$dir/counter.lua" <<'LUA'
-- Holds pitch at 0.25 rad and records how often step() ran; "five" only at its 5th call.
local pitch = module.joint("pitch")
local n = 0
function step(dt)
  n = n + 1
  pitch:set_target(0.25)
  module.trace("calls", n)
  if n == 5 then module.trace("five", 5) end
end
LUA
cat > "$dir/world.lua" <<'LUA'
world.set{duration = 100, seed = 4}
world.ground{}
local a = world.spawn("superbot", {at = {0, 0, 0.053}, name = "m1", behavior = "counter.lua"})
local b = world.spawn("superbot", {name = "m2"})
world.connect(a, "front", b, "back")
world.trace("at_load", 7)
world.at(0.2, function(t) world.trace("at_0_2", 0.5) end)
world.on_end(function(t)
  world.metric("final_x", a:position().x)
  world.metric("steps_seen", t / world.dt())
  world.trace("at_end", t)
end)
LUA
"$rm3d" run "$dir/world.lua" --steps 30 --trace "$dir/new/folder/t.csv" --trace-every 10 \
  --json "$dir/other/s.json" --param gain=2.5 --param n=3 --param mode=fast --quiet > "$dir/run.log" 2>&1
rc=$?
cat "$dir/run.log"
csv="$dir/new/folder/t.csv"
check "run exits 0" [ $rc -eq 0 ]
check "trace written into a new folder" [ -f "$csv" ]
check "no part file left" [ ! -e "$csv.part" ]
check "run says what it wrote" grep -q "wrote 11 rows x .* columns to .*t.csv" "$dir/run.log"

# cell STEP MODULE_ID COLUMN: the cell of that row (plain names: no quoted commas here).
cell() {
  awk -F, -v step="$1" -v id="$2" -v name="$3" '
    NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i; next }
    $2 == step && $3 == id { n++; v = $c }
    END { if (n != 1) print "ROWS=" n; else print v }' "$csv"
}
expect_cell() {  # expect_cell STEP ID COLUMN VALUE
  local got
  got=$(cell "$1" "$2" "$3")
  check "step $1 module $2 $3 = '$4' (got '$got')" [ "$got" = "$4" ]
}
header=$(head -1 "$csv")
fixed="time,step,module_id,module,type,x,y,z,qw,qx,qy,qz,joint.pitch.angle,"
check "header starts with the fixed columns" [ "${header:0:${#fixed}}" = "$fixed" ]
for c in joint.pitch.angle joint.pitch.target joint.pitch.torque dock.front dock.front.peer trace.calls \
         trace.five trace.at_load trace.at_0_2 trace.at_end; do
  check "column $c" grep -q "\(^\|,\)$c\(,\|$\)" <(echo "$header")
done
widths=$(awk -F, '{print NF}' "$csv" | sort -u)
check "every row as wide as the header ($widths)" [ "$widths" = "$(echo "$header" | awk -F, '{print NF}')" ]
# Rows at steps 0, 10, 20, 30 for both modules; world rows where a world series was recorded.
check "8 module rows" [ "$(awk -F, 'NR > 1 && $3 != 0' "$csv" | wc -l)" -eq 8 ]
check "module rows at steps 0 10 20 30" [ "$(awk -F, 'NR > 1 && $3 == 1 {printf "%s ", $2}' "$csv")" = "0 10 20 30 " ]
expect_cell 10 1 time 0.16666666666666666
expect_cell 10 1 module m1
expect_cell 10 1 type superbot
expect_cell 0 1 trace.calls ""
expect_cell 10 1 trace.calls 10
expect_cell 30 1 trace.calls 30
expect_cell 10 1 trace.five 5
expect_cell 20 1 trace.five ""
expect_cell 10 2 trace.calls ""
expect_cell 10 1 joint.pitch.target 0.25
expect_cell 10 2 joint.pitch.target 0
expect_cell 0 1 dock.front 2
expect_cell 0 1 dock.front.peer 2
expect_cell 0 2 dock.back.peer 1
expect_cell 0 1 dock.back 1
expect_cell 0 1 dock.back.peer ""
expect_cell 0 0 trace.at_load 7
expect_cell 0 0 module world
expect_cell 20 0 trace.at_0_2 0.5
angle=$(cell 30 1 joint.pitch.angle)
check "pitch moved towards its target (angle $angle at step 30)" awk -v a="$angle" 'BEGIN { exit !(a > 0.15 && a < 0.35) }'
torque=$(cell 30 1 joint.pitch.torque)
check "pitch torque is a number ($torque)" awk -v a="$torque" 'BEGIN { exit !(a == a + 0 && a != "") }'
check "world row for on_end at the last step" [ "$(awk -F, '$3 == 0 && $2 == 30' "$csv" | wc -l)" -eq 1 ]
end_col=$(echo "$header" | tr , '\n' | grep -nx trace.at_end | cut -d: -f1)
check "on_end series in the last row" [ "$(awk -F, -v c="$end_col" '$3 == 0 && $2 == 30 {print $c}' "$csv")" = "0.5" ]

# The summary: metrics, version, command line, typed parameters, seed.
json="$dir/other/s.json"
check "summary written into a new folder" [ -f "$json" ]
check "metric final_x" grep -q '"final_x": -\?[0-9]' "$json"
check "metric steps_seen = 30" grep -q '"steps_seen": 30\.0' "$json"
check "version" grep -qE '"version": "[0-9]+\.[0-9]+\.[0-9]+' "$json"
check "command line" grep -q '"--trace-every",' "$json"
check "params typed" bash -c "tr -d ' \n' < '$json' | grep -q '\"params\":{\"gain\":2.5,\"mode\":\"fast\",\"n\":3}'"
check "seed" grep -q '"seed": 4' "$json"

# Every step by default; a module name that needs quoting.
cat > "$dir/quoted.lua" <<'LUA'
world.set{duration = 1}
world.spawn("superbot", {at = {0, 0, 0.053}, name = 'a, "b"', fixed = true})
LUA
"$rm3d" run "$dir/quoted.lua" --steps 3 --trace "$dir/q.csv" --quiet > /dev/null 2>&1
check "every step traced without --trace-every" [ "$(wc -l < "$dir/q.csv")" -eq 5 ]
check "a quoted module name" grep -q '^0,0,1,"a, ""b""",superbot,' "$dir/q.csv"

# rm3d plot: PNG and SVG, one module by name and one by id, two columns.
"$rm3d" plot "$csv" --y joint.pitch.angle,joint.pitch.target --module m1 --module 2 \
  --out "$dir/plots/pitch.png" --title "pitch of m1 and m2" > "$dir/plot.log" 2>&1
rc=$?
cat "$dir/plot.log"
png="$dir/plots/pitch.png"
check "plot exits 0" [ $rc -eq 0 ]
check "plot says 4 lines, 16 points" grep -q "wrote .*pitch.png: 4 lines, 16 points" "$dir/plot.log"
check "PNG signature" [ "$(head -c 8 "$png" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ]
check "PNG larger than 5 kB ($(stat -c %s "$png" 2>/dev/null) bytes)" [ "$(stat -c %s "$png" 2>/dev/null || echo 0)" -gt 5000 ]
check "no temporary files beside the plot" [ "$(ls "$dir/plots")" = "pitch.png" ]
"$rm3d" plot "$csv" --y trace.calls --out "$dir/calls.svg" > /dev/null 2>&1
check "SVG plot" grep -q "<svg" "$dir/calls.svg"
"$rm3d" plot "$csv" --y trace.callz > "$dir/bad.log" 2>&1
rc=$?
check "unknown column: exit 2" [ $rc -eq 2 ]
check "unknown column: names the file and lists the columns" \
  grep -q "rm3d plot: --y trace.callz: no column 'trace.callz' in .*t.csv (columns: time, step, .*trace.calls" "$dir/bad.log"

# rm3d plot of a sweep's JSON lines: a line per --by value, --mean over seeds with the standard
# deviation written for gnuplot's error bars.
cat > "$dir/sweep.jsonl" <<'JSONL'
{"params": {"a": 1, "p": 2}, "seed": 1, "exit_code": 0, "metrics": {"v": 1.0}}
{"params": {"a": 1, "p": 2}, "seed": 2, "exit_code": 0, "metrics": {"v": 3.0}}
{"params": {"a": 2, "p": 2}, "seed": 1, "exit_code": 0, "metrics": {"v": 5.0}}
{"params": {"a": 1, "p": 4}, "seed": 1, "exit_code": 0, "metrics": {"v": 7.0}}
{"params": {"a": 2, "p": 4}, "seed": 1, "exit_code": 1, "metrics": {}}
JSONL
"$rm3d" plot "$dir/sweep.jsonl" --x params.a --y metrics.v --by params.p --mean --out "$dir/sweep.png" \
  > "$dir/sweep.log" 2>&1
rc=$?
cat "$dir/sweep.log"
check "sweep plot exits 0" [ $rc -eq 0 ]
check "sweep plot: 2 lines (p = 2, p = 4), 3 mean points (the failed run has no metric)" \
  grep -q "wrote .*sweep.png: 2 lines, 3 points" "$dir/sweep.log"
check "sweep plot is a PNG" [ "$(head -c 8 "$dir/sweep.png" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ]
# Axis labels and a title of the user's choosing.
"$rm3d" plot "$dir/sweep.jsonl" --x params.a --y metrics.v --by params.p --mean --out "$dir/labels.svg" \
  --xlabel "gait amplitude (rad)" --ylabel "speed (m/s)" --title "my sweep" > /dev/null 2>&1
for label in "gait amplitude (rad)" "speed (m/s)" "my sweep"; do
  check "plot --xlabel/--ylabel/--title: '$label' in the SVG" grep -qF "$label" "$dir/labels.svg"
done
check "plot: the column name is not the x label when --xlabel is given" bash -c "! grep -qF '>params.a<' '$dir/labels.svg'"
printf '{"params": {"a": 1}}\nnot json\n' > "$dir/bad.jsonl"
"$rm3d" plot "$dir/bad.jsonl" --x params.a --y metrics.v > "$dir/badj.log" 2>&1
rc=$?
check "bad JSON line: exit 2, names file:line" [ $rc -eq 2 ]
check "bad JSON line: the message" grep -q "bad.jsonl:2: expected a JSON object per line" "$dir/badj.log"

[ $fail -eq 0 ] && echo "1 passed, 0 failed" || echo "0 passed, 1 failed"
exit $fail
