#!/usr/bin/env bash
# scripts/two_sets.sh with a stand-in bench (DRAPEGEN_BIN): each set is generated with its own options, split into
# words as the bench needs them and kept in set.args, under the protocol's options; then both sets are diagnosed and
# OUT/diagnosed marks the end. A registered test runs through it, so a slip here would cost a session's run.
#   two_sets_test.sh WORK
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
work=$(realpath -m "$1")
rm -rf "$work" && mkdir -p "$work/bin"
cat > "$work/bin/drapegen_diagnosis_bench" <<'FAKE'
#!/usr/bin/env bash
# Logs its arguments; --generate-only makes OUT/captures/x, a diagnosis OUT/diagnoses/x.json.
out=
for ((i = 1; i <= $#; ++i)); do [ "${!i}" = --out ] && { j=$((i + 1)); out=${!j}; }; done
echo "$*" >> "$out/calls.log"
case " $* " in
  *" --generate-only "*) mkdir -p "$out/captures/x" ;;
  *" --second-placement "*) mkdir -p "$out/diagnoses" && echo '{}' > "$out/diagnoses/x.json" ;;
esac
FAKE
printf '#!/usr/bin/env bash\nexit 0\n' > "$work/bin/drapegen"
chmod +x "$work/bin/drapegen_diagnosis_bench" "$work/bin/drapegen"
fail() { echo "FAIL: $*"; cat "$work"/out/*.log "$work"/out/*/calls.log 2>/dev/null; exit 1; }

DRAPEGEN_BIN="$work/bin" bash "$here/../two_sets.sh" "$work/out" s1 "--families yield curl --per-family 3 \
  --controls 0 --seed 1" s2 "--families shear --per-family 2 --controls 12 --seed 2" > "$work/run.log" 2>&1 ||
  fail "two_sets.sh failed: $(cat "$work/run.log")"

[ -f "$work/out/diagnosed" ] || fail "no OUT/diagnosed"
printf '%s\n' --families yield curl --per-family 3 --controls 0 --seed 1 | diff - "$work/out/s1/set.args" ||
  fail "s1's set.args"
printf '%s\n' --families shear --per-family 2 --controls 12 --seed 2 | diff - "$work/out/s2/set.args" ||
  fail "s2's set.args"
for s in s1 s2; do
  [ -f "$work/out/$s/generated" ] || fail "$s not marked generated"
  [ -x "$work/out/$s/bin/drapegen_diagnosis_bench" ] || fail "$s has no bench of its own"
  [ -s "$work/out/$s/bin/COMMIT" ] || fail "$s has no commit"
  grep -q -- "--generate-only" "$work/out/$s/calls.log" || fail "$s was not generated"
  grep -q -- "--placements 3 --turn-over --visible-only 20" "$work/out/$s/calls.log" || fail "$s without the protocol"
  grep -q -- "--second-placement --jobs 1 --diagnose-args --fine --ignore-measured-bending" "$work/out/$s/calls.log" ||
    fail "$s was not diagnosed"
  [ -f "$work/out/$s/diagnoses/x.json" ] || fail "$s has no report"
done
grep -q -- "--seed 1" "$work/out/s1/calls.log" && ! grep -q -- "--seed 2" "$work/out/s1/calls.log" ||
  fail "s1 ran with another set's options"

# Resumed: the same options go through; other options for an existing set are refused.
DRAPEGEN_BIN="$work/bin" bash "$here/../two_sets.sh" "$work/out" s1 "--families yield curl --per-family 3 \
  --controls 0 --seed 1" s2 "--families shear --per-family 2 --controls 12 --seed 2" > "$work/rerun.log" 2>&1 ||
  fail "a resumed run failed: $(cat "$work/rerun.log")"
if DRAPEGEN_BIN="$work/bin" bash "$here/../two_sets.sh" "$work/out" s1 "--families yield --seed 9" s2 \
  "--families shear --per-family 2 --controls 12 --seed 2" > "$work/changed.log" 2>&1; then
  fail "a set's options changed and two_sets.sh went on"
fi
grep -q "a generation failed" "$work/changed.log" || fail "no clear error: $(cat "$work/changed.log")"
grep -q "was generated with" "$work/out/generate-s1.log" || fail "generate's reason not logged"

# Wrong use: the usage, exit 2.
set +e
bash "$here/../two_sets.sh" "$work/out" s1 > /dev/null 2>&1
[ $? -eq 2 ] || fail "wrong arguments did not exit 2"
echo "ok: two sets generated with their own options, diagnosed, marked; resumed; changed options refused"
