#!/usr/bin/env bash
# The CLI's conventions (docs/cli.md, "Conventions"): "did you mean", -q/-v and -o/--out on every
# command, the generated man page and bash completion, plain CSVs with a JSON sidecar, and every
# document the help names present in the repository.
# usage: cli_conventions_test.sh IMPACTDECK SOURCE_DIR PYTHON3 [MAN_PAGE COMPLETION]
set -u
bin=$1; src=$2; py=$3; man_page=${4:-}; completion=${5:-}
. "$(dirname "$0")/check_lib.sh"

# refused CODE NAME PATTERN ARGS...: exit CODE, one stderr line matching PATTERN.
refused() {
  local code=$1 name=$2 pattern=$3; shift 3
  "$bin" "$@" >"$tmp/u.out" 2>"$tmp/u.err"
  local rc=$?
  check "$name: exit $code" test "$rc" -eq "$code"
  check "$name: one line" test "$(wc -l <"$tmp/u.err")" -eq 1
  check "$name: '$pattern'" grep -Eq -- "$pattern" "$tmp/u.err"
}
usage_error() { refused 2 "$@"; }  # usage_error NAME PATTERN ARGS...
input_error() { refused 3 "$@"; }  # input_error NAME PATTERN ARGS...

# 1. Did you mean: subcommands, flags, scene keys, enum values.
usage_error "subcommand rnu" "did you mean 'run'\?" rnu samples.toml
usage_error "nested subcommand tabel1" "did you mean 'table1'\?" study tabel1
usage_error "campaign subcommand colect" "did you mean 'collect'\?" campaign colect dir
usage_error "flag --jsn" "did you mean '--json'\?" run "$src/samples/two_spheres.toml" --jsn
usage_error "flag before the positional" "did you mean '--length-unit'\?" inspect --lenght-unit mm x.stl
usage_error "flag with =" "did you mean '--grid-steps'\?" sweep "$src/samples/fig4_sweep.toml" --grid-step=4
usage_error "enum --cloud" "did you mean 'grid'\?" sweep "$src/samples/fig4_sweep.toml" --cloud gird --out "$tmp/x"
usage_error "enum --radius-rule" "did you mean 'elliptical'\?" study table1 --radius-rule eliptical --out "$tmp/x"
usage_error "enum --formats" "did you mean 'svg'\?" sweep "$src/samples/fig4_sweep.toml" --formats csv,svh --out "$tmp/x"
usage_error "enum --length-unit" "did you mean 'in'\?" inspect "$src/samples/parts/cgal_handle.off" --length-unit inch
usage_error "nothing near: no suggestion" "^impactdeck: usage error: [^;]*$" xyzzy-frobnicate
sed 's/^mesh_size *=/mesh_sise =/' "$src/samples/eccentric_fem.toml" >"$tmp/typo_key.toml"
check "the typo is in the scene" grep -q "^mesh_sise =" "$tmp/typo_key.toml"
input_error "scene key mesh_sise" "key 'outputs\.fem\.mesh_sise': unknown key \(allowed here: .*\); did you mean 'mesh_size'\?" \
  run "$tmp/typo_key.toml" --out "$tmp/typo_out"
check "a refused scene writes nothing" test ! -e "$tmp/typo_out/fem_impact"
sed 's/contact_radius = "[a-z]*"/contact_radius = "eliptical"/' "$src/samples/two_spheres.toml" >"$tmp/typo_value.toml"
grep -q eliptical "$tmp/typo_value.toml" || sed -i 's/^\(\[\[impacts\]\]\)$/\1\ncontact_radius = "eliptical"/' "$tmp/typo_value.toml"
input_error "scene value eliptical" "unknown value \"eliptical\" .*; did you mean 'elliptical'\?" run "$tmp/typo_value.toml" --out "$tmp/typo_out"
input_error "--preset" "unknown preset \"papr\" .*; did you mean 'paper'\?" study table1 --preset papr --out "$tmp/x"
input_error "--impact name" "did you mean 'fig4'\?" sweep "$src/samples/fig4_sweep.toml" --impact fig5 --out "$tmp/x"

# 2. -q / -v and -o / --out on every command. Each runnable command's help lists them.
cmds=(run sweep inspect mesh-ellipsoid fem-check compare-contact "study table1" "campaign plan" "campaign run"
      "campaign run-case" "campaign status" "campaign cancel" "campaign collect")
