#!/usr/bin/env bash
# The FEM samples through CalculiX: `run` writes and runs the decks, the momentum checks pass and
# are printed, `fem-check` re-runs ccx with the documented JSON keys and exit codes.
# usage: fem_samples_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
. "$(dirname "$0")/check_lib.sh"

# 1. The paper's Table 2 case, coarse and short: linear momentum <= 0.1 % (central hit).
"$bin" run "$src/samples/paper_table2_fem.toml" --json --out "$tmp/paper" >"$tmp/paper.json" 2>"$tmp/paper.err"
rc=$?
check "paper FEM sample exit 0 (got $rc: $(tail -3 "$tmp/paper.err"))" test $rc -eq 0
check "paper deck has the ccx and Code_Aster files" test -s "$tmp/paper/fem_table2/impact.inp" -a \
  -s "$tmp/paper/fem_table2/impact.comm" -a -s "$tmp/paper/fem_table2/mesh.med" -a -s "$tmp/paper/fem_table2/mesh.geo"
check "no ccx progress on a stderr that is not a terminal" test -z "$(grep -e "ccx \[" -e "^ccx: step" "$tmp/paper.err")"
python3 - "$tmp/paper.json" <<'PY' || { echo "FAILED: paper FEM JSON"; fails=$((fails+1)); }
import json, sys
d = json.load(open(sys.argv[1]))
f = d["impacts"][0]["fem"]
c = f["check"]
print("paper_table2_fem: %d nodes, %d tets, linear momentum relative error %.3e, ccx %.1f s"
      % (f["node_count"], f["tet_count"], c["linear_momentum_relative_error"], c["solver_wall_time_s"]))
assert c["linear_momentum_relative_error"] <= 1e-3, c
assert c["angular_momentum_relative_error"] is None  # central hit
for s in ("fem_mesh", "fem_decks", "fem_run"):
    assert s in d["stages_run"], d["stages_run"]
    assert d["stage_times_s"][s] >= 0, d["stage_times_s"]
PY

# 1b. The drop test (issue 12): a real part (CGAL's handle) dropped tilted on a steel floor, first
# contact, FEM deck through ccx: the checks pass, the contact lies on the risen floor, the part's
# spin is checked against the rigid model, and the stresses come back with a verdict.
"$bin" run "$src/samples/drop_test.toml" --json --out "$tmp/drop" >"$tmp/drop.json" 2>"$tmp/drop.err"
rc=$?
check "drop-test FEM sample exit 0 (got $rc: $(tail -3 "$tmp/drop.err"))" test $rc -eq 0
python3 - "$tmp/drop.json" <<'PY' || { echo "FAILED: drop-test FEM JSON"; fails=$((fails+1)); }
import json, sys
d = json.load(open(sys.argv[1]))
i = d["impacts"][0]
assert i["contact_mode"] == "first-contact"
# The floor travels along (-0.4, 0, 2)/|v| from z = 0 until it touches the handle.
rise = i["travel_m"] * 2 / (0.4 ** 2 + 2 ** 2) ** 0.5
assert abs(i["contact_point_m"][2] - rise) < 1e-9, (i["contact_point_m"], rise)
c = i["fem"]["check"]
print("drop_test_fem: linear momentum relative error %.3e, model velocity error %s, spin error %s, verdict %s"
      % (c["linear_momentum_relative_error"], c["model_linear_velocity_relative_error"],
         c["model_angular_velocity_relative_error"], c["stress"]["verdict"]["result"]))
assert c["passed"], c["failures"]
assert c["stress"]["verdict"]["result"] in ("survives", "yields")
PY

# 2. The eccentric hit: linear <= 0.1 %, angular <= 1 %.
"$bin" run "$src/samples/eccentric_fem.toml" --json --out "$tmp/ecc" >"$tmp/ecc.json" 2>"$tmp/ecc.err"
rc=$?
check "eccentric FEM sample exit 0 (got $rc: $(tail -3 "$tmp/ecc.err"))" test $rc -eq 0
python3 - "$tmp/ecc.json" <<'PY' || { echo "FAILED: eccentric FEM JSON"; fails=$((fails+1)); }
import json, sys
d = json.load(open(sys.argv[1]))
f = d["impacts"][0]["fem"]
c = f["check"]
print("eccentric_fem: %d nodes, %d tets, linear momentum relative error %.3e, angular momentum relative error %.3e, ccx %.1f s"
      % (f["node_count"], f["tet_count"], c["linear_momentum_relative_error"],
         c["angular_momentum_relative_error"], c["solver_wall_time_s"]))
assert c["linear_momentum_relative_error"] <= 1e-3, c
assert c["angular_momentum_relative_error"] <= 1e-2, c
assert c["passed"]
PY

# 3. fem-check re-runs ccx on the folder; JSON keys as documented.
"$bin" fem-check "$tmp/ecc/fem_eccentric" --json >"$tmp/fc.json" 2>"$tmp/fc.err"
rc=$?
check "fem-check exit 0 (got $rc: $(tail -3 "$tmp/fc.err"))" test $rc -eq 0
python3 - "$tmp/fc.json" <<'PY' || { echo "FAILED: fem-check JSON keys"; fails=$((fails+1)); }
import json, sys
c = json.load(open(sys.argv[1]))
for k in ("fe_mass_kg", "linear_momentum_relative_error", "angular_momentum_relative_error", "solver_wall_time_s", "probes"):
    assert k in c, k
assert len(c["probes"]) == 2
for p in c["probes"]:
    assert "mean_velocity_m_s" in p and "mean_velocity_scatter_m_s" in p, p
assert c["solver_wall_time_s"] > 0
assert 14000 < c["fe_mass_kg"] < 16500, c["fe_mass_kg"]
PY

# 4. Exit 4 above a threshold; exit 3 for a folder that is not a deck.
"$bin" fem-check "$tmp/ecc/fem_eccentric" --no-run --linear-tolerance 1e-12 >/dev/null 2>"$tmp/e4.err"
check "tight tolerance -> exit 4" test $? -eq 4
# A failed check after a ccx run publishes ccx's results in the deck folder: the evidence (issue 32).
cp -r "$tmp/ecc/fem_eccentric" "$tmp/evidence"
rm -f "$tmp/evidence"/impact.{dat,frd,log,sta,cvg}
"$bin" fem-check "$tmp/evidence" --linear-tolerance 1e-12 >"$tmp/ev.out" 2>"$tmp/ev.err"
check "ccx run, tight tolerance -> exit 4" test $? -eq 4
check "exit 4: impact.dat and impact.frd published as evidence" test -s "$tmp/evidence/impact.dat" -a -s "$tmp/evidence/impact.frd"
check "exit 4: the line says the results are published" grep -q "FEM check failed: linear momentum .*results are published in the deck folder" "$tmp/ev.err"
check "exit 4: the report printed" test -s "$tmp/ev.out"
check "exit 4: nothing hidden left" bash -c "! ls -A '$tmp/evidence' | grep -q '^\\.'"
# stdout is written before the results are published: a broken pipe then leaves the folder as it was.
cp -r "$tmp/ecc/fem_eccentric" "$tmp/pipe"
rm -f "$tmp/pipe"/impact.{dat,frd,log,sta,cvg}
before=$(ls -A "$tmp/pipe")
python3 - "$bin" "$tmp/pipe" "$tmp/pipe.rc" <<'PY'
import os, signal, subprocess, sys
binary, deck, rc = sys.argv[1:]
r, w = os.pipe()
os.close(r)  # the reader is gone before the check starts
p = subprocess.run([binary, "fem-check", deck, "--json"], stdout=w, stderr=subprocess.DEVNULL,
                   stdin=subprocess.DEVNULL, preexec_fn=lambda: signal.signal(signal.SIGPIPE, signal.SIG_IGN))
open(rc, "w").write(str(p.returncode))
PY
check "fem-check > a broken pipe: exit 3 (got $(cat "$tmp/pipe.rc"))" [ "$(cat "$tmp/pipe.rc")" = 3 ]
check "fem-check > a broken pipe: the deck folder as before" [ "$(ls -A "$tmp/pipe")" = "$before" ]
"$bin" fem-check "$tmp/nowhere" >/dev/null 2>"$tmp/e3.err"
check "missing deck folder -> exit 3" test $? -eq 3
check "missing deck folder message" grep -q "nowhere: deck folder: does not exist" "$tmp/e3.err"

# A deck ccx rejects: exit 3 quoting ccx's first *ERROR line.
cp -r "$tmp/ecc/fem_eccentric" "$tmp/broken"
sed -i '/^\*SOLID SECTION/d' "$tmp/broken/impact.inp"
"$bin" fem-check "$tmp/broken" >/dev/null 2>"$tmp/broken.err"
check "ccx error -> exit 3" test $? -eq 3
check "ccx error quoted" grep -q "ccx failed (exit code [0-9]*): .*ERROR in calinput: no material was assigned" "$tmp/broken.err"

# 5. Nothing of this runs unless asked: no [outputs.fem] -> no meshing, stages skipped.
"$bin" run "$src/samples/paper_table2.toml" --json --out "$tmp/plain" >"$tmp/plain.json" 2>/dev/null
check "no FEM folder without [outputs.fem]" test ! -e "$tmp/plain/fem_table2"
python3 - "$tmp/plain.json" <<'PY' || { echo "FAILED: FEM stages skipped"; fails=$((fails+1)); }
import json, sys
d = json.load(open(sys.argv[1]))
for s in ("fem_mesh", "fem_decks", "fem_run"):
    assert s in d["stages_skipped"], d["stages_skipped"]
assert "fem" not in d["impacts"][0]
PY

# 6. Bad [outputs.fem] input: one-line errors naming file, line and key; exit 3; no folder.
sed -e 's/^run = "calculix".*/run = "calculix"\nmesh_sise = 300/' "$src/samples/paper_table2_fem.toml" >"$tmp/typo.toml"
"$bin" run "$tmp/typo.toml" --out "$tmp/typo" >/dev/null 2>"$tmp/typo.err"
check "unknown key -> exit 3" test $? -eq 3
check "unknown key message" grep -q "key 'outputs.fem.mesh_sise': unknown key" "$tmp/typo.err"
sed -e 's/^calculix = true/calculix = false/' "$src/samples/paper_table2_fem.toml" >"$tmp/nocx.toml"
"$bin" run "$tmp/nocx.toml" --out "$tmp/nocx" >/dev/null 2>"$tmp/nocx.err"
check "run without calculix deck -> exit 3" test $? -eq 3
check "run without calculix message" grep -q "outputs.fem.run" "$tmp/nocx.err"
sed -e 's/^probes = .*/probes = [[0, 600, 0]]/' -e 's/^run = "calculix".*/run = "none"/' "$src/samples/paper_table2_fem.toml" >"$tmp/probe.toml"
"$bin" run "$tmp/probe.toml" --out "$tmp/probe" >/dev/null 2>"$tmp/probe.err"
check "probe outside -> exit 3" test $? -eq 3
check "probe outside message" grep -q "probe.toml: line [0-9]*, key 'outputs.fem': impact 'table2': FEM deck: .*fem_table2/mesh.geo: PROBE1: probe point is not inside the ellipsoid" "$tmp/probe.err"
check "no deck after a failure" test ! -e "$tmp/probe/fem_table2"

finish fem_samples_test
