#!/usr/bin/env bash
# One fresh diagnosis set under the protocol of sessions 59-70 (docs/DIAGNOSIS_RESULTS.md): three placements of each
# specimen, turned over between them, every effect draw screened for visibility (at most 20 draws), diagnosed with
# `drapegen diagnose --fine --ignore-measured-bending` and the second and held-out placements. Three steps, each
# resumable (the bench keeps what exists):
#
#   scripts/diagnosis_set.sh generate OUT BENCH-OPTIONS...  # copies build/bin's programs into OUT/bin (the build the
#                                                            # set is diagnosed with, commit in OUT/bin/COMMIT), keeps
#                                                            # the options in OUT/set.args, generates, marks
#                                                            # OUT/generated
#   scripts/diagnosis_set.sh diagnose OUT... [--lanes N] [--first-core K]
#                                                            # N diagnoses at once (default: the cores), one core
#                                                            # each (K, K+1, ...; default 0), sharing the sets'
#                                                            # cases (the bench's case locks: sets generated since
#                                                            # session 70; lanes may join a running diagnose)
#   scripts/diagnosis_set.sh arm ARM BASE OPTIONS...         # ARM: an arm of the generated set BASE (its build,
#                                                            # captures, truth and screen linked), diagnosed with
#                                                            # these diagnose options added (kept in ARM/arm.args;
#                                                            # none: scripts/first_mesh.py's default arm); then
#                                                            # `diagnose ARM` and `scripts/compare_arms.py`
#   scripts/diagnosis_set.sh score OUT...                    # each set's summary, the verdict and region tables,
#                                                            # the camera reading, then scripts/score_test.py's
#                                                            # per-capture table and summary
#
# DRAPEGEN_BIN (default build/bin) is where generate takes the programs from.
#
# BENCH-OPTIONS choose the captures (drapegen_diagnosis_bench --help): e.g.
#   scripts/diagnosis_set.sh generate out/p72/s80 --families sensor --per-family 6 --controls 3 --seed 80 \
#       --sensor-kinds pose bias
set -euo pipefail
cd "$(dirname "$0")/.."
usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0" >&2; exit 2; }
[ $# -ge 2 ] || usage
step=$1 out=$2
shift 2
protocol=(--placements 3 --turn-over --visible-only 20 --fabrics sampler/data/fabrics618.csv)

set_args() {  # the set's own options, one per line in OUT/set.args
  [ -f "$1/set.args" ] || { echo "diagnosis_set: $1/set.args is missing (run the generate step first)" >&2; exit 1; }
  mapfile -t args < "$1/set.args"
}
runner=()  # a prefix for the bench (a lane's taskset)
bench() {  # bench SET MORE-OPTIONS...: the set's own bench on the set, under the protocol and the set's options
  set_args "$1"
  "${runner[@]}" "$1/bin/drapegen_diagnosis_bench" --out "$1" "${protocol[@]}" "${args[@]}" "${@:2}"
}

case $step in
  generate)
    [ $# -gt 0 ] || usage
    build=${DRAPEGEN_BIN:-build/bin}  # the programs a set is made with (tests point it at stand-ins)
    for p in drapegen drapegen_diagnosis_bench; do
      [ -x "$build/$p" ] || { echo "diagnosis_set: $build/$p is missing (scripts/build.sh)" >&2; exit 1; }
    done
    mkdir -p "$out/bin"
    if [ -f "$out/set.args" ]; then  # a resumed generation keeps its build and options
      set_args "$out"
      [ "${args[*]}" = "$*" ] || { echo "diagnosis_set: $out was generated with: ${args[*]}" >&2; exit 1; }
    else
      cp "$build/drapegen" "$build/drapegen_diagnosis_bench" "$out/bin/"
      { git rev-parse HEAD; git status --porcelain --untracked-files=no | sed 's/^/dirty: /'; } > "$out/bin/COMMIT"
      printf '%s\n' "$@" > "$out/set.args"
      set_args "$out"
    fi
    bench "$out" --generate-only
    date -u +%FT%TZ > "$out/generated"
    ;;
  diagnose)
    sets=("$out") lanes=$(nproc) first=0
    while [ $# -gt 0 ]; do
      case $1 in
        --lanes) lanes=$2; shift 2 ;;
        --first-core) first=$2; shift 2 ;;
        *) sets+=("$1"); shift ;;
      esac
    done
    for s in "${sets[@]}"; do
      [ -f "$s/generated" ] || { echo "diagnosis_set: $s is not generated yet ($s/generated)" >&2; exit 1; }
    done
    lane() {  # lane K: every set in turn, one diagnosis at a time on core K; the bench's case locks share the work
      runner=(taskset -c "$(( ($first + $1) % $(nproc) ))")
      for s in "${sets[@]}"; do
        extra=$(cat "$s/arm.args" 2>/dev/null || true)
        bench "$s" --second-placement --jobs 1 --diagnose-args "--fine --ignore-measured-bending${extra:+ $extra}" \
          | sed "s/^/lane $1: /"
      done
    }
    for ((k = 0; k < lanes; ++k)); do lane "$k" & done
    wait
    ;;
  arm)
    [ $# -ge 1 ] || usage
    base=$1
    shift
    [ -f "$base/generated" ] || { echo "diagnosis_set: $base is not generated yet ($base/generated)" >&2; exit 1; }
    [ ! -e "$out" ] || { echo "diagnosis_set: $out exists" >&2; exit 1; }
    mkdir -p "$out"
    for f in bin captures truth screen set.args generated; do
      if [ -e "$base/$f" ]; then ln -s "$(realpath "$base/$f")" "$out/$f"; fi
    done
    echo "$*" > "$out/arm.args"
    ;;
  score)
    runs=("$out" "$@")
    for run in "${runs[@]}"; do
      set_args "$run"
      echo "== $run: ${args[*]}"
      bench "$run" --second-placement --score-only
    done
    python3 scripts/diagnosis_rules.py --matrix current --pooled "${runs[@]}"
    python3 scripts/region_rules.py "${runs[@]}"
    python3 scripts/view_rms.py "${runs[@]}"
    python3 scripts/score_test.py "${runs[@]}"
    ;;
  *) usage ;;
esac
