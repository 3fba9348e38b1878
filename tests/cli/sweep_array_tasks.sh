#!/usr/bin/env bash
# The tasks of a Slurm job array share one output and run at once: here without Slurm, six
# `rm3d sweep --array-task N` processes of 3 runs each start a few milliseconds apart on one
# output, 60 times over. Every task must run all its runs: a task that finished used to take away
# the shared folder of the runs' logs while another was between two runs, whose next run then
# could not start ("cannot start", exit 2; 18 of 900 tasks, 4 of 180, in two measurements).
# Usage: sweep_array_tasks.sh RM3D SRC OUT
set -u
rm3d=$1 src=$2 out=$3
rm -rf "$out" && mkdir -p "$out"
cd "$src" || exit 1
failed=0
for round in $(seq 1 60); do
  dir="$out/round_$round"
  mkdir -p "$dir"
  for task in 0 1 2 3 4 5; do
    (
      sleep "0.0$((RANDOM % 10))"
      "$rm3d" sweep tests/cli/sweep/world.lua --param amp=0.2,0.5,0.8,1.1 --seeds 1-5 --out "$dir/runs.jsonl" \
        --runs-per-task 3 --array-task "$task" > "$dir/task_$task.log" 2>&1
      echo $? > "$dir/task_$task.code"
    ) &
  done
  wait
  for task in 0 1 2 3 4 5; do
    code=$(cat "$dir/task_$task.code")
    if [ "$code" != 0 ]; then
      echo "FAIL: round $round, array task $task exited $code:"
      tail -3 "$dir/task_$task.log"
      failed=$((failed + 1))
    fi
  done
  lines=$(grep -c . "$dir/runs.jsonl")
  if [ "$lines" != 18 ]; then
    echo "FAIL: round $round: $lines runs in the output, expected 18"
    failed=$((failed + 1))
  fi
  if [ -e "$dir/runs.jsonl.runs" ]; then
    echo "FAIL: round $round: the runs' folder $dir/runs.jsonl.runs was left behind"
    failed=$((failed + 1))
  fi
  rm -rf "$dir"
done
if [ "$failed" != 0 ]; then
  echo "$failed failures"
  exit 1
fi
echo "60 rounds of 6 array tasks at once: every run done, nothing left behind"
