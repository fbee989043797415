#!/usr/bin/env bash
# Runs every fuzz target of fuzz/ (cargo-fuzz, libFuzzer) for SECONDS each
# (default 60), one after the other, one process each, on the stable
# toolchain; or only the targets named after SECONDS.
#
#   bash scripts/fuzz.sh            # every target, 60 s each
#   bash scripts/fuzz.sh 10         # what scripts/test.sh runs
#   bash scripts/fuzz.sh 3600 format mcap_read
#
# Installs cargo-fuzz (pinned) when it is missing: a tool that cannot be
# installed fails the run, nothing is skipped. cargo-fuzz passes `-Z` flags
# to rustc; RUSTC_BOOTSTRAP=1 lets the stable compiler take them (no
# nightly toolchain is needed). No sanitizer (the targets are safe Rust: a
# panic, an overflow with debug assertions, a timeout or running out of
# memory is the failure), debug assertions on, 16 codegen units (cargo-fuzz
# defaults to 1: a build twice as long on two cores), and no comparison
# tracing (`--no-trace-compares`: its hooks took half of each execution of
# the text targets).
#
# The text targets (parse_check, format, script) run every input through the
# parser, the checks, the bundle and the engine; libFuzzer's defaults make
# them crawl (120-250 executions a second). They run with the dictionary of
# the grammar's tokens (made from grammar/src/situ.pest at each run, so it
# never lags the grammar: comparison tracing no longer finds keywords), with
# inputs of at most 1 KiB (a longer input costs more and reached barely
# more edges), edge coverage without hit counts (-use_counters=0: the corpus
# grows three times slower), without the entropic schedule (it keeps a
# sorted table of rare features per input and moves memory for each one: two
# thirds of the time here) and without mutations from traced comparisons
# (-use_cmp=0): about 1,500 to 3,900 executions a second on a core of their
# own, instead of 120 to 250
# (docs/reliability.md). FUZZ_ARGS adds libFuzzer flags to every target.
#
# Each target starts from its committed corpus (fuzz/corpus/TARGET, read
# only: new inputs go to a scratch directory, so a run leaves the tree as it
# was). A crash is written to fuzz/artifacts/TARGET/ and fails the run, after
# the other targets have run; reproduce it with
#   RUSTC_BOOTSTRAP=1 cargo fuzz run -a -s none --codegen-units 16 --no-trace-compares TARGET fuzz/artifacts/TARGET/crash-…
# (from fuzz/), then keep it as a regression test of the owning crate.
# To minimise a corpus after a long run:
#   RUSTC_BOOTSTRAP=1 cargo fuzz cmin -a -s none --codegen-units 16 --no-trace-compares TARGET corpus/TARGET
set -euo pipefail
cd "$(dirname "$0")/.."

CARGO_FUZZ_VERSION=0.13.1
ALL=(parse_check format script bundle_decode mcap_read zenoh_wire scenario native)

seconds=${1:-60}
[[ $seconds =~ ^[0-9]+$ ]] || { echo "usage: scripts/fuzz.sh [SECONDS] [TARGET...]" >&2; exit 2; }
shift || true
targets=("$@")
[[ ${#targets[@]} -gt 0 ]] || targets=("${ALL[@]}")

if ! cargo fuzz --version 2>/dev/null | grep -qF "$CARGO_FUZZ_VERSION"; then
    echo "== installing cargo-fuzz $CARGO_FUZZ_VERSION (crates.io)"
    cargo install --locked cargo-fuzz --version "$CARGO_FUZZ_VERSION"
fi

export RUSTC_BOOTSTRAP=1
flags=(-a -s none --codegen-units 16 --no-trace-compares)
cd fuzz

echo "== building the fuzz targets (fuzz/target)"
start=$(date +%s)
cargo fuzz build "${flags[@]}"
echo "built in $(($(date +%s) - start)) s"

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

# The grammar's literal tokens (keywords, operators, units), less its own
# expressions and example strings, as a libFuzzer dictionary.
dict="$scratch/situ.dict"
grep -oE '"[^"]+"' ../grammar/src/situ.pest | sort -u \
    | grep -vE '~|\\|path\.situ|straight road|situ::|^" "$|^"\(|^"\)' >"$dict"
[[ $(wc -l <"$dict") -ge 50 ]] || { echo "the grammar's dictionary has $(wc -l <"$dict") tokens" >&2; exit 2; }
text_args=(-dict="$dict" -max_len=1024 -use_counters=0 -entropic=0 -use_cmp=0)
read -r -a extra_args <<<"${FUZZ_ARGS:-}"
failed=()
summary=()
for t in "${targets[@]}"; do
    [[ -d corpus/$t ]] || { echo "no corpus for $t (fuzz/corpus/$t)" >&2; exit 2; }
    echo "== fuzzing $t for $seconds s"
    mkdir -p "$scratch/$t" "artifacts/$t"
    log="$scratch/$t.log"
    case $t in
        parse_check | format | script) args=("${text_args[@]}") ;;
        *) args=() ;;
    esac
    # -timeout: an input that takes longer is a hang, and a failure.
    if cargo fuzz run "${flags[@]}" "$t" "$scratch/$t" "corpus/$t" -- \
        -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
        "${args[@]}" "${extra_args[@]}" >"$log" 2>&1; then
        status=ok
    else
        status=FAILED
        failed+=("$t")
        grep -E -A30 "panicked|ERROR: libFuzzer|deadly signal|Test unit written" "$log" | head -60 | cut -c1-300 || tail -40 "$log" | cut -c1-300
    fi
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
    cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -1 | cut -d' ' -f2)
    line=$(printf '%-14s %-6s %12s runs %8s exec/s  cov %s' "$t" "$status" "${runs:-?}" "${rate:-?}" "${cov:-?}")
    echo "$line"
    summary+=("$line")
done

echo "== fuzz summary ($seconds s per target)"
printf '%s\n' "${summary[@]}"
if [[ ${#failed[@]} -gt 0 ]]; then
    echo "failed: ${failed[*]} (inputs in fuzz/artifacts/)" >&2
    exit 1
fi
