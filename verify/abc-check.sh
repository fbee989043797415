#!/usr/bin/env bash
# ABC and situ must agree on every safety property of the repository's rule
# files, the examples and the planted bugs of tests/verify/: for each
# property, `situ export --aiger --property NAME` writes the circuit of the
# abstraction (exact in time, runs of any length), ABC's `pdr` and `int`
# engines decide it, and `situ test --format json` must give the same
# answer (proved, or failed with a counterexample). Unbounded `eventually`
# has no bad state and is left out. A property situ could only exhaust (its
# abstraction samples values compared with variables) agrees with ABC's
# "proved" on that abstraction's circuit. It fails loudly when ABC (Debian's
# `berkeley-abc`) is missing and cannot be installed.
#
#   bash verify/abc-check.sh                     # all the files below
#   SITU=target/release/situ bash verify/abc-check.sh rules/outdoor.situ
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/apt-install.sh berkeley-abc=berkeley-abc

if [ -z "${SITU:-}" ]; then
    cargo build --quiet
    SITU=target/debug/situ
fi
if [ "$#" -gt 0 ]; then
    files=("$@")
else
    files=(rules/*.situ examples/*/*.situ tests/verify/*.situ)
fi
SITU="$SITU" python3 - "${files[@]}" <<'PY'
import json, os, subprocess, sys, tempfile

situ = os.environ["SITU"]
disagree, checked = [], 0
with tempfile.TemporaryDirectory() as tmp:
    for path in sys.argv[1:]:
        out = subprocess.run([situ, "test", path, "--format", "json", "--engine", "exhaustive"],
                             capture_output=True, text=True)
        if out.returncode == 2:
            print(f"{path}: not checked by situ ({out.stderr.strip().splitlines()[:1]})")
            continue
        props = [json.loads(l) for l in out.stdout.splitlines() if l.startswith("{")]
        props = [p for p in props if p.get("kind") == "property"]
        for p in props:
            verdicts = [v for v in (p.get("exhaustive"), p.get("symbolic")) if v]
            # "exhausted": the abstraction was explored whole with no
            # counterexample, but it samples some values (those compared
            # with variables): not "proved" for the rules, yet exactly what
            # ABC decides on the exported circuit of that same abstraction.
            if p["verdict"] in ("violated", "error"):
                mine = "failed"
            elif any(v["verdict"] == "proved" for v in verdicts):
                mine = "proved"
            elif any(v["verdict"] == "exhausted" for v in verdicts):
                mine = "exhausted"
            else:
                mine = "undecided"
            aig = os.path.join(tmp, "p.aig")
            e = subprocess.run([situ, "export", "--aiger", path, "--property", p["name"], "-o", aig],
                               capture_output=True, text=True)
            if e.returncode != 0:
                if "no safety property" in e.stderr:
                    continue  # unbounded `eventually`: a liveness property
                disagree.append(f"{path}: \"{p['name']}\": export failed: {e.stderr.strip()}")
                continue
            # pdr must decide every property; int (interpolation) is given a
            # few seconds and must agree whenever it decides.
            for engine, limit in (("pdr", 300), ("int", 5)):
                try:
                    r = subprocess.run(["berkeley-abc", "-c", f"read_aiger {aig}; {engine}"],
                                       capture_output=True, text=True, timeout=limit)
                    text = r.stdout + r.stderr
                except subprocess.TimeoutExpired:
                    text = ""
                if "Property proved" in text:
                    abc = "proved"
                elif "was asserted" in text or "Counter-example" in text or "cex" in text.lower() and "failed" in text.lower():
                    abc = "failed"
                else:
                    abc = "undecided"
                checked += 1
                line = f"{path}: \"{p['name']}\": situ {mine}, ABC {engine} {abc}"
                print(line)
                # The circuit of a sampled abstraction proved by ABC is the
                # abstraction situ exhausted: they agree.
                same = abc == mine or (mine == "exhausted" and abc == "proved")
                if not same and (engine == "pdr" or abc != "undecided"):
                    disagree.append(line)
if disagree:
    print("\nABC and situ disagree:\n" + "\n".join(disagree), file=sys.stderr)
    sys.exit(1)
if checked == 0:
    print("error: nothing was checked", file=sys.stderr)
    sys.exit(1)
print(f"ABC and situ agree on {checked} verdicts")
PY
