#!/usr/bin/env bash
# Builds the libFuzzer targets (clang-14, -fsanitize=fuzzer,address,undefined; CMake option AVATARBOOTH_FUZZ, a
# build of its own) and runs each for a bounded time on a copy of its seed corpus (tests/fuzz/corpus/<target>/).
# Prints one line of figures per target; exits 1 on any crash or sanitizer report (the reproducer is kept under
# <build-dir>/artifacts/<target>/), 77 when clang-14 or libFuzzer is not installed.
#
# Usage: tests/fuzz/run.sh [--seconds N] [--build-dir DIR] [--target NAME]...   (default: 60 s each, build/fuzz)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
seconds=60
build="$root/build/fuzz"
targets=()
while (($#)); do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --build-dir) build="$2"; shift 2 ;;
    --target) targets+=("$2"); shift 2 ;;
    *) echo "usage: $0 [--seconds N] [--build-dir DIR] [--target NAME]..." >&2; exit 2 ;;
  esac
done
((${#targets[@]})) || targets=(fuzz_photo fuzz_session_folder fuzz_config fuzz_manifest fuzz_share_request)

if ! command -v clang++-14 >/dev/null || [ ! -e /usr/lib/llvm-14/lib/clang/14.0.6/lib/linux/libclang_rt.fuzzer-x86_64.a ] &&
   ! ls /usr/lib/llvm-14/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  echo "fuzz: skipped: clang-14 and libclang-rt-14-dev (libFuzzer) are needed (tests/setup.sh installs them)"
  exit 77
fi

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
start=$(date +%s)
cmake -S "$root" -B "$build" -DAVATARBOOTH_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_CXX_COMPILER=clang++-14 "${launcher[@]}" >"$build.configure.log" 2>&1 ||
  { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j "$(nproc)" --target "${targets[@]}" >"$build.build.log" 2>&1 ||
  { tail -50 "$build.build.log"; exit 1; }
echo "fuzz: built ${#targets[@]} targets in $(( $(date +%s) - start )) s"

# ASan: no leak check (it needs ptrace, missing in some containers; leaks are the soak test's job); UBSan: every
# report is fatal.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:allocator_may_return_null=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
failed=0
for t in "${targets[@]}"; do
  name="${t#fuzz_}"
  seeds="$root/tests/fuzz/corpus/$name"
  work="$build/corpus/$name"         # new inputs go here, never into the repository
  artifacts="$build/artifacts/$name/"
  rm -rf "$artifacts"
  mkdir -p "$work" "$artifacts"
  log="$build/$t.log"
  set +e
  "$build/tests/fuzz/$t" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$artifacts" "$work" "$seeds" >"$log" 2>&1
  rc=$?
  set -e
  runs=$(grep -oE '^stat::number_of_executed_units: *[0-9]+' "$log" | grep -oE '[0-9]+$' || echo 0)
  speed=$(grep -oE '^stat::average_exec_per_sec: *[0-9]+' "$log" | grep -oE '[0-9]+$' || echo 0)
  cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -1 | grep -oE '[0-9]+' || echo 0)
  corpus=$(find "$work" -type f | wc -l)
  crashes=$(find "$artifacts" -type f | wc -l)
  reports=$(grep -cE 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error:' "$log" || true)
  printf 'fuzz: %-20s %ss  runs %-8s exec/s %-6s coverage %-5s corpus %-5s crashes %s  sanitizer reports %s\n' \
         "$t" "$seconds" "$runs" "$speed" "$cov" "$corpus" "$crashes" "$reports"
  if ((rc != 0 || crashes != 0 || reports != 0)); then
    failed=1
    echo "fuzz: $t FAILED (exit $rc); reproducer(s): $(find "$artifacts" -type f | tr '\n' ' ')"
    grep -E -A25 'ERROR:|runtime error:|deadly signal|uncaught|terminate' "$log" | head -60
  fi
done
exit $failed
