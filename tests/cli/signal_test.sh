#!/usr/bin/env bash
# SIGINT and SIGTERM end a run after the current step: world.on_end runs, the JSON summary is
# written (and parses) with "interrupted": true, and so is the --trace CSV (into folders made for
# them), with the series world.on_end recorded; the exit code is 130 / 143. `rm3d test`
# stops at the world being run and exits 130. Usage: signal_test.sh RM3D SRC OUT CMAKE
set -u
set -m  # background jobs in their own process group, with SIGINT not ignored
rm3d=$1 src=$2 out=$3 cmake=$4
dir="$out/signal"
rm -rf "$dir" && mkdir -p "$dir"
cat > "$dir/long.lua" <<'LUA'
world.set{duration = 100000}
world.ground{}
world.spawn('superbot', {at = {0, 0, 0.1}})
world.on_end(function(t) log('on_end ran at ' .. t); world.trace('ended_at', t) end)
LUA
# Reads FILE, fails unless it parses with interrupted = true, signal = SIG and stop_time > 0.
cat > "$dir/check.cmake" <<'CM'
file(READ ${FILE} j)
string(JSON interrupted ERROR_VARIABLE e GET "${j}" interrupted)
if(e)
  message(FATAL_ERROR "${FILE}: ${e}")
endif()
string(JSON sig GET "${j}" signal)
string(JSON stop GET "${j}" stop_time)
string(JSON code GET "${j}" exit_code)
if(NOT interrupted OR NOT sig STREQUAL "${SIG}" OR NOT stop GREATER 0 OR NOT code EQUAL ${CODE})
  message(FATAL_ERROR "${FILE}: interrupted ${interrupted}, signal ${sig}, stop_time ${stop}, exit_code ${code}")
endif()
CM
fail=0
for pair in INT:130 TERM:143; do
  sig=${pair%%:*} want=${pair##*:}
  "$rm3d" run "$dir/long.lua" --json "$dir/json/$sig.json" --trace "$dir/trace/$sig.csv" --trace-every 30 \
    > "$dir/$sig.log" 2>&1 &
  pid=$!
  sleep 2
  kill -$sig $pid
  wait $pid
  rc=$?
  cat "$dir/$sig.log"
  [ $rc -eq $want ] || { echo "FAIL: SIG$sig: exit code $rc, expected $want"; fail=1; }
  grep -q "interrupted (SIG$sig) at t=" "$dir/$sig.log" || { echo "FAIL: SIG$sig: no 'interrupted' line"; fail=1; }
  grep -q "on_end ran at" "$dir/$sig.log" || { echo "FAIL: SIG$sig: world.on_end did not run"; fail=1; }
  csv="$dir/trace/$sig.csv"
  if [ -f "$csv" ] && [ ! -e "$csv.part" ]; then
    head -1 "$csv" | grep -q "^time,step,module_id,module,type," || { echo "FAIL: SIG$sig: trace header"; fail=1; }
    [ "$(grep -c ',1,superbot_1,superbot,' "$csv")" -ge 2 ] || { echo "FAIL: SIG$sig: fewer than 2 module rows"; fail=1; }
    grep -q ',0,world,' "$csv" || { echo "FAIL: SIG$sig: no world row with on_end's series"; fail=1; }
  else
    echo "FAIL: SIG$sig: no trace (or its part file left)"; fail=1
  fi
  if [ -f "$dir/json/$sig.json" ]; then
    "$cmake" -DFILE="$dir/json/$sig.json" -DSIG="SIG$sig" -DCODE=$want -P "$dir/check.cmake" || { echo "FAIL: SIG$sig: summary"; fail=1; }
  else
    echo "FAIL: SIG$sig: no JSON summary"; fail=1
  fi
done
# rm3d test: the world being run ends, the rest are skipped, exit code 130.
"$rm3d" test "$dir/long.lua" "$src/tests/worlds/servo_45.lua" --junit "$dir/junit.xml" > "$dir/test.log" 2>&1 &
pid=$!
sleep 2
kill -INT $pid
wait $pid
rc=$?
cat "$dir/test.log"
[ $rc -eq 130 ] || { echo "FAIL: test: exit code $rc, expected 130"; fail=1; }
grep -q "^INTERRUPTED .*long.lua" "$dir/test.log" || { echo "FAIL: test: no INTERRUPTED line"; fail=1; }
grep -q "1 of 2 worlds not run" "$dir/test.log" || { echo "FAIL: test: the rest was not skipped"; fail=1; }
[ -f "$dir/junit.xml" ] || { echo "FAIL: test: no JUnit report"; fail=1; }
[ $fail -eq 0 ] && echo "1 passed, 0 failed" || echo "0 passed, 1 failed"
exit $fail