for c in "${cmds[@]}"; do
  "$bin" $c --help >"$tmp/h.txt" 2>&1
  check "'$c --help' lists -q,--quiet" grep -Eq -- "-q,--quiet" "$tmp/h.txt"
  check "'$c --help' lists -v,--verbose" grep -Eq -- "-v,--verbose" "$tmp/h.txt"
done
for c in run sweep mesh-ellipsoid compare-contact "study table1" "campaign plan"; do
  "$bin" $c --help >"$tmp/h.txt" 2>&1
  check "'$c' (writes files) takes -o,--out" grep -Eq -- "-o,--out" "$tmp/h.txt"
done
"$bin" mesh-ellipsoid --help >"$tmp/h.txt"
check "mesh-ellipsoid keeps --output" grep -q -- "--output" "$tmp/h.txt"
usage_error "-q and -v exclude each other" "excludes" mesh-ellipsoid 1 1 1 -o "$tmp/e.stl" -q -v

# quiet: nothing on stderr (the warning of the paper sample stays in --json); verbose: stage times.
"$bin" run "$src/samples/paper_table2.toml" --json -o "$tmp/q" -q >"$tmp/q.json" 2>"$tmp/q.err"
check "run -q: exit 0" test $? -eq 0
check "run -q: stderr empty" test ! -s "$tmp/q.err"
check "run -q: the warning is still in the JSON" grep -q "outside the validity range" "$tmp/q.json"
"$bin" run "$src/samples/paper_table2.toml" --json -o "$tmp/q" >/dev/null 2>"$tmp/n.err"
check "run without -q: the warning on stderr" grep -q "impactdeck: warning:" "$tmp/n.err"
"$bin" run "$src/samples/paper_table2.toml" -o "$tmp/v" -v >/dev/null 2>"$tmp/v.err"
check "run -v: a line per stage" grep -Eq "^impactdeck: run: stage impact: [0-9.e-]+ s$" "$tmp/v.err"
"$bin" mesh-ellipsoid 2 1 1 --subdivisions 1 -o "$tmp/e.stl" -v >/dev/null 2>"$tmp/me.err"
check "mesh-ellipsoid -o: file written" test -s "$tmp/e.stl"
check "mesh-ellipsoid -v: its time" grep -Eq "^impactdeck: mesh-ellipsoid: mesh and write: [0-9.e-]+ s$" "$tmp/me.err"
"$bin" mesh-ellipsoid 2 1 1 --subdivisions 1 --out "$tmp/e2.stl" -q >/dev/null 2>"$tmp/me.err"
check "mesh-ellipsoid --out: file written" test -s "$tmp/e2.stl"
check "mesh-ellipsoid -q: stderr empty" test ! -s "$tmp/me.err"

# -q prints nothing but errors: no report on stdout either; --json (data asked for) stays.
"$bin" run "$src/samples/paper_table2.toml" -o "$tmp/q2" -q >"$tmp/q2.out" 2>"$tmp/q2.err"
check "run -q: exit 0" test $? -eq 0
check "run -q: stdout empty (no report)" test ! -s "$tmp/q2.out"
check "run -q: stderr empty" test ! -s "$tmp/q2.err"
check "run -q: the files written" test -s "$tmp/q2/force_table2.csv"
"$bin" run "$src/samples/paper_table2.toml" -o "$tmp/q2c" -q >&- 2>"$tmp/q2c.err"
check "run -q with stdout closed: exit 0 (nothing to print)" test $? -eq 0
check "run -q with stdout closed: the files written" test -s "$tmp/q2c/force_table2.csv"
"$bin" run "$src/samples/paper_table2.toml" -o "$tmp/q3" >"$tmp/q3.out" 2>/dev/null
check "run without -q: the report on stdout" grep -q "^impact 'table2'" "$tmp/q3.out"
"$bin" mesh-ellipsoid 2 1 1 --subdivisions 1 -o "$tmp/e3.stl" -q >"$tmp/me.out" 2>/dev/null
check "mesh-ellipsoid -q: stdout empty" test ! -s "$tmp/me.out"
"$bin" run "$src/samples/two_spheres.toml" -o "$tmp/q4" -q --set checks.impulse_relative=1e-99 >"$tmp/q4.out" 2>"$tmp/q4.err"
check "run -q, a failed check: exit 4" test $? -eq 4
check "run -q, a failed check: stdout empty" test ! -s "$tmp/q4.out"
check "run -q, a failed check: one stderr line naming the check" \
  bash -c "[ \$(wc -l <'$tmp/q4.err') = 1 ] && grep -q 'impulse check (Eq. 31) failed' '$tmp/q4.err'"
