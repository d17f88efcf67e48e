#!/usr/bin/env bash
# Issue 18 item 6: `run`'s report.html, rendered by headless Chromium (Debian's `chromium`):
# the page loads with no console message and no blocked resource, has the verdict, the inputs,
# the checks and the F(t) picture, and shows names carrying HTML (<script>, an <img onerror>, an
# attribute breaker) as text. The detector itself is checked on a page that does log an error.
# Skips (exit 77) only when chromium is not installed; scripts/test installs it.
# usage: report_html_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
command -v chromium >/dev/null 2>&1 || { echo "chromium is not installed: skipped"; exit 77; }
. "$(dirname "$0")/check_lib.sh"
. "$(dirname "$0")/page_height.sh"

# render FILE OUT: the DOM after loading (stdout) and Chromium's log (stderr, console included).
render() {
  timeout 60 chromium --headless --disable-gpu --no-sandbox --no-first-run --user-data-dir="$tmp/profile" \
    --enable-logging=stderr --v=0 --virtual-time-budget=3000 --dump-dom "file://$1" >"$2.dom" 2>"$2.log"
}
# Console messages (any level) and resources the page's policy refused.
console_errors() { grep -E "CONSOLE|Refused to|Uncaught" "$1.log"; }
no_console_errors() { ! console_errors "$1" || { echo "console messages of $1:"; false; }; }

# The detector sees an error when there is one.
cat >"$tmp/broken.html" <<'HTML'
<!DOCTYPE html><html><head><title>t</title></head><body><script>console.error("boom"); undefined_fn();</script></body></html>
HTML
render "$tmp/broken.html" "$tmp/broken"
check "chromium ran" test -s "$tmp/broken.dom"
check "the detector sees a console error" console_errors "$tmp/broken"

"$bin" run "$src/tests/data/report/injected_names.toml" --json --out "$tmp/out" >"$tmp/run.json" 2>"$tmp/run.err"
check "run exit 0" test $? -eq 0
check "report.html written" test -s "$tmp/out/report.html"
check "report.html in files_written" python3 -c "
import json, sys; d = json.load(open('$tmp/run.json'))
assert any(f.endswith('/report.html') for f in d['files_written']), d['files_written']"
render "$tmp/out/report.html" "$tmp/page"
check "page rendered" test -s "$tmp/page.dom"
check "no console message" no_console_errors "$tmp/page"
python3 - "$tmp/page.dom" "$tmp/out/report.html" <<'PY' || { echo "FAILED: page content"; fails=$((fails+1)); }
import re, sys
dom = open(sys.argv[1]).read(); page = open(sys.argv[2]).read()
# The verdict, from the Hertz peak pressure against the yield onset (no FEM in this scene).
m = re.search(r'<p id="verdict"[^>]*>([^<]*)</p>', dom)
assert m and m.group(1).startswith("Verdict: survives (smallest safety factor "), m and m.group(1)
# Inputs, checks and the picture.
for text in ["Eq. 31", "Eq. 32", "Materials", "Bodies", "Validity warnings", "output length unit", "force.csv"]:
    assert text in dom, text
assert dom.count("<svg") >= 1, "no inline F(t) picture"
# No script anywhere (the page's own markup has none), no element or attribute from a name.
assert "<script" not in dom.lower() and "<script" not in page.lower()
assert not re.search(r"<img[^>]*src=\"?x", dom), "an injected img element"
assert not re.search(r"<[^>]* onmouseover=", dom), "an injected attribute"
assert "&lt;script&gt;document.title='pwned'&lt;/script&gt;" in dom or \
       "&lt;script&gt;document.title=&#39;pwned&#39;&lt;/script&gt;" in dom, "the name is not shown as text"
assert "<title>impactdeck run: injected_names.toml</title>" in dom, "title changed"
# Self-contained: pictures are data: URIs, links are relative (to the files beside the page).
assert not re.search(r'src="(?!data:)', page), "an external resource"
assert not re.search(r'href="(?![A-Za-z0-9_.~%-])|href="[^"]*:', page), "a link out of the output folder"
PY

