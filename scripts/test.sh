#!/usr/bin/env bash
# Every test of situ, from a fresh machine: installs what the tests need
# (Python packages from PyPI, CLIPS and spin from Debian's packages), then
# runs the Rust tests with every feature (the Zenoh bus included) and the
# checks against the external references. A tool that cannot be installed
# fails the run: nothing is skipped.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== installing the Python packages the tests use (examples/python/requirements.txt)"
python3 -m pip install --quiet --disable-pip-version-check -r examples/python/requirements.txt

bash scripts/install-graphviz.sh # situ graph lays pictures out with Graphviz; tests/graph_cmd.rs needs it
bash scripts/install-chromium.sh # tests/view_cmd.rs drives situ view's page in headless Chromium
bash scripts/install-capi-tools.sh # capi/tests/c_programs.rs: CMake, gcc, g++ and valgrind for the C API
bash scripts/install-net-tools.sh # tests/faults.rs: iproute2 and nftables for the test hosts (network namespaces, as root)
echo "== the runtime depends on the bundle crate, not on the compiler (cargo tree -p situ-runtime)"
tree=$(cargo tree -p situ-runtime) # dev-dependencies included
grep -q "^situ-runtime " <<<"$tree" || { echo "cargo tree printed no tree for situ-runtime" >&2; exit 1; }
leaked=$(grep -E "pest|miette|grammar|petgraph|situ-compiler" <<<"$tree" || true)
if [ -n "$leaked" ]; then
    echo "situ-runtime reaches the compiler's dependencies:"
    echo "$leaked"
    exit 1
fi

echo "== cargo test --workspace --all-features"
cargo test --workspace --all-features

echo "== the Python package: pip install ./python (maturin; the dev profile, whose build the tests above made), mypy --strict, pytest"
MATURIN_PEP517_ARGS="--profile dev" python3 -m pip install --quiet --disable-pip-version-check --force-reinstall ./python
(cd python && python3 -m mypy --strict situ tests ../examples/python/board_node.py)
SITU=target/debug/situ python3 -m pytest -q -p no:cacheprovider python/tests
echo "== the Python package and clipspy reach situ bench's states (bench/python/vs_clipspy.py; the speeds: docs/performance.md, release)"
python3 bench/python/vs_clipspy.py --situ target/debug/situ --events 20000

echo "== the fuzz targets, 5 s each, from their committed corpora (scripts/fuzz.sh; cargo-fuzz on stable)"
bash scripts/fuzz.sh 5

echo "== the VS Code extension's grammar on every .situ file (vscode-tmgrammar-test, from npm)"
bash editors/vscode/test/run.sh

echo "== a situ run recording reads with the mcap package from PyPI (Foxglove's schemas)"
bash tests/python/check.sh target/debug/situ

echo "== CLIPS: the outdoor rules in CLIPS pass their own tests"
bash bench/clips/install.sh
bash bench/clips/selftest.sh

echo "== situ, CLIPS and the hand-written matcher reach the same states"
# The test build's binaries: the agreement is checked here; the speeds are
# docs/performance.md's, measured in release with `bash bench/vs-clips.sh`.
PROFILE=debug EVENTS=200000 bash bench/vs-clips.sh

echo "== spin and situ agree on the properties (Promela export)"
SITU=target/debug/situ bash verify/spin-check.sh

echo "== ABC and situ agree on the properties (AIGER export of the circuit; pdr and int)"
SITU=target/debug/situ bash verify/abc-check.sh
