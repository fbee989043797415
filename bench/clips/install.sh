#!/usr/bin/env bash
# Installs CLIPS 6.30 from Debian's package `clips` if the `clips` command is
# missing. Exits non-zero with a message if it cannot.
set -euo pipefail

bash "$(dirname "$0")/../../scripts/apt-install.sh" clips=clips