"$bin" campaign status "$tmp/nowhere" -q >"$tmp/q5.out" 2>"$tmp/q5.err"
check "campaign status -q of a missing folder: the error still shown" test -s "$tmp/q5.err"

# `-`: the scene from stdin, --json - and -o - to stdout (a single file only).
"$bin" run - -o "$tmp/stdin" --json <"$src/samples/two_spheres.toml" >"$tmp/stdin.json" 2>"$tmp/stdin.err"
check "run - (scene on stdin): exit 0 ($(head -c 200 "$tmp/stdin.err"))" test $? -eq 0
check "run -: the scene is named '-'" python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["scene"] == "-", d["scene"]' "$tmp/stdin.json"
check "run -: its outputs written" test -s "$tmp/stdin/force_two_spheres.csv"
check "run -: the same numbers as the file" python3 -c '
import json, subprocess, sys
a = json.load(open(sys.argv[1]))["impacts"][0]["max_force_N"]
b = json.loads(subprocess.run([sys.argv[2], "run", sys.argv[3], "--json", "-o", sys.argv[4]], capture_output=True).stdout)["impacts"][0]["max_force_N"]
assert a == b, (a, b)' "$tmp/stdin.json" "$bin" "$src/samples/two_spheres.toml" "$tmp/stdin_file"
(cd "$src/samples" && "$bin" run - -o "$tmp/stdin_parts" -q <two_parts.toml 2>"$tmp/parts.err")
check "run -: a relative part path resolves against the current folder" test $? -eq 0
(cd "$tmp" && "$bin" run - -o "$tmp/stdin_parts2" -q <"$src/samples/two_parts.toml" 2>"$tmp/parts2.err")
check "run - elsewhere: the part is looked up in the current folder (exit 3)" test $? -eq 3
check "run - elsewhere: the message names the part as given" grep -q "parts/cgal_handle.off" "$tmp/parts2.err"
sed 's/^poisson_ratio = 0.3$/poisson_ratio = 0.7/' "$src/samples/two_spheres.toml" | "$bin" run - -o "$tmp/stdin_bad" >/dev/null 2>"$tmp/stdin_bad.err"
check "run - with a bad value: exit 3" test $? -eq 3
check "run - with a bad value: the message names '-', the line and the key" grep -Eq "^impactdeck: error: -: line 11, key 'materials.steel.poisson_ratio'" "$tmp/stdin_bad.err"
check "run - with a bad value: nothing written" test ! -e "$tmp/stdin_bad"
head -c 17000000 /dev/zero | "$bin" run - -o "$tmp/stdin_big" >/dev/null 2>"$tmp/stdin_big.err"
check "run - beyond the scene limit: exit 3" test $? -eq 3
check "run - beyond the scene limit: says so" grep -q "^impactdeck: error: -: stdin: the scene on stdin is longer than the limit of 16 MiB" "$tmp/stdin_big.err"
check "run - beyond the scene limit: nothing written" test ! -e "$tmp/stdin_big"
for form in "--json - $src/samples/two_spheres.toml" "$src/samples/two_spheres.toml --json -" "$src/samples/two_spheres.toml --json=-"; do
  # shellcheck disable=SC2086
  "$bin" run $form -o "$tmp/jd" >"$tmp/jd.json" 2>/dev/null
  check "run $form: exit 0, the JSON on stdout" python3 -c 'import json,sys; json.load(open(sys.argv[1]))["impacts"]' "$tmp/jd.json"
