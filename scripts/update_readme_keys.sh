#!/usr/bin/env bash
# Regenerate README.md's config reference (between the keys:begin/keys:end markers) from
# `bksim keys`, the single source of truth; tests/test_cli.c checks they agree.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
bk_find_bksim bksim
cd "$BK_REPO"
bk_temp_dir tmp
ref=$tmp/keys.md
"$bksim" keys > "$ref"
awk -v ref="$ref" '
    /<!-- keys:begin -->/ { print; while ((getline line < ref) > 0) print line; skip = 1; next }
    /<!-- keys:end -->/   { skip = 0 }
    !skip' README.md > README.md.new
mv README.md.new README.md
