#!/usr/bin/env bash
# Runs inside the kernel guest (tests/kernel/run.sh writes the call): each test suite of the kernel_tests binary
# as a process of its own under a time limit, so that a suite stuck in the kernel or in a driver fails alone and
# says where its threads wait (their kernel stacks, the kernel's list of blocked tasks), and the suites after it
# still run, instead of the whole guest timing out with nothing said; a suite stopped so runs once more (twice
# stopped fails). One JUnit file per suite in $W.
# Usage: guest_suites.sh KERNEL_TESTS_BINARY GTEST_FILTER SUITE_LIMIT_S    Exit code: 0 when every suite passed.
binary=$1 filter=$2 limit=$3
uptime_s() { cut -d. -f1 /proc/uptime; }
# The processes whose parent is $1 (procps may be missing from the guest's root).
children() { for st in /proc/[0-9]*/stat; do awk -v p="$1" '$4 == p {print $1}' "$st" 2>/dev/null; done; }

listing=$("$binary" --gtest_filter="$filter" --gtest_list_tests) || { echo "[guest] cannot list the tests"; exit 1; }
# gtest's listing: "Suite." at the line's start, then "  Test" lines (parameterised ones with a comment after).
suites=$(printf '%s\n' "$listing" | awk '/^[^ ]/ && $1 ~ /\.$/ {print substr($1, 1, length($1) - 1)}')
# Runs one suite under its time limit; exit code the suite's, 124 when it had to be stopped.
run_suite() {
  local suite=$1 tests=$2 limit=$3 start pid kids t k
  start=$(uptime_s)
  "$binary" --gtest_filter="$tests" --gtest_color=no --gtest_output=xml:"$W/kernel_tests_$suite.xml" &
  pid=$!
  while kill -0 "$pid" 2>/dev/null; do
    if [ $(( $(uptime_s) - start )) -ge "$limit" ]; then
      echo "[guest] suite $suite still running after $limit s; where its threads wait:"
      for t in /proc/"$pid"/task/*; do
        echo "--- thread ${t##*/} ($(cat "$t/comm")), state $(awk '/^State/ {print $2}' "$t/status"), wchan $(cat "$t/wchan")"
        cat "$t/stack" 2>/dev/null
      done
      kids=$(children "$pid")
      for k in $kids; do echo "--- child $k ($(cat /proc/"$k"/comm 2>/dev/null)): $(tr '\0' ' ' < /proc/"$k"/cmdline 2>/dev/null)"; done
      echo w > /proc/sysrq-trigger
      echo "--- the kernel's log (blocked tasks last):"; dmesg | tail -n 100
      kill -9 "$pid" $kids 2>/dev/null
      wait "$pid" 2>/dev/null
      echo "[guest] suite $suite: stopped after $(( $(uptime_s) - start )) s"
      return 124
    fi
    sleep 1
  done
  wait "$pid"; local src=$?
  echo "[guest] suite $suite: exit code $src after $(( $(uptime_s) - start )) s"
  return "$src"
}

rc=0
for suite in $suites; do
  tests=$(printf '%s\n' "$listing" |
    awk -v s="$suite." '/^[^ ]/ {cur = $1} /^  / && cur == s {printf "%s%s%s", sep, s, $1; sep = ":"}')
  # The Daemon suite starts the whole booth in the guest twice (50-130 s under TCG): it gets twice the time.
  slimit=$limit
  [ "$suite" = Daemon ] && slimit=$(( 2 * limit ))
  run_suite "$suite" "$tests" "$slimit"; src=$?
  # A suite that had to be stopped (not one that failed) runs once more, so that a rare stall of the emulated
  # machine is told apart from a hang: twice stopped fails, and either way the log above says where it waited.
  if [ "$src" -eq 124 ]; then
    echo "[guest] suite $suite: running it once more after the stop"
    run_suite "$suite" "$tests" "$slimit"; src=$?
  fi
  [ "$src" -eq 0 ] || rc=1
done
exit "$rc"
