#!/usr/bin/env python3
"""Every XML, HTML and JSON output stays well formed whatever the scene's names hold (issue 43 item 6).

Names with ", &, <, >, ', a double dash and non-ASCII text (materials, bodies, an impact, a sequence)
go through `run` (a sequence's .pvd and .vtp frames, SVG pictures, CSV sidecars, report.html, an
FEM deck run through ccx: its .vtu and results.pvd, deck.json), `sweep` (.vtp, --json) and a point
campaign (`campaign plan/run/collect`: cases.json, map.svg, map.vtp, collect/report.html). Each XML
file is parsed by xml.etree, each JSON file by json, each HTML page by html.parser (every tag one of
the page's own, every name shown as text exactly as written).
Before, a sequence named with a quote wrote a .pvd whose DataSet file attribute broke the XML.
Usage: hostile_names_test.py IMPACTDECK SOURCE_DIR WORK_DIR
"""
import html.parser
import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

impactdeck, source, work = (os.path.abspath(a) for a in sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)

NAMES = {  # each a TOML basic string's content (escaped for TOML) -> the name itself
    "material": ('st\\"eel & <b>é</b>', 'st"eel & <b>é</b>'),
    "body": ("part 'x' -- <&> \\u00e9\\u65e5", "part 'x' -- <&> é日"),
    "floor": ('fl\\"oor <!-- x -->', 'fl"oor <!-- x -->'),
    "ball": ("b&all \\u00e7a", "b&all ça"),
    "impact": ("hit \\\"&amp;\\\" <i>'q'<i> \\u00fc-", "hit \"&amp;\" <i>'q'<i> ü-"),
    "sequence": ("drop \\\"1\\\" & <2> 'three' --", "drop \"1\" & <2> 'three' --"),
}
T = {k: v[0] for k, v in NAMES.items()}
N = {k: v[1] for k, v in NAMES.items()}

scene_text = f'''length_unit = "mm"
gravity_m_s2 = [0, 0, -9.81]
[materials."{T["material"]}"]
youngs_modulus_Pa = 2.1e11
poisson_ratio = 0.3
density_kg_m3 = 7850
[[bodies]]
name = "{T["body"]}"
shape = "sphere"
radius = 20
material = "{T["material"]}"
position = [0, 0, 100]
[[bodies]]
name = "{T["floor"]}"
shape = "plane"
normal = [0, 0, 1]
material = "{T["material"]}"
[[bodies]]
name = "{T["ball"]}"
shape = "sphere"
radius = 5
material = "{T["material"]}"
[[impacts]]
name = "{T["impact"]}"
target = "{T["body"]}"
impactor = "{T["ball"]}"
point = [0, 0, 20]
approach_speed_m_s = 1.0
restitution = 0.8
[[sequences]]
name = "{T["sequence"]}"
body = "{T["body"]}"
floor = "{T["floor"]}"
restitution = 0.5
max_impacts = 3
[outputs]
force_table_csv = "force.csv"
force_plot_svg = "force.svg"
[outputs.fem]
mesh_size = 5
run = "calculix"
end_time_s = 2e-4
fem = "none"
'''
# fem = "none" belongs to [[sequences]]: written there below (the deck is the impact's).
scene_text = scene_text.replace('fem = "none"\n', "").replace("max_impacts = 3\n", 'max_impacts = 3\nfem = "none"\n')
scene = os.path.join(work, "hostile.toml")
with open(scene, "w", encoding="utf-8") as f:
    f.write(scene_text)

failures = []


