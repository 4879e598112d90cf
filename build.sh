#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The README's two commands: `./build.sh render` and `./build.sh test`.
# Installs the missing Debian packages (make included), then runs the Makefile target.
set -euo pipefail
cd "$(dirname "$0")"
case "${1:-}" in
  render|test) ;;
  *) echo "usage: ./build.sh render|test" >&2; exit 2 ;;
esac
bash scripts/setup.sh
exec make --no-print-directory "$1"
