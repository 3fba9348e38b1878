#!/usr/bin/env bash
# Runs the catalogue of bad inputs (cases.txt) against an rm3d binary and classifies each case:
#   ok       the outcome and the message are what cases.txt expects
#   crash    killed by a signal (exit >= 128 other than 130/143), or a sanitizer report
#   hang     still running at the timeout
#   escape   a sandbox probe got out (a marker file under /tmp/rm3d_bi_escape, or RM3D-ESCAPE
#            in the output)
#   unclear  it ended, but with the wrong exit code, a message that does not match, or a
#            missing or invalid JSON summary
# Prints a line per case that is not ok, then "N passed, N failed" and the count per class.
# Cases listed in known_failures.txt are reported but do not make the exit code non-zero; a
# listed case that passes does (the list must stay exactly today's failures).
#
# Usage: run.sh RM3D OUTDIR [ID-REGEX]
#   BI_JOBS (default 2) cases run side by side; BI_VMEM (KiB, default 4194304; "unlimited"
#   for an ASan binary) limits each case's address space; BI_TIMEOUT (default 5) seconds per case
#   unless cases.txt gives one;
#   BI_VERBOSE=1 prints the output of every case that is not ok.
set -u
if [ $# -lt 2 ]; then
  echo "usage: $0 RM3D OUTDIR [ID-REGEX]" >&2
  exit 2
fi
RM3D=$(readlink -f "$1")
OUT=$(mkdir -p "$2" && cd "$2" && pwd)
FILTER=${3:-}
BI=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
JOBS=${BI_JOBS:-2}
TMO=${BI_TIMEOUT:-5}
ESC=/tmp/rm3d_bi_escape
EVIL=/tmp/rm3d_bi_evil
export RM3D BI

if [ ! -x "$RM3D" ]; then
  echo "run.sh: $1: not an executable" >&2
  exit 2
fi

# A Lua file outside the project that the sandbox probes try to load.
mkdir -p "$EVIL" "$ESC"
printf 'print("RM3D-ESCAPE: loaded %s/evil.lua")\nreturn "evil loaded"\n' "$EVIL" > "$EVIL/evil.lua"
touch "$ESC/keep"

rm -rf "$OUT/cases" "$OUT/results" "$OUT/runner.log"
mkdir -p "$OUT/cases" "$OUT/results"

# run_case ID EXPECTED REGEX COMMAND: runs one case, writes "class<TAB>detail" to results/ID.
run_case() {
  local id=$1 expected=$2 regex=$3 command=$4 tmo=$TMO
  if [[ $expected == *@* ]]; then tmo=${expected#*@}; expected=${expected%@*}; fi
  local dir="$OUT/cases/$id" rc class detail="" json="" jsonerrs=""
  mkdir -p "$dir"
  local t0=$SECONDS
  local -a argv=()
  local shell=0
  if [[ $command == "sh: "* ]]; then
    shell=1
  else
    read -r -a argv <<< "${command//@\//$BI/}"
  fi
  if [[ ",$expected," == *,fault,* || ",$expected," == *,clean,* ]] && [ $shell = 0 ]; then
    argv+=(--json summary.json)
    json="$dir/summary.json"
  else
    local i
    for ((i = 0; i + 1 < ${#argv[@]}; i++)); do
      [ "${argv[$i]}" = --json ] && json="${argv[$((i + 1))]}"
    done
    [ -n "$json" ] && [[ $json != /* ]] && json="$dir/$json"
  fi
  (
    cd "$dir" || exit 99
    ulimit -v "${BI_VMEM:-4194304}" 2>/dev/null   # 4 GiB: a runaway allocation fails instead of taking the machine (BI_VMEM=unlimited under ASan, whose shadow memory needs more)
    if [ $shell = 1 ]; then
      exec timeout -k 5 "$tmo" bash -c "${command#sh: }"
    else
      exec timeout -k 5 "$tmo" "$RM3D" "${argv[@]}"
    fi
  ) > "$dir/output.txt" 2>&1 < /dev/null
  rc=$?
  echo $((SECONDS - t0)) > "$dir/seconds"
  echo "$rc" > "$dir/rc"

  local all="$dir/all.txt"
  cp "$dir/output.txt" "$all"
  local jsonok=1
  if [ -n "$json" ] && [ -f "$json" ]; then
    if jq -e . "$json" > /dev/null 2>&1; then
      jsonerrs=$(jq -r '[.modules[]?.error // empty | tostring] | join("\n")' "$json")
      printf '%s\n' "$jsonerrs" >> "$all"
      jq -r '.error // empty | tostring' "$json" >> "$all"
    else
      jsonok=0
    fi
  fi

  local markers
  # Any marker file is blamed on the case that finds it (with BI_JOBS > 1 it may be its neighbour's).
  markers=$(cd "$ESC" 2>/dev/null && ls -A | grep -v -x keep || true)
  if [ ! -e "$ESC/keep" ] && [[ $id == sandbox_* ]]; then markers="$markers keep (removed)"; touch "$ESC/keep"; fi
  if grep -a -q 'RM3D-ESCAPE' "$all" || [ -n "${markers// /}" ]; then
    class=escape
    detail=$(grep -a -m3 'RM3D-ESCAPE' "$all" | tr '\n' ' ')
    [ -n "${markers// /}" ] && detail="$detail marker files: $(echo $markers)"
    (cd "$ESC" && rm -f $markers 2>/dev/null)
  elif [ "$rc" = 124 ] || { [ "$rc" = 137 ] && ! [[ ",$expected," == *,137,* ]]; }; then
    class=hang
    detail="no exit within ${tmo} s"
  elif grep -a -q -E 'AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer|runtime error: ' "$all"; then
    class=crash
    detail="sanitizer: $(grep -a -m1 -E 'Sanitizer|runtime error: ' "$all")"
  elif [ "$rc" -ge 128 ] && [ "$rc" != 130 ] && [ "$rc" != 143 ]; then
    class=crash
    detail="exit $rc (signal $((rc - 128)))"
  else
    local want_ok=0 e
    IFS=',' read -r -a exps <<< "$expected"
    for e in "${exps[@]}"; do
      case $e in
        fault) [ "$rc" = 0 ] && [ -n "$jsonerrs" ] && want_ok=1 ;;
        clean) [ "$rc" = 0 ] && [ -n "$json" ] && [ -f "$json" ] && [ $jsonok = 1 ] && [ -z "$jsonerrs" ] &&
                 [ "$(jq -r '.error // empty' "$json")" = "" ] && want_ok=1 ;;
        *) [ "$rc" = "$e" ] && want_ok=1 ;;
      esac
    done
    if [ $jsonok = 0 ]; then
      class=unclear
      detail="exit $rc; the JSON summary is not valid JSON"
    elif [ $want_ok = 0 ]; then
      class=unclear
      if [[ ",$expected," == *,fault,* || ",$expected," == *,clean,* ]] && [ "$rc" = 0 ] && { [ -z "$json" ] || [ ! -e "$json" ]; }; then
        detail="exit 0 but no JSON summary"
      elif [[ ",$expected," == *,fault,* ]] && [ "$rc" = 0 ]; then
        detail="exit 0 and no module fault"
      elif [[ ",$expected," == *,clean,* ]] && [ "$rc" = 0 ]; then
        detail="exit 0 but a module faulted"
      else
        detail="exit $rc"
      fi
      detail="$detail, expected $expected"
    elif [[ ",$expected," == *,fault,* ]] && [ -n "$json" ] && [ -f "$json" ] &&
         [ "$(jq -r '[.modules[]? | select(.name == "healthy") | .error // empty] | length' "$json")" != 0 ]; then
      class=unclear
      detail="the fault spread to the module 'healthy'"
    else
      class=ok
      local pat rest=$regex
      while :; do     # " && " separates patterns that must each match some line
        pat=${rest%% && *}
        if ! grep -a -q -E -- "$pat" "$all"; then
          class=unclear
          detail="message does not match /$pat/"
          break
        fi
        [ "$pat" = "$rest" ] && break
        rest=${rest#* && }
      done
    fi
  fi
  if [ "$class" != ok ]; then
    local first
    first=$(grep -a -v -E '^\[ *[0-9.]+ ' "$all" | grep -m1 -E '.' | cut -c1-240)
    [ -z "$first" ] && first=$(grep -a -m1 . "$all" | cut -c1-240)
    first=$(printf "%s" "$first" | LC_ALL=C tr -c "[:print:]" "?")
    detail="$detail; output: ${first:-<none>}"
  fi
  printf '%s\t%s\n' "$class" "$detail" > "$OUT/results/$id"
}

# Read the manifest.
ids=()
declare -A EXP RX CMD
while IFS= read -r line || [ -n "$line" ]; do
  [[ -z ${line// /} || $line == \#* ]] && continue
  id=${line%% | *}; rest=${line#* | }
  exp=${rest%% | *}; rest=${rest#* | }
  rx=${rest%% | *}; cmd=${rest#* | }
  [ "$rx" = "$rest" ] && cmd=""   # the command may be empty (no arguments at all)
  if [ -n "$FILTER" ] && ! [[ $id =~ $FILTER ]]; then continue; fi
  if [ -n "${EXP[$id]+x}" ]; then
    echo "run.sh: duplicate case id $id" >&2
    exit 2
  fi
  ids+=("$id"); EXP[$id]=$exp; RX[$id]=$rx; CMD[$id]=$cmd
done < "$BI/cases.txt"

declare -A KNOWN
if [ -f "$BI/known_failures.txt" ]; then
  while IFS= read -r line || [ -n "$line" ]; do
    [[ -z ${line// /} || $line == \#* ]] && continue
    KNOWN[${line%% *}]=1
  done < "$BI/known_failures.txt"
fi

start=$SECONDS
running=0
for id in "${ids[@]}"; do
  run_case "$id" "${EXP[$id]}" "${RX[$id]}" "${CMD[$id]}" 2>> "$OUT/runner.log" &
  running=$((running + 1))
  if [ $running -ge "$JOBS" ]; then
    wait -n
    running=$((running - 1))
  fi
done
wait

passed=0 failed=0 unexpected=0 stale=0
declare -A COUNT=([crash]=0 [hang]=0 [escape]=0 [unclear]=0)
for id in "${ids[@]}"; do
  IFS=$'\t' read -r class detail < "$OUT/results/$id"
  if [ "$class" = ok ]; then
    passed=$((passed + 1))
    if [ -n "${KNOWN[$id]+x}" ]; then
      echo "FIXED   $id: passes now; remove it from known_failures.txt"
      stale=$((stale + 1))
    fi
  else
    failed=$((failed + 1))
    COUNT[$class]=$((COUNT[$class] + 1))
    tag="(known)"
    if [ -z "${KNOWN[$id]+x}" ]; then tag="(NEW)"; unexpected=$((unexpected + 1)); fi
    printf '%-7s %s %s: %s\n' "${class^^}" "$tag" "$id" "$detail"
    if [ "${BI_VERBOSE:-0}" = 1 ]; then sed 's/^/    | /' "$OUT/cases/$id/output.txt" | head -20; fi
  fi
done
echo "$passed passed, $failed failed (crash ${COUNT[crash]}, hang ${COUNT[hang]}, escape ${COUNT[escape]}, unclear ${COUNT[unclear]}; $((failed - unexpected)) known, $unexpected new, $stale fixed) in $((SECONDS - start)) s"
[ $unexpected = 0 ] && [ $stale = 0 ]
