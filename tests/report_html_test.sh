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

# render FILE OUT: the DOM after loading (stdout) and Chromium's log (stderr, console included).
render() {
  timeout 60 chromium --headless --disable-gpu --no-sandbox --no-first-run --user-data-dir="$tmp/profile" \
    --enable-logging=stderr --v=0 --virtual-time-budget=3000 --dump-dom "file://$1" >"$2.dom" 2>"$2.log"
}
# Console messages (any level) and resources the page's policy refused.
console_errors() { grep -E "CONSOLE|Refused to|Uncaught" "$1.log"; }

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
if console_errors "$tmp/page" >"$tmp/page.errors"; then
  echo "FAILED: console messages:"; cat "$tmp/page.errors"; fails=$((fails+1))
else
  passes=$((passes+1))
fi
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
# Self-contained: no external reference.
assert not re.search(r'(src|href)="(?!data:|#)', page), "an external resource"
PY
finish report_html
