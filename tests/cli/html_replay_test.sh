#!/usr/bin/env bash
# `--html` pages in a real browser (docs/replay-html.md). Headless Chromium opens the pages from
# disk (file://, no server) and dumps the DOM, where the page keeps its state in
# <pre id="rm3d-status"> (frames, modules, time, connections, caught errors); `#t=T` seeks.
# - worlds/track_to_snake.lua recorded and written with `replay --html`: loads with no console
#   error; the frame count and module count are the recording's; at t = 5 s and t = 15 s the
#   graph panel lists exactly the connections `rm3d run --seconds T --graph` reports there (six in
#   a loop, then five in a chain);
# - a screenshot of the page at t = 15 s (#shot: the 3D view alone, 1280x720) against
#   `rm3d replay --png --at 15` at the same camera: the orange bracket pixels of the two overlap
#   with intersection over union >= 0.6, and clearly more than with the replay's picture at
#   t = 5 s (a page that ignored the seek would fail); the engaged docks' green bars show;
# - a 1000-module snake (`run --html`, 2 s) opens with no console error, 1000 modules, 999
#   connections at the start and at its end those of the run's --graph;
# - --html errors: an unwritable path, a file that is not a recording, three.js missing
#   (RM3D_THREE_JS pointing nowhere: the message names the path and libjs-three; `run` stops
#   before running).
# Skipped (exit 77) with a line saying why where Chromium is missing or cannot start.
# Usage: html_replay_test.sh RM3D SRC OUT IMAGE_COMPARE
set -u
rm3d=$1 src=$2 out=$3 cmp=$4
dir="$out/html_replay"
rm -rf "$dir" && mkdir -p "$dir"
fail=0 passed=0
check() {  # check DESCRIPTION COMMAND...
  local what=$1
  shift
  if "$@"; then passed=$((passed + 1)); else echo "FAIL: $what"; fail=$((fail + 1)); fi
}

browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then
  echo "SKIP: chromium is not installed (.ci/install-deps installs it; apt-get install chromium)"
  exit 77
fi
if ! command -v jq > /dev/null; then
  echo "SKIP: jq is not installed (.ci/install-deps installs it; apt-get install jq)"
  exit 77
fi
# WebGL without a GPU: SwiftShader through ANGLE.
flags=(--headless=new --no-sandbox --disable-gpu --use-angle=swiftshader --enable-unsafe-swiftshader
       --enable-logging=stderr --window-size=1280,720 --hide-scrollbars --user-data-dir="$dir/profile")
printf '<html><body><pre id="p">no</pre><script>document.getElementById("p").textContent = ' > "$dir/probe.html"
printf '(document.createElement("canvas").getContext("webgl") ? "webgl" : "none")</script></body></html>\n' >> "$dir/probe.html"
timeout 120 "$browser" "${flags[@]}" --virtual-time-budget=1000 --dump-dom "file://$dir/probe.html" \
  > "$dir/probe.dom" 2> "$dir/probe.err"
if ! grep -q '<pre id="p">webgl</pre>' "$dir/probe.dom"; then
  echo "SKIP: headless chromium cannot start here or has no WebGL ($browser); its last lines:"
  tail -n 3 "$dir/probe.err"
  exit 77
fi

