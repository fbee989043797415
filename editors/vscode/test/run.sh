#!/usr/bin/env bash
# The extension's grammar tests, from a fresh machine: installs the npm
# packages (vscode-tmgrammar-test), runs the assertions of test/*.test.situ,
# then tokenizes every .situ file of the repository that situ parses and
# checks that the grammar covers the whole lexicon. A missing tool fails.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
repo="$(cd "$here/../.." && pwd)"
cd "$here"

command -v node >/dev/null || { echo "error: node is not installed" >&2; exit 1; }
command -v npm >/dev/null || { echo "error: npm is not installed" >&2; exit 1; }
npm ci --no-audit --no-fund --loglevel=error

echo "== vscode-tmgrammar-test: the assertions of test/*.test.situ"
npx --no-install vscode-tmgrammar-test -g syntaxes/situ.tmLanguage.json "test/*.test.situ"

situ="${SITU:-$repo/target/debug/situ}"
if [ ! -x "$situ" ]; then
    (cd "$repo" && cargo build --bin situ)
fi
echo "== every .situ file of the repository that parses, tokenized"
list="$(mktemp)"
trap 'rm -f "$list"' EXIT
cd "$repo"
git ls-files --cached --others --exclude-standard '*.situ' | while read -r f; do
    # Files written to fail parsing (tests/ui) are left out: their garbage is the point.
    found="$("$situ" check --format json "$f" 2>/dev/null || true)"
    if ! grep -q '"situ::E000[1-8]"' <<<"$found"; then
        echo "$repo/$f"
    fi
done > "$list"
node "$here/test/every-file.js" < "$list"
