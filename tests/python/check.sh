#!/usr/bin/env bash
# Checks that a recording made by `situ run` reads with the `mcap` package
# from PyPI (and `zstandard`, for the zstd chunks), with the schemas
# Foxglove's panels need, every message valid against its channel's JSON
# schema (`jsonschema`). Fails loudly when the packages cannot be installed.
#
#   bash tests/python/check.sh [SITU_BINARY]     (default: target/release/situ, else target/debug/situ)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
situ="${1:-}"
if [[ -z "$situ" ]]; then
  if [[ -x "$root/target/release/situ" ]]; then situ="$root/target/release/situ"; else situ="$root/target/debug/situ"; fi
fi
if [[ ! -x "$situ" ]]; then
  echo "check.sh: no situ binary at $situ (cargo build first)" >&2
  exit 1
fi
python="${PYTHON:-python3}"
venv="${TMPDIR:-/tmp}/situ-mcap-venv"
if [[ ! -x "$venv/bin/python" ]]; then
  "$python" -m venv "$venv" || { echo "check.sh: FAILED to create a Python venv" >&2; exit 1; }
fi
if ! "$venv/bin/python" -m pip install --quiet --disable-pip-version-check mcap zstandard jsonschema; then
  echo "check.sh: FAILED to install the mcap, zstandard and jsonschema packages from PyPI" >&2
  exit 1
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$root"
"$situ" run rules/outdoor.situ --record "$work/run.mcap" > "$work/run.txt"
"$venv/bin/python" "$here/read_mcap.py" "$work/run.mcap"

# A scripted run of a robot of its own (every agent a stand-in): the same
# reader, the states of the script and every agent's modes.
"$situ" run examples/mower/mower.situ --script "a day on the lawn" --record "$work/mower.mcap" > "$work/mower.txt"
"$venv/bin/python" "$here/read_mcap.py" "$work/mower.mcap" --stand-ins | tee "$work/mower-read.txt"
grep -q "states: RAIN_PAUSE -> MOWING -> STUCK -> MOWING -> DOCKING -> CHARGING -> MOWING -> FAULT" "$work/mower-read.txt" \
  || { echo "check.sh: FAILED: the mower's recording does not hold the script's states" >&2; exit 1; }

# A run killed with SIGKILL mid-recording: every flush left a valid file,
# so the standard reader (make_reader) reads everything up to the kill.
"$situ" run examples/fig5/fig5.situ --stack demo --duration 120 --record "$work/killed.mcap" > /dev/null 2>&1 &
pid=$!
grown=0; last=0
for _ in $(seq 1 600); do   # at most 60 s
  sleep 0.1
  size=$(stat -c %s "$work/killed.mcap" 2>/dev/null || echo 0)
  if (( size > last )); then grown=$((grown + 1)); last=$size; fi
  (( grown >= 3 )) && break
done
kill -9 "$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
(( grown >= 3 )) || { echo "check.sh: FAILED: the killed run's recording did not grow" >&2; exit 1; }
"$venv/bin/python" "$here/read_killed.py" "$work/killed.mcap" \
  || { echo "check.sh: FAILED: the recording of a killed run does not read with make_reader" >&2; exit 1; }
