#!/usr/bin/env bash
# The service under AddressSanitizer and UndefinedBehaviorSanitizer: builds `thaw` with THAW_SANITIZE
# into the folder $1, serves a small scene, runs the smoke and fuzz clients (service_clients.py) against
# it and stops it with SIGINT. Fails on any sanitizer report, on a failed check, or on an unclean exit.
#
# Leak checking is off: at exit LeakSanitizer reports 112 bytes (two 56-byte callocs) in code it cannot
# attribute to any loaded file, i.e. JIT-compiled code of the OpenCL or GL driver; suppressions match
# library names, which these frames do not have.
set -euo pipefail

src="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
out="$1"
cmake -S "$src" -B "$out" -DCMAKE_BUILD_TYPE=Debug -DTHAW_SANITIZE=ON -DTHAW_BUILD_TESTS=OFF >/dev/null
cmake --build "$out" -j2 --target thaw >/dev/null

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
# use_sigaltstack=0: with it on, AddressSanitizer's runtime (GCC 12's) failed its own CHECK "unable to
# unmap" while unmapping a thread's alternate signal stack at thread exit, on every run on a fresh
# machine; thaw installs no signal stacks of its own, so nothing of ours is hidden by turning it off.
export ASAN_OPTIONS=detect_leaks=0:halt_on_error=1:use_sigaltstack=0 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
# The sanitizers' own failures are told apart from findings in our code, wherever the run stops (a
# server the sanitizer stopped fails the clients' checks too, or never prints its port): either fails
# the test, but the line printed says which.
sanitizer_verdict() {
  if grep -q "CHECK failed" serve.log; then
    echo "FAIL: the sanitizer runtime itself failed (not a finding in thaw's code):"
    grep "CHECK failed" serve.log
    exit 1
  fi
  if grep -q "ERROR: AddressSanitizer\|runtime error:" serve.log; then
    echo "FAIL: a sanitizer finding in thaw:"
    grep -A3 "ERROR: AddressSanitizer\|runtime error:" serve.log
    exit 1
  fi
}

timeout 400 "$out/thaw" serve ice-on-plate --set spacing=0.006 --port 0 --state-dir states \
  --state-out final.state >serve.log 2>&1 &
server=$!
port=""
for _ in $(seq 1200); do
  port="$(grep -o '127.0.0.1:[0-9]*' serve.log | head -1 | cut -d: -f2 || true)"
  [ -n "$port" ] && break
  kill -0 "$server" 2>/dev/null || break  # it stopped before serving
  sleep 0.1
done
if [ -z "$port" ]; then
  cat serve.log
  sanitizer_verdict
  exit 1
fi

timeout 300 /usr/bin/python3 "$src/tests/server/service_clients.py" "$port" smoke fuzz | tee clients.log
kill -INT "$server"
status=0
wait "$server" || status=$?
cat serve.log
sanitizer_verdict
for check in "frame True" "refused bad_field" "replies True" "still stepping True" "still checking bad_field"; do
  grep -q "$check" clients.log || { echo "missing: $check"; exit 1; }
done
[ -f final.state ] || { echo "no --state-out"; exit 1; }
exit "$status"
