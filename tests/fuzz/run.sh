#!/usr/bin/env bash
# Builds the libFuzzer targets into build-fuzz/ (clang, -DRM3D_FUZZ=ON) and runs them.
# Usage: tests/fuzz/run.sh TARGET SECONDS    TARGET: module_type, world_script, lua_value, recording,
#        height_image or all
#        (all: each target in turn for SECONDS). Env: FUZZ_JOBS (parallel fuzzing processes per
#        target, default 1), FUZZ_ARGS (extra libFuzzer flags).
# The corpus grows in build-fuzz/corpus/TARGET (seeded from the project's module types or worlds,
# and tests/fuzz/corpus/TARGET); crashes,
# timeouts and out-of-memory inputs are saved under build-fuzz/crashes/TARGET/. The fuzzer keeps
# going after a finding (libFuzzer's fork mode) and the script exits 1 if any was saved.
# Reproduce one: build-fuzz/fuzz_TARGET build-fuzz/crashes/TARGET/crash-...
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$(pwd)
[ $# -eq 2 ] || { echo "usage: $0 module_type|world_script|lua_value|recording|height_image|all SECONDS" >&2; exit 2; }
target=$1 seconds=$2
targets=(module_type world_script lua_value recording height_image)
if [ "$target" = all ]; then
  sel=("${targets[@]}")
else
  [[ " ${targets[*]} " == *" $target "* ]] || { echo "unknown target '$target' (${targets[*]} or all)" >&2; exit 2; }
  sel=("$target")
fi

cxx=$(command -v clang++-14 || command -v clang++ || true)
[ -n "$cxx" ] || { echo "fuzzing needs clang++ (apt-get install clang-14 libclang-rt-14-dev)" >&2; exit 2; }
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$root}
cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER="$cxx" "${launcher[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DRM3D_FUZZ=ON -DRM3D_SANITIZE=address,undefined >/dev/null
cmake --build build-fuzz --parallel "$(nproc)" --target "${sel[@]/#/fuzz_}"

# Leaks are findings too; UBSan does not recover (see RM3D_SANITIZE).
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
found=0
for t in "${sel[@]}"; do
  corpus=build-fuzz/corpus/$t crashes=build-fuzz/crashes/$t
  mkdir -p "$corpus" "$crashes"
  dict=()
  [ -f "tests/fuzz/$t.dict" ] && dict=(-dict="tests/fuzz/$t.dict")
  # Seeds: the project's own files of that kind (read in place, not copied), plus hand-made ones.
  seeds=()
  maxlen=${FUZZ_MAX_LEN:-8192}
  case $t in
    module_type) seeds=(assets/modules tests/modules) ;;
    world_script) seeds=(worlds tests/worlds) ;;
    height_image) ;;  # seeds: tests/fuzz/corpus/height_image (small gray and colour PNGs)
    recording) maxlen=${FUZZ_MAX_LEN:-65536} ;;  # seeds: tests/fuzz/corpus/recording (small runs)
  esac
  [ -d "tests/fuzz/corpus/$t" ] && seeds+=("tests/fuzz/corpus/$t")
  echo "== fuzz_$t for $seconds s"
  # fork mode: a crash, timeout or OOM is saved and fuzzing goes on. -close_fd_mask=3: the
  # targets' own output (world-script print, module logs) is dropped; libFuzzer and sanitizer
  # reports still come through.
  rc=0
  "build-fuzz/fuzz_$t" -fork="${FUZZ_JOBS:-1}" -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -max_len=$maxlen -close_fd_mask=3 \
    -artifact_prefix="$crashes/" -print_final_stats=1 "${dict[@]}" ${FUZZ_ARGS:-} \
    "$corpus" "${seeds[@]}" || rc=$?
  n=$(find "$crashes" -type f | wc -l)
  echo "== fuzz_$t: exit $rc, $n saved finding(s) in $crashes"
  [ "$rc" -eq 0 ] && [ "$n" -eq 0 ] || found=1
done
exit $found
