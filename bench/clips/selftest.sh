#!/usr/bin/env bash
# Runs every tests/*.events through run.sh and compares the states it writes
# with tests/*.states (the expected sequence, written by hand from
# docs/language.md 10 and bench/README.md). Exits non-zero on any difference.
set -uo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

passed=0
failed=0
for events in "$here"/tests/*.events; do
    name="$(basename "$events" .events)"
    expected="$here/tests/$name.states"
    if [ ! -f "$expected" ]; then
        echo "FAIL $name: no $expected" >&2
        failed=$((failed + 1))
        continue
    fi
    if ! "$here/run.sh" "$events" "$work/$name.states" >"$work/$name.json" 2>"$work/$name.err"; then
        echo "FAIL $name: run.sh failed:" >&2
        cat "$work/$name.err" >&2
        failed=$((failed + 1))
    elif ! diff -u "$expected" "$work/$name.states" >"$work/$name.diff"; then
        echo "FAIL $name: states differ (- expected, + clips):" >&2
        cat "$work/$name.diff" >&2
        failed=$((failed + 1))
    else
        echo "ok   $name"
        passed=$((passed + 1))
    fi
done

if [ $((passed + failed)) -eq 0 ]; then
    echo "no tests found in $here/tests" >&2
    exit 1
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
