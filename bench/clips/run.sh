#!/usr/bin/env bash
# Usage: bench/clips/run.sh STREAM.events STATES_OUT
#
# Runs the outdoor rules (outdoor.clp) in CLIPS 6.30 over STREAM with the
# driver (driver.clp), writes the state sequence to STATES_OUT and prints the
# benchmark's JSON line (bench/README.md) on standard output:
#   {"engine":"clips","events":N,"seconds":S,"events_per_sec":R,"state_changes":C,"includes_parsing":true}
#
# `seconds` is measured inside CLIPS with (time) around the loop that reads,
# parses and processes the events (start-up and loading the rules are
# outside it). In Debian's CLIPS 6.30, (time) is the process's CPU time
# (clock()); for this single-threaded, CPU-bound loop over a cached file it
# equals the wall time on an idle machine. The wall time of the whole clips
# process and the CLIPS version go to standard error.
set -euo pipefail

if [ $# -ne 2 ]; then
    echo "usage: $0 STREAM.events STATES_OUT" >&2
    exit 2
fi

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
stream="$1"
states="$2"

if [ ! -r "$stream" ]; then
    echo "bench/clips/run.sh: error: cannot read the stream $stream" >&2
    exit 1
fi
if ! command -v clips >/dev/null 2>&1; then
    echo "bench/clips/run.sh: error: no 'clips' command: run bench/clips/install.sh" >&2
    exit 1
fi

# Absolute paths, written as CLIPS strings.
abspath() { case "$1" in /*) printf '%s' "$1" ;; *) printf '%s/%s' "$PWD" "$1" ;; esac; }
clips_string() { local s="${1//\\/\\\\}"; printf '"%s"' "${s//\"/\\\"}"; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cat >"$work/batch.clp" <<CLP
(load* $(clips_string "$here/outdoor.clp"))
(load* $(clips_string "$here/driver.clp"))
(main $(clips_string "$(abspath "$stream")") $(clips_string "$(abspath "$states")"))
(exit)
CLP

version="$(echo '(exit)' | clips 2>/dev/null | sed -n 's/^ *CLIPS (\([^)]*\)).*/\1/p' | head -n 1)"
package="$(dpkg-query -W -f='${Version}' clips 2>/dev/null || echo unknown)"
echo "clips: CLIPS ${version:-unknown} (Debian package clips ${package})" >&2

start_ns=$(date +%s%N)
status=0
clips -f2 "$work/batch.clp" </dev/null >"$work/out" 2>&1 || status=$?
end_ns=$(date +%s%N)

result="$(grep '^RESULT ' "$work/out" || true)"
other="$(grep -v '^RESULT ' "$work/out" || true)"
if [ "$status" -ne 0 ] || [ -z "$result" ] || [ -n "$other" ]; then
    echo "bench/clips/run.sh: error: clips failed (exit code $status) on $stream:" >&2
    cat "$work/out" >&2
    exit 1
fi

echo "clips: process wall time $(( (end_ns - start_ns) / 1000000 )) ms (start-up and loading included)" >&2
echo "$result" | awk '{
    events = $2; seconds = $3; changes = $4
    rate = seconds > 0 ? int(events / seconds + 0.5) : 0
    printf "{\"engine\":\"clips\",\"events\":%d,\"seconds\":%.3f,\"events_per_sec\":%d,\"state_changes\":%d,\"includes_parsing\":true}\n", events, seconds, rate, changes
}'
