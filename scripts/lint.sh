#!/usr/bin/env bash
# Static checks of codemark's own sources (libs, apps, tests, fuzz, bench):
#   scripts/lint.sh          clang-format (--dry-run -Werror, .clang-format) and
#                            clang-tidy (.clang-tidy, warnings are errors) over
#                            the main build's compile_commands.json, 2 at a time
#   scripts/lint.sh --fix    applies clang-format -i and clang-tidy's fixes
#   scripts/lint.sh --format-only | --tidy-only [--fix]
# Environment: LINT_BUILD_DIR (default build; configured here if needed),
# LINT_JOBS (default 2), LINT_TIDY_SCOPE: the top folders whose .cpp files
# clang-tidy checks, default "libs" (the libraries and their public headers:
# the CI budget of 30 min); "libs apps fuzz" took 10 min under load;
# "libs apps fuzz tests bench" for everything (--fix uses that by default).
set -euo pipefail
cd "$(dirname "$0")/.."
FIX=0; FORMAT=1; TIDY=1
for a in "$@"; do
  case "$a" in
    --fix) FIX=1 ;;
    --format-only) TIDY=0 ;;
    --tidy-only) FORMAT=0 ;;
    *) echo "usage: scripts/lint.sh [--fix] [--format-only|--tidy-only]" >&2; exit 2 ;;
  esac
done
BUILD=${LINT_BUILD_DIR:-build}
JOBS=${LINT_JOBS:-2}
CLANG_FORMAT=$(command -v clang-format-14 || command -v clang-format)
CLANG_TIDY=$(command -v clang-tidy-14 || command -v clang-tidy)
RUN_TIDY=$(command -v run-clang-tidy-14 || command -v run-clang-tidy)
APPLY=$(command -v clang-apply-replacements-14 || command -v clang-apply-replacements)

# The project's C++ sources under version control (nothing generated, nothing third-party).
mapfile -t SOURCES < <(git ls-files -- 'libs/*.cpp' 'libs/*.h' 'apps/*.cpp' 'apps/*.h' \
  'tests/*.cpp' 'tests/*.h' 'fuzz/*.cpp' 'bench/*.cpp' 'bench/*.h')
status=0

if [[ $FORMAT == 1 ]]; then
  if [[ $FIX == 1 ]]; then
    "$CLANG_FORMAT" -i "${SOURCES[@]}"
    echo "lint: clang-format applied to ${#SOURCES[@]} files"
  else
    n=$("$CLANG_FORMAT" --dry-run "${SOURCES[@]}" 2>&1 | grep -c 'warning:' || true)
    files=$(for f in "${SOURCES[@]}"; do "$CLANG_FORMAT" --dry-run -Werror "$f" >/dev/null 2>&1 || echo "$f"; done)
    if [[ -n "$files" ]]; then
      echo "lint: clang-format: $n lines to reformat in $(echo "$files" | wc -l) files (scripts/lint.sh --fix):"
      echo "$files" | sed 's/^/  /' | head -50
      status=1
    else
      echo "lint: clang-format clean (${#SOURCES[@]} files)"
    fi
  fi
fi

if [[ $TIDY == 1 ]]; then
  if [[ ! -f "$BUILD/compile_commands.json" ]]; then
    cmake -S . -B "$BUILD" >/dev/null
  fi
  # Only translation units of ours; the headers come in through HeaderFilterRegex.
  default_scope="libs"
  [[ $FIX == 1 ]] && default_scope="libs apps fuzz tests bench"
  scope=${LINT_TIDY_SCOPE:-$default_scope}
  regex="^$PWD/(${scope// /|})/.*\\.cpp\$"
  log=$(mktemp)
  args=(-p "$BUILD" -j "$JOBS" -quiet -clang-tidy-binary "$CLANG_TIDY")
  if [[ $FIX == 1 ]]; then
    args+=(-fix -format -style file -clang-apply-replacements-binary "$APPLY")
  fi
  start=$(date +%s)
  # run-clang-tidy colours its lines (escape codes before the path): strip them,
  # or the findings below would never be counted.
  "$RUN_TIDY" "${args[@]}" "$regex" 2>&1 | sed -E 's/\x1b\[[0-9;]*m//g' >"$log" || true
  n=$(grep -cE '^/.*: (warning|error): .*\[[a-z]' "$log" || true)
  echo "lint: clang-tidy: $n findings over $(grep -c '"file"' "$BUILD/compile_commands.json") TUs in the database, $(( $(date +%s) - start )) s"
  if [[ $n -gt 0 ]]; then
    grep -E '^/.*: (warning|error): .*\[[a-z]' "$log" | sed "s|^$PWD/||" | sort -u | head -200
    grep -oE '\[[a-z]+[a-z0-9.-]*(,-warnings-as-errors)?\]$' "$log" | sed 's/,-warnings-as-errors//' | sort | uniq -c | sort -rn
    [[ $FIX == 1 ]] || status=1
  fi
  rm -f "$log"
fi
exit $status
