#!/usr/bin/env bash
# Puts MathJax 3 (its one-file TeX-to-SVG bundle, no fonts to fetch) in
# book/src/mathjax/ from the npm registry, unless it is there: the book
# typesets its formulas from its own copy (book/theme/head.hbs), so the built
# book shows them with no network. Not committed (2 MB).
set -euo pipefail
cd "$(dirname "$0")"
version=3.2.2
out=src/mathjax
if [ -f "$out/tex-svg-full.js" ] && grep -q "$version" "$out/VERSION" 2>/dev/null; then
  exit 0
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
(cd "$tmp" && npm pack --silent "mathjax@$version" >/dev/null && tar xzf "mathjax-$version.tgz")
mkdir -p "$out"
cp "$tmp/package/es5/tex-svg-full.js" "$tmp/package/LICENSE" "$out/"
echo "$version" > "$out/VERSION"
echo "MathJax $version in book/$out"
