#!/usr/bin/env bash
# The engine's layers (docs/architecture.md): every engine/**/*.{h,cpp} includes project headers
# only from its own layer or a layer below it. Fails naming file:line and both layers on any
# `#include "dir/..."` of a higher layer, of a folder in no layer, or a relative include; and on
# a source folder under engine/ that is in no layer. First checks itself on a small tree with
# known breaches (so a checker that finds nothing fails too). Usage: layering_test.sh SRC OUT
set -u
src=$1 out=$2

# The layers, lowest first: "name:folder folder ...". The public API's headers (engine/api/rm3d,
# included as "rm3d/...") belong to the api layer.
LAYERS=(
  "core:core assets"
  "physics:physics"
  "sim:modules messaging docking particles world"
  "io:io"
  "script:script"
  "render:render"
  "api:api rm3d"
  "app:app"
  "python:python"
)

# check ENGINE_DIR: prints one line per breach, exits 1 if any.
check() {
  local engine=$1 table="" i=0 entry
  for entry in "${LAYERS[@]}"; do
    table+="$i ${entry%%:*} ${entry#*:};"
    i=$((i + 1))
  done
  local files
  mapfile -t files < <(cd "$engine" && find . -type f \( -name '*.h' -o -name '*.cpp' \) | sed 's#^\./##' | LC_ALL=C sort)
  [ ${#files[@]} -gt 0 ] || { echo "$engine: no .h or .cpp files"; return 1; }
  (cd "$engine" && awk -v table="$table" '
      BEGIN {
        n = split(table, rows, ";")
        for (r = 1; r <= n; ++r) {
          k = split(rows[r], f, " ")
          if (k < 3) continue
          for (j = 3; j <= k; ++j) { rank[f[j]] = f[1]; lname[f[j]] = f[2] }
        }
        bad = 0
      }
      FNR == 1 {
        split(FILENAME, parts, "/")
        own = parts[1]
        if (!(own in rank)) {
          printf "engine/%s: folder engine/%s/ is in no layer (add it to the table in %s)\n", FILENAME, own, "tests/cli/layering_test.sh"
          bad = 1
        }
      }
      /^[ \t]*#[ \t]*include[ \t]*"/ {
        inc = $0
        sub(/^[^"]*"/, "", inc)
        sub(/".*$/, "", inc)
        if (inc !~ /\//) next  # a generated header beside the file (rm3d_version_info.h)
        if (inc ~ /^\.\.?\//) {
          printf "engine/%s:%d: relative include \"%s\" (expected \"folder/file.h\" from engine/)\n", FILENAME, FNR, inc
          bad = 1
          next
        }
        dir = inc
        sub(/\/.*$/, "", dir)
        if (!(own in rank)) next
        if (!(dir in rank)) {
          printf "engine/%s:%d: includes \"%s\": engine/%s/ is in no layer\n", FILENAME, FNR, inc, dir
          bad = 1
        } else if (rank[dir] + 0 > rank[own] + 0) {
          printf "engine/%s:%d: includes \"%s\": layer %s (%s/) may not include layer %s (%s/), which is above it\n", FILENAME, FNR, inc, lname[own], own, lname[dir], dir
          bad = 1
        }
      }
      END { exit bad }' "${files[@]}")
}

# Self-check: a tree with one allowed include and three breaches, each reported with its line.
fixture="$out/layering_fixture"
rm -rf "$fixture" && mkdir -p "$fixture"/{core,world,io,render,tools}
printf '#pragma once\n' > "$fixture/core/types.h"
printf '#include "core/types.h"\n#include <vector>\n\n#include "render/picture.h"\n' > "$fixture/world/world.cpp"
printf '#include "world/world.h"\n#include "io/summary.h"\n#include "../core/types.h"\n' > "$fixture/io/summary.cpp"
printf '#include "io/summary.h"\n' > "$fixture/render/picture.h"
printf '#include "core/types.h"\n' > "$fixture/tools/tool.cpp"
got=$(check "$fixture")
rc=$?
want='engine/io/summary.cpp:3: relative include "../core/types.h" (expected "folder/file.h" from engine/)
engine/tools/tool.cpp: folder engine/tools/ is in no layer (add it to the table in tests/cli/layering_test.sh)
engine/world/world.cpp:4: includes "render/picture.h": layer sim (world/) may not include layer render (render/), which is above it'
if [ $rc -ne 1 ] || [ "$got" != "$want" ]; then
  echo "FAIL: the checker itself: on $fixture it exited $rc and printed:"
  echo "$got"
  echo "expected exit 1 and:"
  echo "$want"
  exit 1
fi
echo "ok: the checker finds the three breaches in its fixture (file:line, both layers)"

if ! check "$src/engine"; then
  echo "FAIL: includes against the layer order (docs/architecture.md, \"Layers\")"
  exit 1
fi
echo "ok: $(find "$src/engine" -type f \( -name '*.h' -o -name '*.cpp' \) | wc -l) engine files include only their own layer or those below it"
