#!/bin/sh
# Every scene in scenes/ under SUNDIALS IDA at each relative tolerance (absolute tolerance the
# same, times each dof's scale), to a short end time: the exit code, IDA's steps and the wall
# time per run, as a table. A run that takes longer than the limit counts as "timeout".
# Usage (after building): sh tools/ida-tolerance-sweep.sh [T_END] [LIMIT_SECONDS] [RTOLS...]
set -u
t_end=${1:-0.05}
limit=${2:-120}
[ $# -gt 2 ] && shift 2 || set --
rtols=${*:-1e-3 1e-6 1e-9 1e-12}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '%-34s' scene
for r in $rtols; do printf ' %18s' "rtol $r"; done
printf '\n'
for scene in scenes/*.xml scenes/urdf/*.urdf; do
  printf '%-34s' "$(basename "$scene")"
  for r in $rtols; do
    start=$(date +%s%N)
    timeout "$limit" build/bin/metriplex run "$scene" --integrator ida --rtol "$r" --t-end "$t_end" \
      --out "$out/run" > "$out/log" 2>&1
    code=$?
    wall=$(( ($(date +%s%N) - start) / 1000000 ))
    steps=$(sed -n 's/^  IDA *\([0-9]*\) steps.*/\1/p' "$out/log")
    case $code in
      0) cell="${steps:-?} st ${wall} ms" ;;
      124) cell="timeout" ;;
      2) cell="refused (2)" ;;
      *) cell="failed ($code)" ;;
    esac
    printf ' %18s' "$cell"
    rm -rf "$out/run"
  done
  printf '\n'
done
