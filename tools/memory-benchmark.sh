#!/bin/sh
# Resident memory over a long run: 10^6 steps of the two thermo-springs (dt 0.2 to t = 200 000)
# per integrator, the resident set size (VmRSS) sampled every second from /proc; prints the
# sample after one second, the last and the largest. Flat memory means output is streamed.
# Usage (after building): sh tools/memory-benchmark.sh [build/bin/metriplex] [integrators...]
set -eu
binary=${1:-build/bin/metriplex}
[ $# -gt 0 ] && shift
integrators=${*:-eem midpoint}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '%-12s %8s %10s %10s %10s %8s\n' integrator steps "rss0[kB]" "rss1[kB]" "max[kB]" "wall[s]"
for integrator in $integrators; do
  start=$(date +%s)
  "$binary" run scenes/two_thermo_springs.xml --integrator "$integrator" --dt 0.2 --t-end 200000 \
    --out "$out/$integrator" > "$out/$integrator.log" 2>&1 &
  pid=$!
  samples=""
  while kill -0 "$pid" 2>/dev/null; do
    rss=$(awk '/VmRSS/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
    [ -n "$rss" ] && samples="$samples $rss"
    sleep 1
  done
  wait "$pid"
  steps=$(awk '/^  steps/ {print $2}' "$out/$integrator.log")
  echo "$samples" | awk -v name="$integrator" -v steps="$steps" -v wall=$(( $(date +%s) - start )) '{
    max = 0; for (i = 1; i <= NF; ++i) if ($i > max) max = $i
    first = NF >= 3 ? $2 : $1  # the sample at t = 0 may precede the scene load
    printf "%-12s %8s %10d %10d %10d %8d\n", name, steps, first, $NF, max, wall }'
  rm -rf "${out:?}/$integrator"
done