done
check "--json -: no file named '-'" test ! -e ./- -a ! -e "$tmp/jd/-"
(cd "$tmp" && "$bin" mesh-ellipsoid 2 1 1 --subdivisions 1 -o - >"$tmp/stdout.stl" 2>"$tmp/stdout.err")
check "mesh-ellipsoid -o -: exit 0" test $? -eq 0
check "mesh-ellipsoid -o -: no file named '-'" test ! -e "$tmp/-"
check "mesh-ellipsoid -o -: stdout is the binary STL alone (84 + 50 x 80 triangles bytes)" test "$(stat -c %s "$tmp/stdout.stl")" -eq 4084
"$bin" mesh-ellipsoid 2 1 1 --subdivisions 1 -o "$tmp/file.stl" -q
check "mesh-ellipsoid -o -: the same bytes as -o FILE" cmp -s "$tmp/stdout.stl" "$tmp/file.stl"
(cd "$tmp" && "$bin" mesh-ellipsoid 2 1 1 --subdivisions 1 --ascii -o - >"$tmp/stdout_ascii.stl")
check "mesh-ellipsoid --ascii -o -: an ASCII STL on stdout" bash -c "head -1 '$tmp/stdout_ascii.stl' | grep -q '^solid ellipsoid' && tail -1 '$tmp/stdout_ascii.stl' | grep -q '^endsolid'"
"$bin" man -o - >"$tmp/man_stdout.1"
check "man -o -: the page on stdout" grep -q "EXIT STATUS" "$tmp/man_stdout.1"
for c in "run $src/samples/two_spheres.toml" "sweep $src/samples/fig4_sweep.toml" "study table1" "compare-contact $src/samples/two_spheres.toml" "campaign plan $src/samples/point_campaign.toml"; do
  # shellcheck disable=SC2086
  (cd "$tmp" && "$bin" $c -o - >"$tmp/dash.out" 2>"$tmp/dash.err")
  rc=$?
  check "$c -o -: usage error (exit 2, got $rc), a folder is not stdout" bash -c "[ $rc = 2 ] && grep -q \"writes a folder of files, not one file\" '$tmp/dash.err'"
  check "$c -o -: no folder named '-'" test ! -e "$tmp/-"
done

# 3. The man page: renders without warnings, names every subcommand and flag.
"$bin" man >"$tmp/impactdeck.1"
check "man: exit 0" test $? -eq 0
[ -n "$man_page" ] && check "the built man page is the command's" cmp -s "$man_page" "$tmp/impactdeck.1"
groff -man -Tutf8 -ww -z "$tmp/impactdeck.1" 2>"$tmp/groff.err"
check "groff renders the man page" test $? -eq 0
check "groff: no warnings" test ! -s "$tmp/groff.err"
MANWIDTH=200 man -l "$tmp/impactdeck.1" 2>"$tmp/man.err" | col -b >"$tmp/man.txt"
check "man -l: no warnings" test ! -s "$tmp/man.err"
# Every subcommand and flag of every --help is in the rendered page.
for c in "${cmds[@]}" study campaign; do
  check "man lists 'impactdeck $c'" grep -q "impactdeck $c" "$tmp/man.txt"
  for f in $("$bin" $c --help | grep -Eo -- '(^|[ ,])--?[a-zA-Z][a-zA-Z0-9-]*' | tr -d ' ,' | sort -u); do
    check "man lists '$c $f'" grep -q -- "$f" "$tmp/man.txt"
  done
done
check "man has the exit codes" grep -q "EXIT STATUS" "$tmp/man.txt"

# 4. The bash completion: subcommands, nested subcommands and flags.
"$bin" completion bash >"$tmp/impactdeck.bash"
[ -n "$completion" ] && check "the built completion is the command's" cmp -s "$completion" "$tmp/impactdeck.bash"
complete_words() {  # complete_words WORD...: what TAB offers after `impactdeck WORD...` (the last word is the prefix)
  bash -c '. "$1"; shift; COMP_WORDS=(impactdeck "$@"); COMP_CWORD=$#; _impactdeck; printf "%s\n" "${COMPREPLY[@]}"' \
    complete_words "$tmp/impactdeck.bash" "$@"
}
check "complete -p registers impactdeck" bash -c ". '$tmp/impactdeck.bash'; complete -p impactdeck | grep -q _impactdeck"
check "'impactdeck r' completes run" bash -c "[ \"\$(printf '%s' \"$(complete_words r)\")\" = run ]"
check "'impactdeck ' offers every subcommand" bash -c "for s in run sweep study inspect mesh-ellipsoid fem-check compare-contact campaign; do printf '%s\n' \"$(complete_words '')\" | grep -qx \$s || exit 1; done"
check "'impactdeck ' hides man and completion" bash -c "! printf '%s\n' \"$(complete_words '')\" | grep -qx 'man\|completion'"
check "'impactdeck study t' completes table1" bash -c "[ \"$(complete_words study t)\" = table1 ]"
check "'impactdeck campaign co' completes collect" bash -c "[ \"$(complete_words campaign co)\" = collect ]"
check "'impactdeck campaign ca' completes cancel" bash -c "[ \"$(complete_words campaign ca)\" = cancel ]"
check "'impactdeck run x --js' completes --json" bash -c "[ \"$(complete_words run x.toml --js)\" = --json ]"
check "'impactdeck sweep --qu' completes --quiet" bash -c "[ \"$(complete_words sweep --qu)\" = --quiet ]"
check "'impactdeck study table1 --sc' completes --scene" bash -c "[ \"$(complete_words study table1 --sc)\" = --scene ]"
check "'impactdeck inspect --length' completes --length-unit" bash -c "[ \"$(complete_words inspect --length)\" = --length-unit ]"
check "a file argument: left to the shell's file completion" bash -c "[ -z \"$(complete_words run sam)\" ]"

