#!/usr/bin/env bash
# The drop-sequence sample with FEM (docs/sequences.md, "FEM"): a real part dropped through its
# bounces; its worst impact gets the single impact's deck, ccx run and verdict, and only it.
# usage: sequence_sample_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
. "$(dirname "$0")/check_lib.sh"

"$bin" run "$src/samples/drop_sequence_part.toml" --json --out "$tmp/out" >"$tmp/run.json" 2>"$tmp/run.err"
rc=$?
check "sample exit 0 (got $rc: $(tail -3 "$tmp/run.err"))" test $rc -eq 0
python3 - "$tmp/run.json" "$tmp/out" <<'PY' || { echo "FAILED: sequence sample JSON"; fails=$((fails+1)); }
import json, os, sys
d = json.load(open(sys.argv[1]))
out = sys.argv[2]
q = d["sequences"][0]
w = q["worst_impact_index"]
impacts = q["impacts"]
assert w is not None and impacts[w]["force_applicable"], q["worst_impact_reason"]
f0, fw = impacts[0]["max_force_N"], impacts[w]["max_force_N"]
fem = q["fem"]
assert fem["mode"] == "worst", fem
assert [k["index"] for k in fem["decks"]] == [w], fem
deck = fem["decks"][0]
folder = os.path.join(out, "sequence_drop_impact_%d" % w)
assert deck["folder"] == folder and os.path.isfile(os.path.join(folder, "impact.inp")), deck
assert deck["worst"] and deck["checks_passed"], deck
assert deck["verdict"] in ("survives", "yields"), deck
# The deck's record is the single impact's (impacts[w].fem), with ccx's check.
check = impacts[w]["fem"]["check"]
assert check["passed"], check["failures"]
assert check["stress"]["verdict"]["result"] == deck["verdict"]
for i, imp in enumerate(impacts):
    assert ("fem" in imp) == (i == w), i
    assert not os.path.exists(os.path.join(out, "sequence_drop_impact_%d" % i)) or i == w, i
for s in ("sequence", "force_table", "fem_mesh", "fem_decks", "fem_run"):
    assert s in d["stages_run"], d["stages_run"]
assert d["all_checks_passed"], d["failed_checks"]
page = open(os.path.join(out, "report.html"), encoding="utf-8").read()
assert 'class="sequence-verdict"' in page and ("Worst impact %d: %s" % (w, deck["verdict"])) in page
print("drop_sequence_part: %d impacts, worst %d (%s): F_max %.1f N against the first impact's %.1f N (x %.2f); "
      "deck %d nodes, %s, safety factor %.2f, ccx %.1f s"
      % (len(impacts), w, impacts[w]["contact_law"], fw, f0, fw / f0, impacts[w]["fem"]["node_count"],
         deck["verdict"], deck["safety_factor"], check["solver_wall_time_s"]))
PY
finish sequence_sample
