#!/usr/bin/env bash
# Installs what the fault tests need when a command is missing (Debian's
# packages): `ip` (iproute2: network namespaces, veth pairs, a bridge,
# routes' rto_min, nstat) and `nft` (nftables: loss between the test hosts).
# tests/faults.rs makes its test hosts with them, as root; a missing tool or
# privilege fails those tests with the reason, never skips them.
set -euo pipefail
exec bash "$(dirname "$0")/apt-install.sh" ip=iproute2 nft=nftables
