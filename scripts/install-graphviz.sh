#!/usr/bin/env bash
# Installs Graphviz (Debian's `graphviz`) if the `dot` command is missing:
# `situ graph` lays pictures out with it and tests/graph_cmd.rs needs it.
set -euo pipefail
exec bash "$(dirname "$0")/apt-install.sh" dot=graphviz
