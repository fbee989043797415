#!/usr/bin/env bash
# The engine's cost in instructions per event, against the hand-written
# matcher's, on the same seeded stream over rules/outdoor.situ
# (docs/performance.md). Instruction counts do not move with the load of a
# shared machine as wall-clock times do.
#
#   bash bench/instructions.sh                 # 300,000 events, seed 1
#   EVENTS=100000 SEED=7 bash bench/instructions.sh
#   TOP=25 bash bench/instructions.sh          # and situ's 25 costliest functions
#   KEEP=DIR bash bench/instructions.sh        # keep the callgrind files in DIR
#   INTERPRETED=1 bash bench/instructions.sh   # situ's Rete interpreter instead of its fast path
#
# 1. builds in release `situ`, `situ-handwritten` and the example
#    `instructions` of situ-runtime (valgrind: scripts/install-capi-tools.sh);
# 2. `situ build` compiles the rules to a bundle; `situ bench` generates the
#    stream (written to a file) and its state sequence;
# 3. runs situ's engine (`runtime/examples/instructions.rs`) on its fast path
#    (or its interpreter), situ's engine on the native code of the rules
#    (`situ build --native`, `runtime-tests/native/outdoor.rs`, which the
#    example links), and the hand-written matcher (`bench/handwritten/`) on
#    that file under `valgrind --tool=callgrind`;
# 4. the four state sequences (situ bench, the engine twice under
#    callgrind, the hand-written matcher) must be equal, else it stops with
#    exit 1;
# 5. prints the instructions per event of each and the `handwritten/situ`
#    ratios.
#
# What is counted: only the processing loop. Both programs read and parse
# the stream first, then call one `#[inline(never)]` function that processes
# the whole pre-parsed stream (`process_stream`: situ's steps every event as
# `situ bench` does, with its clock, its step, the state at rest and the
# reset of a finished mission; the hand-written one is its timed loop).
# Callgrind collects only inside it (`--toggle-collect=*::process_stream`):
# set-up, parsing and output are not counted. The native run's loop is
# `process_stream_native`, the same loop calling the module's `step` as a
# program that links native code does.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
events="${EVENTS:-300000}"
seed="${SEED:-1}"
top="${TOP:-0}"
rules="$root/rules/outdoor.situ"
if [[ -n ${KEEP:-} ]]; then
    work="$KEEP"
    mkdir -p "$work"
else
    work="$(mktemp -d)"
    trap 'rm -rf "$work"' EXIT
fi
if ! command -v valgrind >/dev/null; then
    echo "error: valgrind is missing: bash scripts/install-capi-tools.sh installs it" >&2
    exit 2
fi

echo "== building situ, the hand-written matcher and the example \`instructions\` (release)" >&2
(cd "$root" && cargo build --release --quiet -p situ -p situ-handwritten \
    && cargo build --release --quiet -p situ-runtime --example instructions)
target="${CARGO_TARGET_DIR:-$root/target}/release"

echo "== $events events, seed $seed, over rules/outdoor.situ" >&2
"$target/situ" build "$rules" -o "$work/outdoor.bundle" >&2
"$target/situ" bench "$rules" --events "$events" --seed "$seed" \
    --stream-out "$work/stream.events" --states-out "$work/bench.states" >/dev/null

callgrind() {
    local out="$1"
    shift
    valgrind --tool=callgrind --toggle-collect='*::process_stream*' \
        --callgrind-out-file="$out" "$@" >/dev/null 2>"$out.log" || {
        echo "error: $* failed under valgrind:" >&2
        cat "$out.log" >&2
        exit 1
    }
}
callgrind "$work/situ.cg" "$target/examples/instructions" "$work/outdoor.bundle" "$work/stream.events" \
    "$work/situ.states"
INTERPRETED=0 NATIVE=1 callgrind "$work/native.cg" "$target/examples/instructions" "$work/outdoor.bundle" \
    "$work/stream.events" "$work/native.states"
callgrind "$work/handwritten.cg" "$target/situ-handwritten" --stream "$work/stream.events" \
    --states-out "$work/handwritten.states"

for engine in situ native handwritten; do
    if ! cmp -s "$work/bench.states" "$work/$engine.states"; then
        echo "error: \`situ bench\` and $engine (under callgrind) reach different state sequences; first difference:" >&2
        diff "$work/bench.states" "$work/$engine.states" | head -n 6 >&2 || true
        exit 1
    fi
done
changes="$(wc -l <"$work/bench.states")"
echo "== situ and the hand-written matcher agree: $changes state changes, identical" >&2

# The instructions collected (the `summary:` line of a callgrind file: Ir).
total() {
    local n
    n="$(sed -n 's/^summary: \([0-9]*\).*/\1/p' "$1")"
    if [[ -z $n || $n == 0 ]]; then
        echo "error: callgrind collected nothing in $1: is \`process_stream\` still a function of its own?" >&2
        exit 1
    fi
    echo "$n"
}
situ_ir="$(total "$work/situ.cg")"
native_ir="$(total "$work/native.cg")"
hand_ir="$(total "$work/handwritten.cg")"
label="fast path"
if [[ ${INTERPRETED:-0} == 1 ]]; then label="interpreter"; fi
python3 - "$events" "$situ_ir" "$native_ir" "$hand_ir" "$label" <<'PY'
import sys
events, situ, native, hand = (int(x) for x in sys.argv[1:5])
label = sys.argv[5]
for name, n in ((f"situ ({label}):", situ), ("situ (native):", native), ("handwritten:", hand)):
    print(f"{name:<20} {n:>15,} instructions  {n / events:8.1f} per event")
print(f"handwritten/situ ratio (instructions), {label}: {situ / hand:.2f}")
print(f"handwritten/situ ratio (instructions), native: {native / hand:.2f}")
PY
if [[ $top -gt 0 ]]; then
    for run in situ native; do
        echo "== $run: the $top costliest functions (exclusive instructions, inlined code in its caller)"
        # sed, not head: the pipe is read to its end (no SIGPIPE under pipefail).
        callgrind_annotate --threshold=100 "$work/$run.cg" 2>/dev/null | sed -n '/^Ir/,$p' | sed -n "1,$((top + 2))p"
    done
fi
