#!/usr/bin/env bash
# No file of the repository refers to documents outside it: the formats
# live in docs/spec.md, the design in docs/design.md.
# usage: self_contained.sh SOURCE_DIR
set -euo pipefail
cd "$1"
pattern='\.\./shared|landmark-spec\.md|paper-notes|mrpt-notes|ARCHITECTURE\.md|STYLE\.md'
# A checkout's .git is a directory, a worktree's a file.
if [[ -e .git ]] && command -v git >/dev/null; then
	files=$(git ls-files)
else
	files=$(find . -type f -not -path './build*' -not -path './.git/*')
fi
hits=$(grep -n -I -E "$pattern" $files 2>/dev/null | grep -v -E '^(\./)?tests/docs/self_contained.sh:' || true)
if [[ -n "$hits" ]]; then
	echo "files that refer to documents outside the repository:"
	echo "$hits"
	exit 1
fi
