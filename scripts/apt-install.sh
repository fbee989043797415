#!/usr/bin/env bash
# Installs Debian packages for the commands a test or a check needs, when a
# command is missing: `bash scripts/apt-install.sh COMMAND=PACKAGE…`, e.g.
# `bash scripts/apt-install.sh spin=spin gcc=gcc`. It updates the package
# lists and retries once if the first try fails, and exits non-zero with a
# message naming what is missing if it cannot: a missing tool fails the run,
# it never skips it. It waits up to 5 minutes for another apt-get to finish.
set -euo pipefail

missing=()
for pair in "$@"; do
    command -v "${pair%%=*}" >/dev/null 2>&1 || missing+=("$pair")
done
[ "${#missing[@]}" -eq 0 ] && exit 0

packages=()
for pair in "${missing[@]}"; do
    packages+=("${pair#*=}")
done
if [ "$(id -u)" -eq 0 ]; then
    SUDO=()
elif command -v sudo >/dev/null 2>&1; then
    SUDO=(sudo)
else
    echo "scripts/apt-install.sh: error: ${packages[*]} missing, and installing needs root (or sudo)" >&2
    exit 1
fi

export DEBIAN_FRONTEND=noninteractive
echo "scripts/apt-install.sh: installing Debian's ${packages[*]}" >&2
if ! "${SUDO[@]}" apt-get -o DPkg::Lock::Timeout=300 install -y "${packages[@]}" >&2; then
    echo "scripts/apt-install.sh: apt-get install failed; updating the package lists and retrying" >&2
    if ! "${SUDO[@]}" apt-get -o DPkg::Lock::Timeout=300 update >&2 || ! "${SUDO[@]}" apt-get -o DPkg::Lock::Timeout=300 install -y "${packages[@]}" >&2; then
        echo "scripts/apt-install.sh: error: could not install Debian's ${packages[*]}" >&2
        exit 1
    fi
fi

for pair in "${missing[@]}"; do
    if ! command -v "${pair%%=*}" >/dev/null 2>&1; then
        echo "scripts/apt-install.sh: error: package ${pair#*=} installed but no '${pair%%=*}' command on PATH" >&2
        exit 1
    fi
done
