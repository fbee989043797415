#!/usr/bin/env bash
# Installs CLIPS 6.30 from Debian's package `clips` if the `clips` command is
# missing. Exits non-zero with a message if it cannot.
set -euo pipefail

if command -v clips >/dev/null 2>&1; then
    exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
    SUDO=()
elif command -v sudo >/dev/null 2>&1; then
    SUDO=(sudo)
else
    echo "bench/clips/install.sh: error: 'clips' is missing, and installing it needs root (or sudo)" >&2
    exit 1
fi

export DEBIAN_FRONTEND=noninteractive
echo "bench/clips/install.sh: installing Debian's package clips" >&2
if ! "${SUDO[@]}" apt-get install -y clips >&2; then
    echo "bench/clips/install.sh: apt-get install failed; updating the package lists and retrying" >&2
    if ! "${SUDO[@]}" apt-get update >&2 || ! "${SUDO[@]}" apt-get install -y clips >&2; then
        echo "bench/clips/install.sh: error: could not install Debian's package clips" >&2
        exit 1
    fi
fi

if ! command -v clips >/dev/null 2>&1; then
    echo "bench/clips/install.sh: error: package clips installed but no 'clips' command on PATH" >&2
    exit 1
fi
