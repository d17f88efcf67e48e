#!/usr/bin/env bash
# Evidence on failure (issue 32, item 3): a run whose physics self-check fails (exit 4) publishes
# its complete outputs — force tables, FEM deck, ccx's results, report.html — through the same
# transaction; the text report and report.html say FAILED first, naming each failed check;
# `--json` lists them in `failed_checks`; the one-line error names the check and where the
# evidence is. Invalid input (exit 3) still writes nothing.
# usage: cli_evidence_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
. "$src/tests/check_lib.sh"
no_staging() { [ -z "$(ls -A "$1" | grep '^\.impactdeck')" ]; }

# 1. The impulse check (Eq. 31) made to fail by an impossible limit: a run without FEM.
out=$tmp/imp
"$bin" run "$src/samples/two_spheres.toml" --set checks.impulse_relative=1e-99 --out "$out" >"$tmp/imp.txt" 2>"$tmp/imp.err"
rc=$?
check "impulse: exit 4 (got $rc)" [ "$rc" = 4 ]
check "impulse: one line on stderr" [ "$(wc -l <"$tmp/imp.err")" = 1 ]
check "impulse: the line names the check and its limit" \
  grep -Eq "^impactdeck: error: .*two_spheres\.toml: physics self-check failed; impact 'impact1': impulse check \(Eq\. 31\) failed: relative error [0-9.e+-]+ > limit 1e-99 \(\[checks\] impulse_relative\); its outputs were published in '$out' as evidence" "$tmp/imp.err"
for f in force_two_spheres.csv force_two_spheres.csv.json report.html; do
  check "impulse: $f published as evidence" [ -s "$out/$f" ]
done
check "impulse: no staging folder or journal left" no_staging "$out"
check "impactdeck's text report says FAILED first (line 2)" \
  grep -Eq "^FAILED: 1 self-check\(s\) failed" <(sed -n 2p "$tmp/imp.txt")
check "the text report names the check under FAILED" \
  grep -Eq "^  impact 'impact1': impulse check \(Eq\. 31\) failed" <(sed -n 3p "$tmp/imp.txt")
python3 - "$out/report.html" <<'PY' || { echo "FAILED: report.html says FAILED first"; fails=$((fails+1)); }
import re, sys
page = open(sys.argv[1], encoding="utf-8").read()
body = page[page.index("<body"):]
failed, verdict = body.find('<p id="failed"'), body.find('<p id="verdict"')
assert 0 <= failed < verdict, (failed, verdict)
# Nothing but the title before it.
between = re.sub(r"<h1>.*?</h1>", "", body[body.index(">") + 1:failed])
assert "<p" not in between and "<table" not in between, between
assert "FAILED: 1 self-check(s) failed" in body
assert "impulse check (Eq. 31) failed" in body
PY

# --json lists the failed checks (and stdout is the document alone).
out=$tmp/impj
"$bin" run "$src/samples/two_spheres.toml" --set checks.impulse_relative=1e-99 --out "$out" --json >"$tmp/imp.json" 2>/dev/null
check "impulse --json: exit 4" [ $? = 4 ]
python3 - "$tmp/imp.json" "$out" <<'PY' || { echo "FAILED: --json failed_checks"; fails=$((fails+1)); }
import json, sys
d = json.load(open(sys.argv[1]))
assert d["all_checks_passed"] is False
f = d["failed_checks"]
assert [c["name"] for c in f] == ["impulse"], f
c = f[0]
assert c["impact"] == "impact1" and c["limit"] == 1e-99 and c["value"] > c["limit"], c
assert "impulse check (Eq. 31)" in c["reason"] and "[checks] impulse_relative" in c["reason"], c
assert sorted(p.rsplit("/", 1)[1] for p in d["files_written"]) == ["force_two_spheres.csv", "force_two_spheres.csv.json", "report.html"], d["files_written"]  # the CSV's sidecar too
PY
"$bin" run "$src/samples/two_spheres.toml" --out "$tmp/ok" --json >"$tmp/ok.json" 2>/dev/null
check "a passing run: exit 0" [ $? = 0 ]
check "a passing run: failed_checks is empty" python3 -c 'import json,sys; assert json.load(open(sys.argv[1]))["failed_checks"] == []' "$tmp/ok.json"
check "a passing run: no FAILED in the report page" bash -c "! grep -q 'id=\"failed\"' '$tmp/ok/report.html'"

# 2. Invalid input (exit 3) still writes nothing.
"$bin" run "$src/samples/two_spheres.toml" --set 'materials.steel.poisson_ratio=0.7' --out "$tmp/bad" >/dev/null 2>"$tmp/bad.err"
check "invalid input: exit 3" [ $? = 3 ]
check "invalid input: nothing written" [ -z "$(ls -A "$tmp/bad" 2>/dev/null)" ]

# 3. A real FEM run whose FE body check fails (the volume tolerance set below what any mesh
# reaches): ccx still runs, and the deck, ccx's results and the report are published.
out=$tmp/fem
"$bin" run "$src/samples/eccentric_fem.toml" --set outputs.fem.volume_tolerance=1e-9 --out "$out" --json -q \
  >"$tmp/fem.json" 2>"$tmp/fem.err"
rc=$?
check "FE body: exit 4 (got $rc: $(head -c 300 "$tmp/fem.err"))" [ "$rc" = 4 ]
check "FE body: one line on stderr under -q" [ "$(wc -l <"$tmp/fem.err")" = 1 ]
check "FE body: the line names the check" \
  grep -q "FE body check of deck 'fem_eccentric' (FE volume against the part's) failed: relative error .* > limit 1e-09 (\[outputs.fem\] volume_tolerance)" "$tmp/fem.err"
for f in impact.inp mesh.inp deck.json impact.dat impact.frd; do
  check "FE body: fem_eccentric/$f published" [ -s "$out/fem_eccentric/$f" ]
done
check "FE body: report.html published" [ -s "$out/report.html" ]
check "FE body: no staging folder or journal left" no_staging "$out"
python3 - "$tmp/fem.json" "$out/report.html" <<'PY' || { echo "FAILED: FE body failed_checks"; fails=$((fails+1)); }
import json, sys
d = json.load(open(sys.argv[1]))
assert "fem_run" in d["stages_run"], d["stages_run"]
names = [c["name"] for c in d["failed_checks"]]
assert "fe_body_volume" in names, names
c = d["failed_checks"][names.index("fe_body_volume")]
assert c["limit"] == 1e-9 and c["value"] > 1e-9, c
assert d["impacts"][0]["fem"]["check"] is not None  # ccx ran on the failed body
page = open(sys.argv[2], encoding="utf-8").read()
assert page.find('id="failed"') < page.find('id="verdict"') and "fe_body_volume" in page
PY
finish cli_evidence_test
