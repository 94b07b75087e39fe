#!/usr/bin/env bash
# Interleaved A/B timing of two builds of drapegen_drape_bench on the benchmark's 15 drapes (5 fabrics x flat, sine,
# fold at 100x100): each drape runs under build A, then at once under build B, pinned to one core, so that the
# host's drift (10% within an hour on the development machine) falls on both alike. Prints per drape the iterations
# and CPU seconds of both and their ratio, then the medians and the median ratios (whole drape, and per iteration for
# drapes whose paths differ).
#
#   scripts/drape_ab.sh OLD/drapegen_drape_bench NEW/drapegen_drape_bench [ROUNDS=1] [CORE=1]
set -euo pipefail
if [[ $# -lt 2 || $1 == -h || $1 == --help ]]; then
  sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
a=$1 b=$2 rounds=${3:-1} core=${4:-1}
for exe in "$a" "$b"; do [[ -x $exe ]] || { echo "drape_ab: not an executable: $exe" >&2; exit 2; }; done
run() {  # bench quantile init -> "iterations cpu_seconds"
  taskset -c "$core" "$1" --resolution 100 --fabrics 5 --only "$2" --inits "$3" 2>&1 | grep '^fabric' |
    sed -E 's/.*: [a-z_]+ +([0-9]+) it .* CPU +([0-9.]+) s.*/\1 \2/'
}
for ((r = 1; r <= rounds; ++r)); do
  for q in 0 1 2 3 4; do
    for init in flat sine fold; do
      echo "$q $init $(run "$a" "$q" "$init") $(run "$b" "$q" "$init")"
    done
  done
done | awk '
  function median(v, n,   i, j, t) {
    for (i = 2; i <= n; ++i) { t = v[i]; for (j = i - 1; j >= 1 && v[j] > t; --j) v[j + 1] = v[j]; v[j + 1] = t }
    return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
  }
  { ++n; sa[n] = $4; sb[n] = $6; r[n] = $6 / $4; ri[n] = ($6 / $5) / ($4 / $3)
    printf "fabric %d %-4s  A %4d it %6.2f s  B %4d it %6.2f s  B/A %.3f  per iteration %.3f\n", $1, $2, $3, $4, $5, $6, r[n], ri[n] }
  END {
    printf "%d drapes: median A %.2f s, B %.2f s; median ratio B/A %.3f, per iteration %.3f\n", n, median(sa, n),
           median(sb, n), median(r, n), median(ri, n)
  }'