# status PAGE FRAGMENT NAME: the page's state after loading (and seeking) as JSON in NAME.json;
# its console lines in NAME.err. A page not ready when Chromium dumps it (once on a busy CI
# machine: the 1000-module page, whose frames DecompressionStream decodes off the page's thread)
# is opened again with a larger virtual-time budget, twice at most.
status() {
  local budget
  for budget in 30000 120000 600000; do
    timeout 300 "$browser" "${flags[@]}" --virtual-time-budget=$budget --dump-dom "file://$1#$2" \
      > "$dir/$3.dom" 2> "$dir/$3.err"
    sed -n 's/.*<pre id="rm3d-status" hidden="">\(.*\)<\/pre>.*/\1/p' "$dir/$3.dom" |
      sed 's/&lt;/</g; s/&gt;/>/g; s/&amp;/\&/g' > "$dir/$3.json"
    [ -s "$dir/$3.json" ] || echo '{}' > "$dir/$3.json"
    [ "$(jq -r .ready "$dir/$3.json")" = true ] && return
    echo "$1#$2: not ready after a virtual-time budget of $budget ms; Chromium's last lines:"
    tail -n 3 "$dir/$3.err"
  done
}
field() { jq -r "$2" "$dir/$1.json"; }
# No console errors: nothing the page caught, no uncaught exception or console.error line.
no_errors() {
  [ "$(field "$1" '.errors | length')" = 0 ] && ! grep -E 'Uncaught|:ERROR:CONSOLE|"error", source:' "$dir/$1.err"
}
# The connections of a --graph JSON file as sorted "name.dock - name.dock" lines.
graph_lines() {
  jq -r '(.modules | map({(.id | tostring): .name}) | add) as $n |
         .connections[] | [($n[.[0] | tostring] + "." + .[1]), ($n[.[2] | tostring] + "." + .[3])] |
         sort | join(" - ")' "$1" | sort
}
page_lines() { jq -r '.connections[] | sort | join(" - ")' "$dir/$1.json" | sort; }

# --- worlds/track_to_snake.lua
"$rm3d" run "$src/worlds/track_to_snake.lua" --quiet --record "$dir/tts.rec" > "$dir/tts_run.txt" 2>&1
check "track_to_snake recorded" test -s "$dir/tts.rec"
"$rm3d" replay "$dir/tts.rec" --html "$dir/tts.html" > "$dir/tts_html.txt" 2>&1
cat "$dir/tts_html.txt"
check "replay --html wrote the page" grep -q "^wrote .*tts.html" "$dir/tts_html.txt"
# The page says what the world shows: the first sentence of the world's opening comment.
check "the page carries the world's own description" \
  grep -q '"about":"Rolling track to snake (the paper.s Fig. 5, middle): six SuperBots docked into a closed loop' "$dir/tts.html"
frames=$(sed -n 's/.*: \([0-9]*\) frames, .*/\1/p' "$dir/tts_html.txt")
modules=$(sed -n 's/.* \([0-9]*\) modules, recorded from.*/\1/p' "$dir/tts_html.txt")
for t in 5 15; do
  "$rm3d" run "$src/worlds/track_to_snake.lua" --quiet --seconds $t --graph "$dir/graph_$t.json" > /dev/null 2>&1
  status "$dir/tts.html" "t=$t" "tts_$t"
  check "t=$t: page ready" test "$(field "tts_$t" .ready)" = true
  check "t=$t: no console errors" no_errors "tts_$t"
  check "t=$t: frames $(field "tts_$t" .recordedFrames), recording $frames" test "$(field "tts_$t" .recordedFrames)" = "$frames"
  check "t=$t: all frames kept" test "$(field "tts_$t" .frames)" = "$frames"
  check "t=$t: modules $(field "tts_$t" .modules), recording $modules" test "$(field "tts_$t" .modules)" = "$modules"
  check "t=$t: seeked to $(field "tts_$t" .time)" jq -e ".time - $t | fabs < 0.01" "$dir/tts_$t.json" > /dev/null
  check "t=$t: drawn" jq -e '.drawn > 0' "$dir/tts_$t.json" > /dev/null
  graph_lines "$dir/graph_$t.json" > "$dir/graph_$t.txt"
  page_lines "tts_$t" > "$dir/page_$t.txt"
  check "t=$t: the graph panel lists the run's connections" diff "$dir/graph_$t.txt" "$dir/page_$t.txt"
done
check "six connections at t=5" test "$(wc -l < "$dir/page_5.txt")" -eq 6
check "five connections at t=15" test "$(wc -l < "$dir/page_15.txt")" -eq 5

# Seek and camera: the page's picture at t = 15 s against `replay --png` at the same time.
timeout 300 "$browser" "${flags[@]}" --virtual-time-budget=30000 --screenshot="$dir/page_15.png" \
  "file://$dir/tts.html#t=15&shot" > /dev/null 2> "$dir/shot.err"