# Issue 32 item 1: a report an analyst hands on, on the drop test (a real part, ccx's stresses).
"$bin" run "$src/samples/drop_test.toml" --json --out "$tmp/drop" >"$tmp/drop.json" 2>"$tmp/drop.err"
check "drop run exit 0" test $? -eq 0
render "$tmp/drop/report.html" "$tmp/drop_page"
check "drop page rendered" test -s "$tmp/drop_page.dom"
check "no console message (drop)" no_console_errors "$tmp/drop_page"
height=$(page_height "$tmp/drop/report.html")
echo "drop test page: ${height:-?} px tall at 1200 px"
check "drop page height measured" test "${height:-0}" -gt 0
python3 - "$tmp/drop_page.dom" "$tmp/drop/report.html" "$tmp/drop.json" "$tmp/drop" "$src/samples/drop_test.toml" <<'PY' || { echo "FAILED: drop page content"; fails=$((fails+1)); }
import hashlib, html, json, os, re, sys
dom = open(sys.argv[1]).read(); page = open(sys.argv[2]).read(); run = json.load(open(sys.argv[3]))
out = sys.argv[4]
# The verdict first (right under the title), with its governing number: the stress, where, when.
body = dom[dom.index("<body>"):]
first = re.search(r"<h1>[^<]*</h1>\s*(<[a-z0-9]+[^>]*>)", body)
assert first and 'id="verdict"' in first.group(1), first and first.group(1)
sf = run["impacts"][0]["fem"]["check"]["stress"]["verdict"]["safety_factor"]
assert re.search(r'<p id="verdict"[^>]*>Verdict: survives \(smallest safety factor %s\)</p>' % re.escape("%.4g" % sf), dom), ("verdict", sf)
m = re.search(r'<p id="governing"[^>]*>([^<]*)</p>', dom)
assert m and re.search(r"peak von Mises \d+(\.\d)? MPa outside the contact zone, at \([^)]*\) mm", m.group(1)), m and m.group(1)
# Each warning once, every warning of the run shown.
shown = [html.unescape(w) for w in re.findall(r'<p class="warning">([^<]*)</p>', dom)]
assert len(shown) == len(set(shown)), "a warning shown twice"
assert run["warnings"] and set(run["warnings"]) <= set(shown), (run["warnings"], shown)
validity = [w for i in run["impacts"] for w in i["validity"]["warnings"]]
assert validity and all(sum(w in p for p in shown) == 1 for w in validity), ("a validity warning not shown once", shown)
# The part: four views drawn from its triangles, the contact point, the floor.
fig = re.search(r'<figure class="part-drawing" id="part-drawing-0">(.*?)</figure>', dom, re.S)
assert fig and "<svg" in fig.group(1) and fig.group(1).count("<polygon") >= 200, "no part drawing"
for label in ["front: x right, z up", "side: y right, z up", "top: x right, y up", "isometric", "contact point", "floor"]:
    assert label in fig.group(1), label
# The stress field at its peak, coloured, with its unit.
fig = re.search(r'<figure class="stress-field" id="stress-field-0">(.*?)</figure>', dom, re.S)
assert fig and fig.group(1).count("<polygon") >= 100 and ">MPa</text>" in fig.group(1), "no stress field"
# The curve the verdict uses beside the contact node's.
assert "verdict: max outside the contact zone" in dom and "(contact node)" in dom, "the verdict's stress curve"
# Version, the scene's SHA-256 (a part file is read once, by its loader: not hashed) and the date.
assert run["impactdeck_version"] in dom
assert hashlib.sha256(open(sys.argv[5], "rb").read()).hexdigest() in dom, "the scene's hash"
assert re.search(r"inputs dated \d{4}-\d\d-\d\d \d\d:\d\d UTC", dom), "the inputs' date"
# A link to every file of the output folder, each one resolving there.
links = set(html.unescape(h) for h in re.findall(r'<a href="([^"]*)"', page))
files = set(os.path.relpath(os.path.join(d, f), out) for d, _, fs in os.walk(out) for f in fs)
assert files <= links, sorted(files - links)
assert all(os.path.isfile(os.path.join(out, l)) for l in links), "a link to no file"
assert "@media print" in page
# Every picture's text fits its canvas (DejaVu Sans: at most ~0.6 em a character) and its numbers
# are rounded (at most 4 significant digits).
for svg in re.findall(r"<svg[^>]*>.*?</svg>", page, re.S):
    width = float(re.search(r'<svg[^>]*width="([0-9.]+)"', svg).group(1))
    for attrs, text in re.findall(r"<text([^>]*)>([^<]*)</text>", svg):
        if "rotate(" in attrs: continue
        x = float(re.search(r' x="([-0-9.]+)"', attrs).group(1))
        size = float(re.search(r'font-size="([0-9.]+)"', attrs).group(1))
        w = 0.6 * size * len(html.unescape(text))
        anchor = re.search(r'text-anchor="(\w+)"', attrs).group(1)
        lo, hi = {"start": (x, x + w), "middle": (x - w / 2, x + w / 2), "end": (x - w, x)}[anchor]
        assert lo >= -2 and hi <= width + 2, ("text out of its picture", text, lo, hi, width)
        for num in re.findall(r"\d+\.?\d*(?:e[-+]?\d+)?", html.unescape(text)):
            digits = re.sub(r"e.*", "", num).replace(".", "").lstrip("0")
            assert len(digits) <= 4 or "." not in num, ("an unrounded number", text)
PY
finish report_html
