#!/usr/bin/env bash
# Installs Chromium (Debian's `chromium`) if the `chromium` command is
# missing: tests/view_cmd.rs loads `situ view`'s page in headless Chromium.
set -euo pipefail
exec bash "$(dirname "$0")/apt-install.sh" chromium=chromium
