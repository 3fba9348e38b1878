#!/usr/bin/env bash
# `rm3d run --watch` end to end: an edited behaviour is reloaded into the running modules, a
# broken edit is rejected while the old code runs on, and an edited world script rebuilds the
# world. Usage: watch_test.sh RM3D SRC OUT
set -u
rm3d=$1 src=$2 out=$3
dir="$out/watch"
rm -rf "$dir" && mkdir -p "$dir"
cp "$src/worlds/nodders.lua" "$dir/w.lua"
cp "$src/behaviors/nod.lua" "$dir/nod.lua"
sed -i 's|behaviors/nod.lua|nod.lua|g' "$dir/w.lua"
"$rm3d" run "$dir/w.lua" --watch --seconds 4 --quiet > "$dir/log.txt" 2>&1 &
pid=$!
sleep 1
sed -i 's|local amplitude = params.amplitude or 0.5 .*|local amplitude = 0.9|' "$dir/nod.lua"
sleep 0.8
echo "function step( broken" > "$dir/nod.lua"
sleep 0.8
echo "-- edited" >> "$dir/w.lua"
wait $pid
rc=$?
cat "$dir/log.txt"
fail=0
grep -q "reloaded .*watch/nod.lua into 2 modules" "$dir/log.txt" || { echo "FAIL: no reload"; fail=1; }
grep -q "reload rejected, old code keeps running: .*nod.lua:2:" "$dir/log.txt" || { echo "FAIL: broken edit not rejected"; fail=1; }
grep -q "world script changed: rebuilt" "$dir/log.txt" || { echo "FAIL: world not rebuilt"; fail=1; }
[ $rc -eq 0 ] || { echo "FAIL: exit code $rc"; fail=1; }
[ $fail -eq 0 ] && echo "1 passed, 0 failed" || echo "0 passed, 1 failed"
exit $fail
