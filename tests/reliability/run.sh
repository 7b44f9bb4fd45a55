#!/usr/bin/env bash
# The reliability suite, with every figure printed at the end so runs can be compared:
#   soak      the simulated booth serves random visitors (in one process): sessions, crashes, RSS drift, fds, threads
#   faults    camera unplugged mid-preview / mid-capture, torn and late frames, disk full while writing and keeping,
#             the daemon SIGKILLed while writing and restarted (reliability_tests)
#   bad input the adversarial seed files through the normal build (reliability_tests BadInputFiles.*)
#   fuzz      the libFuzzer targets, ASan + UBSan (tests/fuzz/run.sh)
# Fast form (what CI runs through ctest, label `reliability`): a 14-session soak and 30 s per fuzz target.
# --long: a 2000-session soak (SOAK_SESSIONS to change; about 4 s per session here) and 10 minutes per fuzz target.
# Usage: tests/reliability/run.sh [--long]     (build dir: $BUILD_DIR, default build/release)
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${BUILD_DIR:-$root/build/release}"
long=0
[ "${1:-}" = "--long" ] && long=1
sessions=14; fuzz_seconds=30
((long)) && { sessions="${SOAK_SESSIONS:-2000}"; fuzz_seconds="${FUZZ_SECONDS:-600}"; }
export EGL_PLATFORM=surfaceless
out="$build/reliability"
mkdir -p "$out"

if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null || exit 1
fi
cmake --build "$build" -j "$(nproc)" --target avatarbooth reliability_soak reliability_tests \
  >"$out/build.log" 2>&1 || { tail -40 "$out/build.log"; exit 1; }

status=0
echo "== soak ($sessions sessions)"
"$build/tests/reliability/reliability_soak" --sessions "$sessions" --work "$out/soak" --samples-csv "$out/soak_samples.csv" | tee "$out/soak.txt" || status=1
echo "== faults"
"$build/tests/reliability/reliability_tests" --gtest_filter='-BadInputFiles.*' 2>&1 | tee "$out/faults.txt" | grep -E '^figure:|^\[  (PASSED|FAILED|SKIPPED) |Failure|error:' || true
grep -q '^\[  FAILED' "$out/faults.txt" && status=1
echo "== bad input files"
"$build/tests/reliability/reliability_tests" --gtest_filter='BadInputFiles.*' >"$out/bad_input.txt" 2>&1 || status=1
grep -E '^\[  (PASSED|FAILED) |Failure' "$out/bad_input.txt"
echo "== fuzz ($fuzz_seconds s per target)"
"$root/tests/fuzz/run.sh" --seconds "$fuzz_seconds" --build-dir "$root/build/fuzz" | tee "$out/fuzz.txt"
rc=${PIPESTATUS[0]}
((rc == 77)) && echo "fuzz: skipped" || { ((rc != 0)) && status=1; }

echo
echo "== reliability figures ($(date -u +%FT%TZ), $(nproc) cores, $(uname -r))"
grep -hE '^soak: ' "$out/soak.txt"
grep -hE '^figure: ' "$out/faults.txt" | sed 's/^figure: /faults: /'
grep -hE '^\[  (PASSED|FAILED) ' "$out/faults.txt" | sed 's/^/faults: /'
grep -hE '^\[  (PASSED|FAILED) ' "$out/bad_input.txt" | sed 's/^/bad input: /'
grep -hE '^fuzz: ' "$out/fuzz.txt"
echo "reliability: $([ $status = 0 ] && echo PASS || echo FAIL)"
exit $status
