#!/usr/bin/env bash
# Two drapegen_diagnosis_bench runs diagnosing one directory at once (scripts/diagnosis_set.sh's lanes) take each case
# once: a stand-in drapegen logs every capture it is asked to diagnose and answers after a second.
#   diagnosis_shared_test.sh BENCH FABRICS WORK
set -euo pipefail
bench=$1 fabrics=$2 work=$3
rm -rf "$work" && mkdir -p "$work/captures" "$work/truth"
cat > "$work/drapegen" <<'FAKE'
#!/usr/bin/env bash
echo "$3" >> "$(dirname "$0")/asked.log"
sleep 1
echo '{"verdict": "none", "within_floors": true, "shrinkage": 0, "localisation": {"region": "skirt"},
      "gap_mm": {"all_views": 5.0}, "floors": {"all_views_mm": 6.0}, "runtime": {"seconds": 1.0}}'
FAKE
chmod +x "$work/drapegen"
cases=(yield_00 yield_01 yield_02 yield_03 yield_04 yield_05)
for c in "${cases[@]}"; do  # generated already: the bench skips generation
  mkdir -p "$work/captures/$c" && : > "$work/captures/$c/capture.json"
  echo '{"family": "yield", "regions": ["skirt"], "effects": [{"name": "yield", "strength": 1}]}' \
    > "$work/truth/$c.json"
done
run() { "$bench" --out "$work" --families yield --per-family 6 --controls 0 --fabrics "$fabrics" --jobs 2 \
          --drapegen "$work/drapegen" > "$work/run$1.log" 2>&1; }
run 1 & run 2 &
wait
fail() { echo "FAIL: $*"; cat "$work/asked.log" "$work"/run*.log; exit 1; }
asked=$(wc -l < "$work/asked.log")
[ "$asked" -eq ${#cases[@]} ] || fail "$asked diagnoses for ${#cases[@]} cases"
[ "$(sort -u "$work/asked.log" | wc -l)" -eq ${#cases[@]} ] || fail "a case was diagnosed twice"
for c in "${cases[@]}"; do [ -s "$work/diagnoses/$c.json" ] || fail "$c has no report"; done
if compgen -G "$work/diagnoses/*.lock" > /dev/null; then fail "locks left behind"; fi
# the run that ends last scores every report (the other, those there when it ended)
cat "$work"/run*.log | grep -q "top-1 correct on effect captures: 0/6" || fail "no run scored the 6 reports"
echo "ok: ${#cases[@]} cases, each diagnosed once by two runs sharing the directory"
