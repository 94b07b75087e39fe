#!/usr/bin/env bash
# How a diagnosis's time drops when its drapes run on N workers (issue 6, acceptance 3; docs/BENCHMARKS.md):
# the same diagnosis of one capture (with its second and held-out placements when CAPTURE.p1 and CAPTURE.p2 exist)
# in this process with --jobs 1, then for each N given on N threads of this process (N > 1) and on a fleet of N local
# `drapegen worker` processes, with --jobs N. Prints the wall time of each (report.json runtime), its ratio to --jobs 1, the verdict, and whether the
# report is --jobs 1's but for its seconds. Workers on this machine share its cores with the diagnosing process:
# more workers than cores measure contention, not the fleet.
#
#   bench/diagnosis_fleet.sh build/bin/drapegen out/s37a/captures/curl_00 1 2 [-- EXTRA DIAGNOSE ARGS]
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: diagnosis_fleet.sh DRAPEGEN CAPTURE N [N ...] [-- DIAGNOSE-ARGS]" >&2
  exit 1
fi
DRAPEGEN=$(readlink -f "$1")
CAPTURE=$(readlink -f "$2")
shift 2
counts=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do counts+=("$1"); shift; done
[ $# -gt 0 ] && shift
extra=("$@")
[ ${#extra[@]} -gt 0 ] || extra=(--fine --ignore-measured-bending)
args=(--capture "$CAPTURE" --json -q "${extra[@]}")
[ -d "$CAPTURE.p1" ] && args+=(--second-capture "$CAPTURE.p1")
[ -d "$CAPTURE.p2" ] && args+=(--held-out-capture "$CAPTURE.p2")
work=$(mktemp -d "${TMPDIR:-/tmp}/drapegen-fleet-bench.XXXXXX")
trap 'rm -rf "$work"' EXIT

# seconds, verdict of a report
summary() { python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print(r["runtime"]["seconds"], r["verdict"])' "$1"; }
# the report without its seconds and the main thread's share of the simulations
stable() { grep -Ev 'seconds"|simulations_main_thread' "$1"; }

"$DRAPEGEN" diagnose "${args[@]}" --jobs 1 > "$work/local.json"
read -r base verdict < <(summary "$work/local.json")
printf '%-22s %8s %7s  %s\n' "run" "seconds" "ratio" "verdict"
printf '%-22s %8.1f %7.2f  %s\n' "here, --jobs 1" "$base" 1 "$verdict"
for n in "${counts[@]}"; do
  if [ "$n" -gt 1 ]; then  # the same N on threads of this process, for comparison
    "$DRAPEGEN" diagnose "${args[@]}" --jobs "$n" > "$work/here-$n.json"
    read -r seconds verdict < <(summary "$work/here-$n.json")
    printf '%-22s %8.1f %7.2f  %s\n' "here, --jobs $n" "$seconds" "$(python3 -c "print($seconds / $base)")" "$verdict"
  fi
  endpoint="ipc://$work/fleet-$n.ipc"
  pids=()
  trap 'kill "${pids[@]}" 2> /dev/null; rm -rf "$work"' EXIT
  for _ in $(seq 1 "$n"); do
    "$DRAPEGEN" worker --connect "$endpoint" --give-up 120 --log-level warn &
    pids+=($!)
  done
  "$DRAPEGEN" diagnose "${args[@]}" --jobs "$n" --fleet "$endpoint" --fleet-workers "$n" > "$work/fleet-$n.json"
  wait "${pids[@]}"
  read -r seconds verdict < <(summary "$work/fleet-$n.json")
  same=$(cmp -s <(stable "$work/local.json") <(stable "$work/fleet-$n.json") && echo "same report" || echo "REPORT DIFFERS")
  printf '%-22s %8.1f %7.2f  %s (%s)\n' "$n worker(s), --jobs $n" "$seconds" "$(python3 -c "print($seconds / $base)")" \
    "$verdict" "$same"
done