def run(*args, cwd=work):
    p = subprocess.run([impactdeck, *args], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    if p.returncode != 0:
        sys.exit(f"FAIL: impactdeck {' '.join(args)} exited {p.returncode}: {p.stderr.decode(errors='replace')}")
    return p.stdout


class Page(html.parser.HTMLParser):
    TAGS = {"html", "head", "meta", "title", "style", "body", "h1", "h2", "h3", "h4", "p", "table", "thead", "tbody",
            "tr", "th", "td", "a", "ul", "ol", "li", "pre", "details", "summary", "figure", "figcaption", "img", "svg",
            "g", "path", "line", "polyline", "polygon", "rect", "circle", "text", "tspan", "title", "defs", "span",
            "div", "section", "br", "code", "small", "strong", "em", "caption", "nav", "header", "footer",
            "ellipse", "lineargradient", "stop", "clippath", "use", "marker", "sup", "sub", "colgroup", "col", "hr",
            "main", "article", "dl", "dt", "dd", "abbr", "time", "label", "textarea", "symbol", "desc", "tfoot"}

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.text, self.bad = [], []

    def handle_starttag(self, tag, attrs):
        if tag not in self.TAGS:
            self.bad.append(tag)

    def handle_data(self, data):
        self.text.append(data)


def check_file(path):
    rel = os.path.relpath(path, work)
    data = open(path, "rb").read()
    try:
        if path.endswith((".pvd", ".vtp", ".vtu", ".svg")):
            # VTK's raw appended data (sweep's .vtp) is bytes after '_', by design not XML: the
            # markup before it is parsed, closed where the data block starts.
            cut = data.find(b"<AppendedData")
            ET.fromstring(data if cut < 0 else data[:cut] + b"</VTKFile>")
        elif path.endswith(".json"):
            json.loads(data.decode("utf-8"))
        elif path.endswith(".html"):
            p = Page()
            p.feed(data.decode("utf-8"))
            p.close()
            if p.bad:
                failures.append(f"{rel}: tags that are not the page's own (a name read as markup): {sorted(set(p.bad))}")
            return "".join(p.text)
        else:
            return None
    except Exception as e:  # noqa: BLE001 - any parse error is the finding
        failures.append(f"{rel}: {type(e).__name__}: {e}")
    return None


def check_tree(root, must_show=()):
    counts = {}
    pages = {}
    for d, _, files in os.walk(root):
        for f in files:
            ext = os.path.splitext(f)[1]
            if ext in (".pvd", ".vtp", ".vtu", ".svg", ".json", ".html"):
                counts[ext] = counts.get(ext, 0) + 1
                text = check_file(os.path.join(d, f))
                if ext == ".html":
                    pages[os.path.join(d, f)] = text or ""
    for page, text in pages.items():
        for name in must_show:
            if name not in text:
                failures.append(f"{os.path.relpath(page, work)}: the name {name!r} is not shown as text")
    return counts


# 1. run: the sequence, the impact's table, plot and FEM deck through ccx, report.html, --json.
out = os.path.join(work, "run")
doc = run("run", scene, "--out", out, "--json", "-q")
json.loads(doc.decode("utf-8"))
seq = "sequence_" + N["sequence"]
for f in (seq + ".pvd", seq + ".svg", seq + ".csv.json", "report.html", "force.svg", "force.csv.json"):
    if not os.path.isfile(os.path.join(out, f)):
        failures.append(f"run: {f!r} was not written")
if not any(f.endswith(".vtu") for _, _, fs in os.walk(out) for f in fs):
    failures.append("run: no .vtu written (ccx did not run?)")
# The .pvd's frames: each DataSet names a file that exists, as ParaView reads the attribute.
try:
    for ds in ET.parse(os.path.join(out, seq + ".pvd")).getroot().iter("DataSet"):
        if not os.path.isfile(os.path.join(out, ds.get("file"))):
            failures.append(f"run: the .pvd's DataSet file {ds.get('file')!r} does not exist")
except Exception as e:  # noqa: BLE001
    failures.append(f"run: the .pvd: {e}")
counts = {"run": check_tree(out, must_show=(N["sequence"], N["impact"], N["body"]))}

# 2. sweep: .vtp and the SVG map, --json.
sweep_out = os.path.join(work, "sweep")
json.loads(run("sweep", scene, "--out", sweep_out, "--json", "-q", "--grid-steps", "2", "--formats", "csv,vtp,svg")
           .decode("utf-8"))
counts["sweep"] = check_tree(sweep_out)

# 3. a point campaign on the scene: cases.json, map.svg, map.vtp, collect/report.html.
base = os.path.join(work, "base.toml")
with open(base, "w", encoding="utf-8") as f:
    f.write(scene_text.split("[outputs.fem]")[0])
camp_file = os.path.join(work, "campaign.toml")
with open(camp_file, "w", encoding="utf-8") as f:
    f.write(f'scene = "base.toml"\nimpact = "{T["impact"]}"\n[points]\ncount = 3\nseed = 1\n')
camp = os.path.join(work, "camp")
run("campaign", "plan", camp_file, "--out", camp, "-q")
run("campaign", "run", camp, "-q")
json.loads(run("campaign", "collect", camp, "--json").decode("utf-8"))
counts["campaign collect"] = check_tree(os.path.join(camp, "collect"), must_show=(N["impact"],))

print("hostile_names_test: files parsed: " + "; ".join(f"{k}: {v}" for k, v in counts.items()))
if failures:
    sys.exit("FAIL:\n  " + "\n  ".join(failures))
print("hostile_names_test: ok")
