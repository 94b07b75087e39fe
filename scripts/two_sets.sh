#!/usr/bin/env bash
# A registered test's two diagnosis sets (docs/preregistrations/), end to end: each set generated on a core of its
# own (scripts/diagnosis_set.sh generate, with this checkout's build/bin), then both diagnosed two at a time
# (scripts/diagnosis_set.sh diagnose --lanes 2); OUT/diagnosed marks the end, OUT's logs hold the progress.
# Resumable: run it again after a stop and the bench keeps every finished capture and diagnosis.
#
#   scripts/two_sets.sh OUT NAME1 "BENCH-OPTIONS1" NAME2 "BENCH-OPTIONS2"
#   scripts/two_sets.sh out/p91 s123 "--families yield curl --per-family 3 --controls 0 --seed 123" \
#       s124 "--families shear --per-family 3 --controls 12 --seed 124"
#
# Then `scripts/diagnosis_set.sh score OUT/NAME1 OUT/NAME2` (each set's summary, the rules' tables, the camera
# reading, scripts/score_test.py's per-capture table).
set -euo pipefail
[ $# -eq 5 ] || { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0" >&2; exit 2; }
out=$(realpath -m "$1")
cd "$(dirname "$0")/.."
mkdir -p "$out"
read -r -a first <<< "$3"
read -r -a second <<< "$5"
taskset -c 0 scripts/diagnosis_set.sh generate "$out/$2" "${first[@]}" > "$out/generate-$2.log" 2>&1 &
g1=$!
taskset -c "$(( 1 % $(nproc) ))" scripts/diagnosis_set.sh generate "$out/$4" "${second[@]}" \
  > "$out/generate-$4.log" 2>&1 &
g2=$!
status=0
wait $g1 || status=$?
wait $g2 || status=$?
[ $status -eq 0 ] || { echo "two_sets: a generation failed (see $out/generate-*.log)" >&2; exit $status; }
scripts/diagnosis_set.sh diagnose "$out/$2" "$out/$4" --lanes 2 > "$out/diagnose.log" 2>&1
date -u +%FT%TZ > "$out/diagnosed"
echo "two_sets: $out diagnosed"
