#!/usr/bin/env bash
# The live book in one command: builds the WebAssembly package (web/build.sh)
# and serves the book with mdbook on http://127.0.0.1:3000 (widgets need
# http: a page opened as a file cannot load WebAssembly).
set -euo pipefail
cd "$(dirname "$0")/.."
bash web/build.sh
exec mdbook serve book --hostname 127.0.0.1 --port "${PORT:-3000}"