"$rm3d" replay "$dir/tts.rec" --png "$dir/replay_15.png" --at 15 --size 1280x720 > /dev/null
"$rm3d" replay "$dir/tts.rec" --png "$dir/replay_5.png" --at 5 --size 1280x720 > /dev/null
orange=0.95,0.55,0.1
read -r same na nb < <("$cmp" iou "$dir/page_15.png" "$dir/replay_15.png" $orange)
read -r other _ _ < <("$cmp" iou "$dir/page_15.png" "$dir/replay_5.png" $orange)
echo "orange pixels: page $na, replay $nb; IoU at the same time $same, against t=5 $other"
check "page at t=15 matches replay --png (IoU $same >= 0.6)" awk "BEGIN { exit !($same >= 0.6) }"
check "and not the picture at t=5 (IoU $other < $same - 0.2)" awk "BEGIN { exit !($other < $same - 0.2) }"
green=$("$cmp" count "$dir/page_15.png" 0.2,0.8,0.3)
check "engaged dock bars in the page ($green green pixels)" test "${green:-0}" -gt 100

# --- 1000 modules: opens, no errors, all modules.
timeout 600 "$rm3d" run "$src/worlds/snake.lua" --param modules=1000 --seconds 2 --quiet --html "$dir/big.html" \
  --graph "$dir/big_graph.json" > "$dir/big_run.txt" 2>&1
grep "^wrote" "$dir/big_run.txt"
check "1000 modules: page written" test -s "$dir/big.html"
check "1000 modules: no recording left beside it" test ! -e "$dir/big.html.rm3drec.part"
status "$dir/big.html" "t=0" big0
check "1000 modules: ready" test "$(field big0 .ready)" = true
check "1000 modules: no console errors" no_errors big0
check "1000 modules: modules" test "$(field big0 .modules)" = 1000
check "1000 modules: 999 connections at the start" test "$(field big0 '.connections | length')" = 999
# At the end the page's graph is the run's --graph (the long chain breaks in places under its load).
status "$dir/big.html" "t=2" big2
check "1000 modules, t=2: no console errors" no_errors big2
graph_lines "$dir/big_graph.json" > "$dir/big_graph.txt"
page_lines big2 > "$dir/big_page.txt"
echo "1000 modules at t=2: $(wc -l < "$dir/big_page.txt") connections on the page, $(wc -l < "$dir/big_graph.txt") in --graph"
check "1000 modules, t=2: the graph panel lists the run's connections" diff -q "$dir/big_graph.txt" "$dir/big_page.txt"

# --- errors
"$rm3d" replay "$dir/tts.rec" --html /proc/nope/x.html > "$dir/e1.txt" 2>&1
rc=$?
check "unwritable --html: exit $rc, expected 2" test $rc -eq 2
check "unwritable --html: names the flag" grep -q -- "--html" "$dir/e1.txt"
echo "not a recording" > "$dir/bad.rec"
"$rm3d" replay "$dir/bad.rec" --html "$dir/bad.html" > "$dir/e2.txt" 2>&1
rc=$?
check "bad recording: exit $rc, expected 2" test $rc -eq 2
check "bad recording: no page" test ! -e "$dir/bad.html"

RM3D_THREE_JS=/nonexistent/three.min.js "$rm3d" replay "$dir/tts.rec" --html "$dir/nothree.html" > "$dir/e3.txt" 2>&1
rc=$?
cat "$dir/e3.txt"
check "three.js missing: exit $rc, expected 2" test $rc -eq 2
check "three.js missing: names the path and the package" \
  grep -q -- "--html .*three.js is not at /nonexistent/three.min.js (install the Debian package libjs-three" "$dir/e3.txt"
check "three.js missing: no page" test ! -e "$dir/nothree.html"
RM3D_THREE_JS=/nonexistent/three.min.js "$rm3d" run "$src/worlds/snake.lua" --quiet --html "$dir/nothree_run.html" \
  > "$dir/e4.txt" 2>&1
rc=$?
check "run --html, three.js missing: exit $rc, expected 2" test $rc -eq 2
check "run --html, three.js missing: stopped before the run" bash -c "! grep -q 'steps,' '$dir/e4.txt'"
check "run --html, three.js missing: no recording left" test ! -e "$dir/nothree_run.html.rm3drec.part"

echo "$passed passed, $fail failed"
[ $fail -eq 0 ]
