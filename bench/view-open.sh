#!/usr/bin/env bash
# How long `situ view` takes to open a one-hour recording: from the start
# of the command to the page's data being served (`/api/timeline` answers),
# five runs each, on recordings this script makes with the release binary.
#
#   cargo build --release && bash bench/view-open.sh
set -euo pipefail
cd "$(dirname "$0")/.."
situ=target/release/situ
[ -x "$situ" ] || { echo "build it first: cargo build --release" >&2; exit 2; }
command -v curl > /dev/null || { echo "curl is needed" >&2; exit 2; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
# A greenhouse of ours on an hour of random weather (some 30,000 changes),
# and the mower's hour of mowing at its rules' rates (few changes, many events).
"$situ" run tests/view/greenhouse.situ --random 1 --until 3600 --record "$dir/greenhouse.mcap" > /dev/null || true
"$situ" run examples/mower/mower.situ --script "an hour of mowing" --record "$dir/mower.mcap" > /dev/null || true
for rec in greenhouse mower; do
  times=()
  for _ in 1 2 3 4 5; do
    port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
    start=$(date +%s%N)
    "$situ" view "$dir/$rec.mcap" --port "$port" > /dev/null 2> "$dir/err" &
    pid=$!
    until curl -sf -o /dev/null "http://127.0.0.1:$port/api/timeline"; do
      kill -0 "$pid" 2> /dev/null || { cat "$dir/err" >&2; exit 1; }
      sleep 0.005
    done
    times+=($(( ($(date +%s%N) - start) / 1000000 )))
    kill "$pid"; wait "$pid" 2> /dev/null || true
  done
  size=$(stat -c %s "$dir/$rec.mcap")
  echo "$rec.mcap ($((size / 1024)) KiB; $(sed 's/.*: //' "$dir/err")): ${times[*]} ms"
done
