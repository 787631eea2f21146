#!/usr/bin/env bash
# codemark-bench on bad benchmark inis: a non-zero exit and one line that
# names the file, the line (for a key the file sets), the section and the
# key, never a crash.
# usage: bench_bad_ini.sh CODEMARK_BENCH DATA_DIR
set -euo pipefail
bench=$1 data=$2
tmp=$(mktemp -d "${TMPDIR:-/tmp}/codemark-bench-bad.$$.XXXX")
trap 'rm -rf "$tmp"' EXIT
# expect NAME PATTERN: runs the bench on $tmp/NAME.ini, wants exit 1 and PATTERN in stderr.
expect() {
  local ini=$tmp/$1.ini pattern=$2 rc=0
  "$bench" -q --config "$ini" --out "$tmp/out" 2> "$tmp/err" > /dev/null || rc=$?
  if [ "$rc" -ne 1 ]; then echo "$1: exit $rc, expected 1"; cat "$tmp/err"; exit 1; fi
  if ! grep -qF -- "$pattern" "$tmp/err"; then
    echo "$1: stderr lacks '$pattern':"; cat "$tmp/err"; exit 1
  fi
  if [ "$(wc -l < "$tmp/err")" -ne 1 ]; then echo "$1: not one line:"; cat "$tmp/err"; exit 1; fi
  echo "$1: ok: $(cat "$tmp/err")"
}
good="rawlog = $data/annotated.rawlog
map = $data/map.txt
gt = $data/gt_path.txt"

expect missing "$tmp/missing.ini: cannot open"
printf '[dataset:a]\n%s\nspeed = 3\n' "$good" > "$tmp/unknown_key.ini"
expect unknown_key "unknown_key.ini:5: [dataset:a] speed: unknown key"
printf '[dataset:a]\nrawlog = %s/annotated.rawlog\nmap = %s/map.txt\n' "$data" "$data" > "$tmp/no_gt.ini"
expect no_gt "no_gt.ini: [dataset:a] gt: missing"
printf '[dataset:a]\n%s\n' "${good/map.txt/nomap.txt}" > "$tmp/no_map_file.ini"
expect no_map_file "no_map_file.ini:3: [dataset:a] map: $data/nomap.txt: no such file"
printf '[bench]\nrpe_interval_s = 1.0x\n[dataset:a]\n%s\n' "$good" > "$tmp/bad_number.ini"
expect bad_number "bad_number.ini:2: [bench] rpe_interval_s: '1.0x' is not a positive number"
printf '[bench]\nmethods = ekf, kalman\n[dataset:a]\n%s\n' "$good" > "$tmp/bad_method.ini"
expect bad_method "bad_method.ini:2: [bench] methods: unknown method 'kalman'"
printf '[datasets]\nx = 1\n' > "$tmp/bad_section.ini"
expect bad_section "bad_section.ini: [datasets]: unknown section"
printf '[bench]\nmin_span_px = 30\n' > "$tmp/no_dataset.ini"
expect no_dataset "no_dataset.ini: no [dataset:NAME] section"
# Bad arguments: one line naming the argument.
printf '[dataset:a]\n%s\n' "$good" > "$tmp/good.ini"
for args in "--methods ekf,kalman|--methods: unknown method 'kalman'" "--jobs abc|--jobs"; do
  rc=0
  "$bench" -q --config "$tmp/good.ini" --out "$tmp/out" ${args%%|*} 2> "$tmp/err" > /dev/null || rc=$?
  if [ "$rc" -ne 1 ] || ! grep -qF -- "${args#*|}" "$tmp/err" || [ "$(wc -l < "$tmp/err")" -ne 1 ]; then
    echo "args '${args%%|*}': exit $rc, stderr:"; cat "$tmp/err"; exit 1
  fi
  echo "args '${args%%|*}': ok: $(cat "$tmp/err")"
done
# A dataset whose rawlog is not a rawlog: the job fails with its name, the others still run.
head -c 3000 /dev/urandom > "$tmp/junk.rawlog"
printf '[dataset:junk]\nrawlog = %s/junk.rawlog\nmap = %s/map.txt\ngt = %s/gt_path.txt\n' "$tmp" "$data" "$data" \
  > "$tmp/junk_rawlog.ini"
rc=0
"$bench" -q --config "$tmp/junk_rawlog.ini" --out "$tmp/out" --methods ekf 2> "$tmp/err" > /dev/null || rc=$?
test "$rc" -eq 1 || { echo "junk rawlog: exit $rc"; cat "$tmp/err"; exit 1; }
grep -q "junk / ekf: " "$tmp/err" || { echo "junk rawlog: no job error"; cat "$tmp/err"; exit 1; }
grep -q "^junk,ekf,error," "$tmp/out/results.csv"
echo "junk_rawlog: ok: $(cat "$tmp/err")"
echo "bench_bad_ini: ok"