# 5. CSVs: a plain header and rows (Python's csv and numpy.loadtxt(skiprows=1)), the metadata and
# every column's unit in FILE.csv.json.
"$bin" run "$src/samples/paper_table2.toml" -o "$tmp/csv_run" -q >/dev/null
"$bin" sweep "$src/samples/fig4_sweep.toml" --grid-steps 2 --curves --curve-samples 5 --formats csv -o "$tmp/csv_sweep" -q >/dev/null
"$bin" study table1 --geometric-ratios 1,2 --mass-ratios 1,2 --grid-steps 2 --no-png -o "$tmp/csv_t1" -q >/dev/null
"$bin" run "$src/samples/eccentric_fem.toml" -o "$tmp/csv_fem" -q >/dev/null
csvs=$(find "$tmp/csv_run" "$tmp/csv_sweep" "$tmp/csv_t1" "$tmp/csv_fem" -name '*.csv' | sort)
check "CSVs of run, sweep (with curves), study table1 and a deck" test "$(printf '%s\n' $csvs | wc -l)" -ge 5
"$py" - $csvs <<'PY'
import csv, json, sys
import numpy
bad = []
for path in sys.argv[1:]:
    text = open(path).read()
    if "#" in text.splitlines()[0] or any(l.startswith("#") for l in text.splitlines()):
        bad.append(path + ": a comment line")
    rows = list(csv.reader(open(path)))
    header = rows[0]
    if len(rows) < 2 or any(len(r) != len(header) for r in rows[1:]):
        bad.append(path + ": ragged rows")
    numeric = [i for i, name in enumerate(header) if name != "flag"]
    data = numpy.loadtxt(path, delimiter=",", skiprows=1, usecols=numeric, ndmin=2)
    if data.shape[0] != len(rows) - 1 or not numpy.isfinite(data).all():
        bad.append(path + ": numpy.loadtxt")
    side = json.load(open(path + ".json"))
    if [c["name"] for c in side["columns"]] != header:
        bad.append(path + ": sidecar columns differ from the header")
    units = {c["name"]: c["unit"] for c in side["columns"]}
    for name, unit in (("time_s", "s"), ("force_N", "N"), ("x_m", "m"), ("max_force_N", "N"),
                       ("target_dvx_m_s", "m/s"), ("geometric_ratio", "1")):
        if name in units and units[name] != unit:
            bad.append(path + ": unit of " + name + " is " + units[name])
    if "impactdeck_version" not in side or side["file"] + ".json" != path.rsplit("/", 1)[1] + ".json":
        bad.append(path + ": sidecar keys")
print("\n".join(bad))
sys.exit(1 if bad else 0)
PY
check "every CSV reads with csv and numpy; sidecars give every column's unit" test $? -eq 0

# 6. Every document a --help names exists in the repository.
for c in "" "${cmds[@]}" study campaign; do
  for doc in $("$bin" $c --help | grep -Eo '[A-Za-z0-9_/.-]*[A-Za-z0-9_-]\.md' | sort -u); do
    case "$doc" in
      docs/*) check "'$c --help' names $doc: exists" test -f "$src/$doc" ;;
      */*) check "'$c --help' names $doc: a docs/ path" false ;;
      *) check "'$c --help' names $doc: in docs/ or the top folder" test -f "$src/docs/$doc" -o -f "$src/$doc" ;;
    esac
  done
done

finish cli_conventions
