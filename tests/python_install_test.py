"""`pip install` into a fresh venv, then docs/python.md's session (issue 32):
    python_install_test.py BUILD_DIR SOURCE_DIR WORK_DIR      (run with Debian's /usr/bin/python3)

The venv is `python3 -m venv --system-site-packages` (numpy, setuptools and wheel from Debian: no
network), and pip runs `pip install --no-build-isolation --no-index SOURCE_DIR`. pip takes the
module, the command and the plugins from this build tree (IMPACTDECK_BUILD_TREE=BUILD_DIR: setup.py
builds the targets there when out of date, then `cmake --install --strip` stages them), because a
from-scratch build (setup.py's default: its own tree in build-pip/) compiles the whole project
again, which takes far longer than a test may on this project's 2-core machines; the from-scratch
path runs the same setup.py code after its configure and build steps (docs/install.md). Checks:
what is installed where, that it is stripped, that the installed module loads the installed
plugins (not the build tree's), and that every Python block of docs/python.md, run from the
checkout by the venv's python, prints exactly the output block after it."""
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

BUILD, SRC, WORK = (Path(a).resolve() for a in sys.argv[1:4])
fails = []


def check(what, ok, detail=""):
    if not ok:
        fails.append(what)
        print(f"FAILED: {what}" + (f"\n{detail}" if detail else ""))


def sh(*args, **kw):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, **kw)


started = time.monotonic()
shutil.rmtree(WORK, ignore_errors=True)
WORK.mkdir(parents=True)
venv = WORK / "venv"
p = sh("/usr/bin/python3", "-m", "venv", "--system-site-packages", venv)
if p.returncode != 0:
    sys.exit(f"FAILED: venv: {p.stderr}")
py = venv / "bin" / "python"
env = dict(os.environ, IMPACTDECK_BUILD_TREE=str(BUILD), IMPACTDECK_PIP_WORK=str(WORK / "pip"), IMPACTDECK_JOBS="2")
env.pop("PYTHONPATH", None)
p = sh(py, "-m", "pip", "install", "--no-build-isolation", "--no-index", SRC, env=env)
if p.returncode != 0:
    sys.exit(f"FAILED: pip install (exit {p.returncode}):\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
print(f"pip install: {time.monotonic() - started:.0f} s")

# What is where: the module and its stubs and plugins in site-packages, the command and its
# plugins on the venv's PATH, the man page; the module is the venv's, not the build tree's.
env = dict(os.environ)
env.pop("PYTHONPATH", None)
site = Path(sh(py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])", env=env).stdout.strip())
module = sh(py, "-c", "import impactdeck; print(impactdeck.__file__)", env=env, cwd=SRC).stdout.strip()
check("the module imported is the installed one", module.startswith(str(site)), module)
plugins = ["libimpactdeck_gmsh_mesher.so", "libimpactdeck_gmsh_cad.so"]
installed = [Path(module), site / "impactdeck.pyi", venv / "bin" / "impactdeck", venv / "share" / "man" / "man1" / "impactdeck.1"]
installed += [site / f for f in plugins] + [venv / "bin" / f for f in plugins]
for f in installed:
    check(f"installed: {f}", f.is_file())
check("the command is executable", os.access(venv / "bin" / "impactdeck", os.X_OK))

# Stripped: no symbol table or debug sections left; the build tree's files keep theirs.
for f in [Path(module), venv / "bin" / "impactdeck", site / plugins[0], site / plugins[1]]:
    if f.is_file():
        sections = sh("readelf", "-S", "-W", f).stdout
        check(f"stripped: {f.name}", ".symtab" not in sections and ".debug_info" not in sections)
        print(f"installed {f.name}: {f.stat().st_size / 1e6:.1f} MB")
built = next((BUILD / "python").glob("impactdeck*.so"))
check("the build tree's module keeps its debug information", ".debug_info" in sh("readelf", "-S", "-W", built).stdout)
print(f"build tree {built.name}: {built.stat().st_size / 1e6:.1f} MB")

# The command on the venv's PATH runs, with its CAD plugin found beside it.
cmd_env = dict(env, PATH=f"{venv / 'bin'}:{env.get('PATH', '')}")
p = sh("impactdeck", "inspect", SRC / "tests" / "data" / "cad" / "screw.step", "--length-unit", "mm", "--json",
       env=cmd_env)
check("the installed command reads a STEP part", p.returncode == 0 and '"format": "step"' in p.stdout, p.stderr)
version = re.search(r'^version = "([^"]+)"', (SRC / "pyproject.toml").read_text(), re.M).group(1)
cmake_version = re.search(r"project\(impactdeck VERSION ([0-9.]+)", (SRC / "CMakeLists.txt").read_text()).group(1)
check("pyproject.toml's version is the CMake project's", version == cmake_version, f"{version} != {cmake_version}")
p = sh(py, "-c", "import impactdeck; print(impactdeck.__version__)", env=env, cwd=SRC)
check("the module's version", p.stdout.strip() == cmake_version, p.stdout + p.stderr)

# The installed module loads the CAD plugin installed beside it.
p = sh(py, "-c", "import impactdeck; impactdeck.load_part('tests/data/cad/screw.step', 'mm');"
       "print([l.split()[-1] for l in open('/proc/self/maps') if 'libimpactdeck_gmsh_cad' in l][0])", env=env, cwd=SRC)
check("the module's CAD plugin is the installed one", p.stdout.strip() == str(site / plugins[1]), p.stdout + p.stderr)

# docs/python.md's session: each ```python block, in order, in one interpreter, from the checkout,
# prints the ``` block that follows it.
doc = (SRC / "docs" / "python.md").read_text()
blocks = re.findall(r"```python\n(.*?)```\n```\n(.*?)```", doc, re.S)
check("docs/python.md has its session", len(blocks) >= 6, f"{len(blocks)} blocks")
runner = r"""
import contextlib, io, json, sys
blocks = json.load(sys.stdin)
scope = {"__name__": "__main__"}
outs = []
for code in blocks:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        exec(compile(code, "docs/python.md", "exec"), scope)
    outs.append(buf.getvalue())
json.dump(outs, sys.__stdout__)
"""
import json  # noqa: E402

p = subprocess.run([str(py), "-c", runner], input=json.dumps([c for c, _ in blocks]), capture_output=True, text=True,
                   env=env, cwd=SRC)
if p.returncode != 0:
    check("docs/python.md's session runs", False, p.stderr[-3000:])
else:
    for i, ((code, want), got) in enumerate(zip(blocks, json.loads(p.stdout))):
        check(f"docs/python.md block {i + 1} prints what the page shows", got == want,
              f"--- code:\n{code}--- page:\n{want}--- printed:\n{got}")
print(f"total: {time.monotonic() - started:.0f} s")
if fails:
    sys.exit(f"{len(fails)} check(s) failed")
print("python_install: all checks passed")
