#!/usr/bin/env bash
# situ against CLIPS 6.30 and a hand-written matcher on the same seeded
# stream of events over rules/outdoor.situ (bench/README.md).
#
#   bash bench/vs-clips.sh                    # 1,000,000 events, seed 1
#   EVENTS=100000 SEED=7 bash bench/vs-clips.sh
#   PROFILE=debug EVENTS=200000 bash bench/vs-clips.sh   # scripts/test.sh
#
# 1. builds `situ` and `situ-handwritten` in release (with PROFILE=debug,
#    the test build's: the agreement is checked, the speeds mean nothing)
#    and installs CLIPS from Debian's package `clips` if it is missing;
# 2. `situ bench` generates the stream (written to a file) and runs on it;
#    CLIPS and the hand-written matcher read that file;
# 3. the three state sequences must be equal, else it stops with exit 1
#    and the first difference (the speeds of engines that disagree mean
#    nothing);
# 4. prints one line per engine, then `situ/clips ratio: X` and
#    `handwritten/situ ratio: Y`.
#
# In release, also situ's native code of the rules (`situ build --native`,
# `runtime-tests/native/outdoor.rs`, linked by the example `instructions`
# of situ-runtime: the same loop as `situ bench`'s, the module's `step`
# inlined), on the same file, its states compared too: `situ native` and
# `handwritten/situ-native ratio`.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
events="${EVENTS:-1000000}"
seed="${SEED:-1}"
profile="${PROFILE:-release}"
rules="$root/rules/outdoor.situ"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

echo "== building situ and the hand-written matcher ($profile)" >&2
case "$profile" in
release) (cd "$root" && cargo build --release --quiet -p situ -p situ-handwritten \
    && cargo build --release --quiet -p situ-runtime --example instructions) ;;
# The features of `cargo test --workspace --all-features`: its binary, not a rebuild.
debug) (cd "$root" && cargo build --quiet --all-features -p situ -p situ-handwritten) ;;
*) echo "error: PROFILE is release or debug, not $profile" >&2; exit 2 ;;
esac
target="${CARGO_TARGET_DIR:-$root/target}/$profile"
bash "$root/bench/clips/install.sh" >&2

echo "== $events events, seed $seed, over rules/outdoor.situ" >&2
"$target/situ" bench "$rules" --events "$events" --seed "$seed" \
    --stream-out "$work/stream.events" --states-out "$work/situ.states" >"$work/situ.json"
bash "$root/bench/clips/run.sh" "$work/stream.events" "$work/clips.states" >"$work/clips.json"
"$target/situ-handwritten" --stream "$work/stream.events" --states-out "$work/handwritten.states" \
    >"$work/handwritten.json"

engines=(clips handwritten)
if [[ $profile == release ]]; then
    "$target/situ" build "$rules" -o "$work/outdoor.bundle" >&2
    NATIVE=1 "$target/examples/instructions" "$work/outdoor.bundle" "$work/stream.events" "$work/native.states" \
        >"$work/native.json"
    engines+=(native)
fi
for engine in "${engines[@]}"; do
    if ! cmp -s "$work/situ.states" "$work/$engine.states"; then
        echo "error: situ and $engine reach different state sequences; first difference:" >&2
        diff "$work/situ.states" "$work/$engine.states" | head -n 6 >&2 || true
        exit 1
    fi
done
changes="$(wc -l <"$work/situ.states")"
echo "== the engines agree (${engines[*]} and situ): $changes state changes, identical" >&2

field() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }
situ_rate="$(field "$work/situ.json" events_per_sec)"
clips_rate="$(field "$work/clips.json" events_per_sec)"
hand_rate="$(field "$work/handwritten.json" events_per_sec)"
python3 - "$work" "$situ_rate" "$clips_rate" "$hand_rate" <<'PY'
import json, sys
work, situ, clips, hand = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
s = json.load(open(f"{work}/situ.json"))
lat = s["latency_ns"]
print(f"situ:        {situ:>13,.0f} events/s  p50 {lat['p50']} ns  p99 {lat['p99']} ns  max {lat['max']} ns  "
      f"peak RSS {s['peak_rss_bytes'] / 2**20:.1f} MiB  {s['nodes']['total']} nodes")
print(f"clips:       {clips:>13,.0f} events/s  (CLIPS 6.30, parsing included)")
print(f"handwritten: {hand:>13,.0f} events/s")
print(f"situ/clips ratio: {situ / clips:.1f}")
print(f"handwritten/situ ratio: {hand / situ:.2f}")
PY
if [[ $profile == release ]]; then
    native_rate="$(field "$work/native.json" events_per_sec)"
    python3 - "$native_rate" "$hand_rate" <<'PY'
import sys
native, hand = float(sys.argv[1]), float(sys.argv[2])
print(f"situ native: {native:>13,.0f} events/s  (situ build --native, the module's step inlined)")
print(f"handwritten/situ-native ratio: {hand / native:.2f}")
PY
fi
if [[ $profile != release ]]; then
    echo "(a $profile build: the speeds above are not figures; docs/performance.md has the release ones)"
fi
