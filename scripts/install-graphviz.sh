#!/usr/bin/env bash
# Installs Graphviz from Debian's package `graphviz` if the `dot` command is
# missing. Exits non-zero with a message if it cannot.
set -euo pipefail

if command -v dot >/dev/null 2>&1; then
    exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
    SUDO=()
elif command -v sudo >/dev/null 2>&1; then
    SUDO=(sudo)
else
    echo "scripts/install-graphviz.sh: error: 'dot' (Graphviz) is missing, and installing it needs root (or sudo)" >&2
    exit 1
fi

export DEBIAN_FRONTEND=noninteractive
echo "scripts/install-graphviz.sh: installing Debian's package graphviz" >&2
if ! "${SUDO[@]}" apt-get install -y graphviz >&2; then
    echo "scripts/install-graphviz.sh: apt-get install failed; updating the package lists and retrying" >&2
    if ! "${SUDO[@]}" apt-get update >&2 || ! "${SUDO[@]}" apt-get install -y graphviz >&2; then
        echo "scripts/install-graphviz.sh: error: could not install Debian's package graphviz" >&2
        exit 1
    fi
fi

if ! command -v dot >/dev/null 2>&1; then
    echo "scripts/install-graphviz.sh: error: package graphviz installed but no 'dot' command on PATH" >&2
    exit 1
fi
