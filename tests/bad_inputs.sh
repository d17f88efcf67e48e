#!/usr/bin/env bash
# Runs every case of tests/data/bad/cases.tsv through the CLI: the exit code must match, stderr
# must be exactly one line matching the case's pattern, stdout must stay empty (`--json` readers
# rely on it), and the output folder must stay empty.
# A case expecting exit 0 (a tricky input that must be read correctly) must print nothing on
# stderr instead, and its pattern must match a line of stdout. A `run` of a scene whose expected
# message is about the scene itself (the pattern begins with the scene's file name) must begin with
# the scene's path as given, then a line, a key, an override or "file" (the file itself missing or
# unreadable): the context of an error raised deep in the library cannot get lost unnoticed.
# {DECK} is a fresh copy of the one-tetrahedron deck tests/data/bad/fem/deck, which must come back
# unchanged (fem-check leaves a deck folder as it was after an error); {FEM} is
# tests/data/bad/fem (fake solvers). {FIFO} is a fresh named pipe nobody writes to: reading it
# would block forever, so it must be refused by its type. Every command runs under a timeout of
# 300 s: a hang fails its case instead of stopping the suite. A case expecting exit 4 (a failed
# self-check) may print its report on stdout, and publishes its outputs as evidence (issue 32): its
# output folder must hold report.html and nothing hidden (no staging folder, no journal).
# usage: bad_inputs.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
bad="$src/tests/data/bad"
pass=0; fail=0
while IFS=$'\t' read -r name args code pattern; do
  case "$name" in ''|'#'*) continue ;; esac
  out=$(mktemp -d)
  a=${args//\{BAD\}/$bad}
  a=${a//\{OUT\}/$out}
  a=${a//\{SRC\}/$src}
  deck="$out.d/deck"
  case "$args" in *'{DECK}'*) mkdir -p "$out.d" && cp -r "$bad/fem/deck" "$deck" ;; esac
  a=${a//\{DECK\}/$deck}
  a=${a//\{FEM\}/$bad/fem}
  case "$args" in *'{FIFO}'*) mkfifo "$out.fifo" ;; esac
  a=${a//\{FIFO\}/$out.fifo}
  # shellcheck disable=SC2086
  timeout -k 10 300 "$bin" $a >"$out.stdout" 2>"$out.stderr" </dev/null
  rc=$?
  lines=$(wc -l <"$out.stderr")
  msg=$(head -n 1 "$out.stderr")
  problems=""
  [ "$rc" = "$code" ] || problems="$problems exit $rc (expected $code);"
  if [ "$code" = 0 ]; then
    [ "$lines" -eq 0 ] || problems="$problems $lines stderr lines (expected none);"
    grep -Eq -- "$pattern" "$out.stdout" || problems="$problems no stdout line matches /$pattern/;"
  else
    [ "$lines" -eq 1 ] || problems="$problems $lines stderr lines (expected 1);"
    [ "$code" = 4 ] || [ ! -s "$out.stdout" ] || problems="$problems stdout not empty: $(head -c 80 "$out.stdout");"
    printf '%s' "$msg" | grep -Eq -- "$pattern" || problems="$problems message does not match /$pattern/;"
    # shellcheck disable=SC2086
    set -- $a
    if [ "$1" = run ] && [ "$code" = 3 ]; then
      scene_re=$(basename -- "$2" | sed 's/\./\\./g')
      case "$pattern" in
        "$scene_re: "*)
          head="impactdeck: error: $2: "
          rest=${msg#"$head"}
          [ "$rest" != "$msg" ] || problems="$problems message does not begin with '$head';"
          printf '%s' "$rest" | grep -Eq "^(line [0-9]+|key '|--set |file: )" ||
            problems="$problems no line, key, override or 'file' after the scene's path;"
          ;;
      esac
    fi
  fi
  if [ "$code" = 4 ]; then
    [ -s "$out/report.html" ] || problems="$problems exit 4 without its evidence (no report.html);"
    [ -z "$(ls -A "$out" 2>/dev/null | grep '^\.')" ] || problems="$problems hidden files left: $(ls -A "$out");"
  else
    [ -z "$(ls -A "$out" 2>/dev/null)" ] || problems="$problems output folder not empty: $(ls -A "$out");"
  fi
  if [ -d "$deck" ]; then
    changed=$(diff -rq "$bad/fem/deck" "$deck" 2>&1)
    [ -z "$changed" ] || problems="$problems the deck folder changed: $changed;"
  fi
  if [ -n "$problems" ]; then
    echo "FAILED $name:$problems"
    echo "  message: $msg"
    fail=$((fail+1))
  else
    pass=$((pass+1))
  fi
  rm -rf "$out" "$out.d" "$out.stdout" "$out.stderr" "$out.fifo"
done <"$bad/cases.tsv"
echo "bad_inputs: $pass passed, $fail failed"
[ "$fail" -eq 0 ] && [ "$pass" -ge 1 ]
