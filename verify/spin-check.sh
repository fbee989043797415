#!/usr/bin/env bash
# spin and situ must agree on the properties of the repository's rule files
# and of the planted bugs of tests/verify/: for each file, `situ export
# --promela` writes the abstraction that `situ test --engine exhaustive`
# explores (same --depth and --max-states), spin checks each property of it
# (`-DPROP=k`: a safety search for the monitors, an acceptance-cycle search
# for unbounded `eventually`), and the verdicts must be the same. It fails
# loudly when spin is missing and cannot be installed.
#
#   bash verify/spin-check.sh            # all the files below
#   SITU=target/release/situ bash verify/spin-check.sh
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/apt-install.sh spin=spin gcc=gcc

if [ -z "${SITU:-}" ]; then
    cargo build -q -p situ
    SITU="${CARGO_TARGET_DIR:-target}/debug/situ"
fi

# FILE:MAX_STATES (the rule files are explored partly: spin compiles every node).
CASES=("rules/outdoor.situ:400" "rules/ugv.situ:400")
for f in tests/verify/*.situ; do CASES+=("$f:20000"); done
DEPTH=12

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
agree=0
disagree=0
for case in "${CASES[@]}"; do
    file="${case%%:*}"
    max="${case##*:}"
    "$SITU" export --promela "$file" --depth "$DEPTH" --max-states "$max" -o "$work/model.pml" 2>/dev/null
    "$SITU" test "$file" --format json --engine exhaustive --depth "$DEPTH" --max-states "$max" >"$work/situ.json" || true
    # situ's "holds": no run breaks it (proved or undecided, not violated).
    mapfile -t situ_passed < <(python3 -c 'import json, sys
for line in open(sys.argv[1]):
    o = json.loads(line)
    if o.get("kind") == "property":
        print("false" if o["verdict"] in ("violated", "error") else "true")' "$work/situ.json")
    mapfile -t kinds < <(grep -o '^/\* PROP=[0-9]* kind=[a-z]*' "$work/model.pml" | sed 's/.*kind=//')
    if [ "${#situ_passed[@]}" != "${#kinds[@]}" ]; then
        echo "error: $file: situ reports ${#situ_passed[@]} properties, the model has ${#kinds[@]}" >&2
        exit 1
    fi
    for k in "${!kinds[@]}"; do
        kind="${kinds[$k]}"
        if [ "$kind" = skipped ]; then
            echo "skip  $file PROP=$k (unbounded eventually on a graph that is not closed)"
            continue
        fi
        (
            cd "$work"
            rm -f pan pan.* model.pml.trail
            spin -a -DPROP="$k" model.pml >/dev/null
            if [ "$kind" = liveness ]; then
                gcc -O0 -w -o pan pan.c && ./pan -a -m1000000 >pan.out 2>&1 || true
            else
                gcc -O0 -w -DSAFETY -o pan pan.c && ./pan -m1000000 >pan.out 2>&1 || true
            fi
        )
        errors="$(grep -o 'errors: [0-9]*' "$work/pan.out" | cut -d' ' -f2 || true)"
        if [ -z "$errors" ]; then
            echo "error: $file PROP=$k: spin gave no verdict:" >&2
            cat "$work/pan.out" >&2
            exit 1
        fi
        spin_holds=$([ "$errors" = 0 ] && echo true || echo false)
        name="$(grep -o "^/\* PROP=$k kind=[a-z]*: .* \*/" "$work/model.pml" | sed 's/^[^:]*: //; s/ \*\/$//')"
        if [ "$spin_holds" = "${situ_passed[$k]}" ]; then
            agree=$((agree + 1))
            echo "agree $file \"$name\": holds=$spin_holds"
        else
            disagree=$((disagree + 1))
            echo "DISAGREE $file \"$name\": spin holds=$spin_holds, situ holds=${situ_passed[$k]}" >&2
        fi
    done
done
echo "spin-check: $agree passed, $disagree failed"
[ "$disagree" = 0 ] && [ "$agree" -gt 0 ]
