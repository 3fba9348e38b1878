#!/usr/bin/env bash
# Install and identity: `cmake --install` into a fresh prefix, then the installed rm3d, run from
# another folder with nothing else copied, runs a stock world from its own data; not-found errors
# name where they looked; a copied binary does not quietly use its build's checkout; `cpack -G DEB`
# packages the same files.
# Usage: install_test.sh RM3D SRC BUILD
set -u
RM3D=$(readlink -f "$1") SRC=$(readlink -f "$2") BUILD=$(readlink -f "$3")
tmp=$(mktemp -d /tmp/rm3d_install.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
check() {  # check NAME EXPECTED_CODE REGEX -- command...
  local name=$1 code=$2 re=$3
  shift 4
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  if [ "$rc" != "$code" ]; then
    fail "$name: exit code $rc, expected $code"; echo "$out" | tail -5
  elif ! grep -Eq -- "$re" <<<"$out"; then
    fail "$name: output does not match '$re'"; echo "$out" | tail -8
  else
    echo "ok: $name"
  fi
}
unset RM3D_ROOT

cmake --install "$BUILD" --prefix "$tmp/prefix" >"$tmp/install.log" 2>&1 || { cat "$tmp/install.log"; exit 1; }
prefix=$tmp/prefix
for f in bin/rm3d share/rm3d/assets/modules/superbot.lua share/rm3d/assets/meshes share/rm3d/lua/noise.lua \
         share/rm3d/behaviors/snake.lua share/rm3d/worlds/snake.lua share/rm3d/assets/terrain/hills_30.png \
         share/rm3d/assets/readme/snake.png; do
  [ -e "$prefix/$f" ] || fail "not installed: $f"
done
mkdir -p "$tmp/elsewhere" && cd "$tmp/elsewhere"
check "installed --version" 0 "^rm3d [0-9]+\.[0-9]+\.[0-9]+" -- "$prefix/bin/rm3d" --version
check "installed rm3d runs a stock world" 0 "10 modules, 0 faults" -- \
  "$prefix/bin/rm3d" run "$prefix/share/rm3d/worlds/snake.lua" --seconds 0.2 --json "$tmp/elsewhere/snake.json"
grep -q '"modules"' "$tmp/elsewhere/snake.json" || fail "no summary from the installed rm3d"
# A shipped world named as in the docs, from a folder that does not hold it, is the data root's;
# `rm3d worlds` lists them; a missing one names both places it looked.
check "installed rm3d runs worlds/snake.lua from elsewhere" 0 "10 modules, 0 faults" -- \
  "$prefix/bin/rm3d" run worlds/snake.lua --seconds 0.2
check "and says which file it ran" 0 "worlds/snake.lua: not found here; using $prefix/share/rm3d/worlds/snake.lua" -- \
  "$prefix/bin/rm3d" run worlds/snake.lua --seconds 0.1
check "installed rm3d runs the terrain world (its heightfield image is installed)" 0 "0 faults" -- \
  "$prefix/bin/rm3d" run worlds/terrain.lua --seconds 0.1 --quiet
check "installed rm3d tests a shipped world from elsewhere" 0 "1 passed, 0 failed" -- \
  "$prefix/bin/rm3d" test worlds/nodders.lua
check "rm3d worlds lists the shipped worlds" 0 "^  worlds/snake.lua +[A-Z]" -- \
  "$prefix/bin/rm3d" worlds
check "and the Python examples' worlds, one folder down" 0 "^  worlds/python/py_chain.lua +A straight chain" -- \
  "$prefix/bin/rm3d" worlds
check "each with its first sentence, without naming itself" 0 "^  worlds/dock_pair.lua +Docking on the ground\.$" -- \
  "$prefix/bin/rm3d" worlds
check "a world in neither place names both" 2 "worlds/nowhere.lua: not found in the working folder \($tmp/elsewhere\) nor in the data root \($prefix/share/rm3d\)" -- \
  "$prefix/bin/rm3d" run worlds/nowhere.lua
# rm3d init: a project folder outside the checkout whose first world runs, with a .luarc.json that
# points at the installed API definitions; it never overwrites.
check "rm3d init makes a project" 0 "wrote $tmp/proj/worlds/hello.lua" -- "$prefix/bin/rm3d" init "$tmp/proj"
grep -q "\"$prefix/share/rm3d/lua/meta\"" "$tmp/proj/.luarc.json" || fail ".luarc.json does not name $prefix/share/rm3d/lua/meta"
[ -f "$prefix/share/rm3d/lua/meta/world.lua" ] || fail "the API definitions are not installed"
check "the project's world runs" 0 "1 module, 0 faults" -- bash -c "cd '$tmp/proj' && '$prefix/bin/rm3d' run worlds/hello.lua"
check "the project's world passes rm3d test" 0 "1 passed, 0 failed" -- bash -c "cd '$tmp/proj' && '$prefix/bin/rm3d' test worlds/hello.lua"
check "rm3d init never overwrites" 2 "$tmp/proj/worlds/hello.lua already exists" -- "$prefix/bin/rm3d" init "$tmp/proj"
# Not found: the errors name the installed data's folders.
printf 'world.spawn("megabot")\n' >unknown_type.lua
check "unknown type names the installed folder" 2 "unknown module type 'megabot'.*looked in $prefix/share/rm3d/assets/modules/" -- \
  "$prefix/bin/rm3d" run unknown_type.lua
printf 'world.spawn("superbot", {behavior = "nowhere.lua"})\n' >no_behaviour.lua
check "missing behaviour names both places" 2 "nowhere.lua' not found \(looked in $tmp/elsewhere/ and $prefix/share/rm3d/, the project root: the only folders a world's files may come from" -- \
  "$prefix/bin/rm3d" run no_behaviour.lua
# A copy of the build's binary outside its build folder finds no data, and says where it looked.
mkdir -p "$tmp/copy" && cp "$RM3D" "$tmp/copy/rm3d"
check "copied binary: nothing found, places named" 2 \
  "no RM3D data found" -- "$tmp/copy/rm3d" run "$prefix/share/rm3d/worlds/snake.lua"
out=$("$tmp/copy/rm3d" run "$prefix/share/rm3d/worlds/snake.lua" 2>&1)
for place in "$tmp/share/rm3d \(next to the executable" "RM3D_ROOT \(not set\)" "$tmp/elsewhere and its parents" \
             "--root DIR or RM3D_ROOT=DIR"; do
  grep -Eq -- "$place" <<<"$out" || fail "the not-found error does not name '$place': $out"
done
check "RM3D_ROOT that is no project" 2 "RM3D_ROOT=$tmp/elsewhere: not an RM3D project" -- \
  env RM3D_ROOT="$tmp/elsewhere" "$tmp/copy/rm3d" run "$prefix/share/rm3d/worlds/snake.lua"
check "RM3D_ROOT gives the copy its data" 0 "10 modules" -- \
  env RM3D_ROOT="$SRC" "$tmp/copy/rm3d" run "$SRC/worlds/snake.lua" --seconds 0.1
check "the current project gives the copy its data" 0 "10 modules" -- \
  bash -c "cd '$SRC/worlds' && '$tmp/copy/rm3d' run snake.lua --seconds 0.1"
check "--root that is no project" 2 "--root $tmp/elsewhere: not an RM3D project" -- \
  "$prefix/bin/rm3d" --root "$tmp/elsewhere" run "$prefix/share/rm3d/worlds/snake.lua"

# The Python package: installed into Debian's python path under the prefix; imported from
# elsewhere, it finds the installed data (share/rm3d above the package), not this checkout.
pydir=$(ls -d "$prefix"/lib/python3*/dist-packages 2>/dev/null | head -1)
if [ -d "$BUILD/python/rm3d" ]; then
  if [ -z "$pydir" ] || [ ! -f "$pydir/rm3d/__init__.py" ] || ! ls "$pydir"/rm3d/_rm3d*.so >/dev/null 2>&1; then
    fail "the Python package is not installed under $prefix/lib/python3*/dist-packages/rm3d"
  else
    check "import rm3d after cmake --install" 0 "^ok 10 $prefix/share/rm3d/worlds/snake.lua" -- \
      env PYTHONPATH="$pydir" /usr/bin/python3 -c "
import rm3d
w = rm3d.World('$prefix/share/rm3d/worlds/snake.lua')
w.step(10)
print('ok', w.steps, w.summary()['world'])"
    printf 'world.spawn("superbot", {behavior = "behaviors/snake.lua"})\n' >py_world.lua
    check "an installed rm3d package uses the installed data" 0 "^ok 1$" -- \
      env PYTHONPATH="$pydir" /usr/bin/python3 -c "
import rm3d
w = rm3d.World('py_world.lua')
w.step(2)
print('ok', len(w.modules))"
  fi
fi

# The Debian package holds the same layout under /usr.
if command -v cpack >/dev/null && command -v dpkg-deb >/dev/null; then
  (cd "$BUILD" && cpack -G DEB -B "$tmp/deb" >"$tmp/cpack.log" 2>&1) || { fail "cpack -G DEB"; tail -5 "$tmp/cpack.log"; }
  deb=$(ls "$tmp"/deb/rm3d_*.deb 2>/dev/null | head -1)
  if [ -z "$deb" ]; then
    fail "cpack wrote no .deb"
  else
    list=$(dpkg-deb -c "$deb")
    for f in ./usr/bin/rm3d ./usr/share/rm3d/assets/modules/superbot.lua ./usr/share/rm3d/worlds/snake.lua; do
      grep -q " $f\$" <<<"$list" || fail "$deb lacks $f"
    done
    if [ -d "$BUILD/python/rm3d" ] && ! grep -Eq " \./usr/lib/python3[.0-9]*/dist-packages/rm3d/_rm3d[^ ]*\.so\$" <<<"$list"; then
      fail "$deb lacks the Python package (usr/lib/python3*/dist-packages/rm3d)"
    fi
    dpkg-deb -f "$deb" Depends | grep -q liblua5.4 || fail "$deb: no library dependencies: $(dpkg-deb -f "$deb" Depends)"
    echo "ok: $(basename "$deb")"
  fi
fi
[ "$fails" -eq 0 ] && echo "install: all checks passed" || { echo "install: $fails checks failed"; exit 1; }
