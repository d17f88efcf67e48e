#!/usr/bin/env python3
"""A meshing run writes nothing outside its folders (issue 43 item 6), checked on the system calls.

Runs `impactdeck run` on a mesh part with an FEM deck (Gmsh meshes it through the plugin) under
strace, with HOME and TMPDIR set to folders of the test, and fails on any call that writes,
creates, renames or removes a path outside the run's own folders: the output folder (with its
staging folders) and TMPDIR, the staging the tool owns. Before the fix, every meshing run had
FLTK (loaded by Gmsh) rewrite /etc/fltk/fltk.org/fltk.prefs and $HOME/.fltk/fltk.org/fltk.prefs,
and gmsh::finalize unlink $HOME/.gmsh-tmp.
Not a write: an unlink(2) of a path ending in '/' (it names a folder, which unlink never removes:
Gmsh's General.TmpFileName = "", common/gmsh/gmsh_home_files.hpp), opening /dev/null or a tty.
Usage: outside_writes_test.py IMPACTDECK SOURCE_DIR WORK_DIR
"""
import os
import re
import shutil
import subprocess
import sys

impactdeck, source, work = (os.path.abspath(a) for a in sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
home, tmp, out = (os.path.join(work, d) for d in ("home", "tmp", "out"))
for d in (home, tmp):
    os.makedirs(d)
part = os.path.join(source, "tests/data/box_200x100x60mm.stl")
scene = os.path.join(work, "mesh.toml")
with open(scene, "w") as f:
    f.write(f'''length_unit = "mm"
[materials.steel]
youngs_modulus_Pa = 2.05e11
poisson_ratio = 0.3
density_kg_m3 = 7850
[[bodies]]
name = "box"
shape = "mesh"
mesh = "{part}"
material = "steel"
[[bodies]]
name = "ball"
shape = "sphere"
radius = 10
material = "steel"
[[impacts]]
name = "hit"
target = "box"
impactor = "ball"
point = [100, 50, 60]
restitution = 1.0
approach_speed_m_s = 1.0
[outputs.fem]
mesh_size = 40
''')
log = os.path.join(work, "strace.log")
cmd = ["strace", "-f", "-qq", "-y", "-s", "1024", "-o", log,
       "-e", "trace=open,openat,creat,mkdir,mkdirat,rename,renameat,renameat2,unlink,unlinkat,rmdir,link,linkat,"
             "symlink,symlinkat,truncate,chmod,fchmodat",
       impactdeck, "run", scene, "--out", out, "-q"]
env = dict(os.environ, HOME=home, TMPDIR=tmp)
run = subprocess.run(cmd, cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if run.returncode != 0:
    sys.exit(f"FAIL: the traced run exited {run.returncode}:\n{run.stderr}")
if not any(n.startswith("fem_") for n in os.listdir(out)):
    sys.exit(f"FAIL: no deck folder in {out}: {os.listdir(out)}")

str_re = re.compile(r'"((?:[^"\\]|\\.)*)"')
dirfd_re = re.compile(r"^(?:AT_FDCWD|\d+<([^>]*)>)")
allowed = [work]  # the output folder, its staging folders, HOME and TMPDIR of the test are inside
harmless = ("/dev/null", "/dev/tty")
writes = []
mesher_loaded = False
pending = {}
for raw in open(log, errors="replace"):
    m = re.match(r"^(\d+)\s+(.*)$", raw.rstrip("\n"))
    if not m:
        continue
    pid, rest = m.group(1), m.group(2)
    if rest.endswith("<unfinished ...>"):
        pending[pid] = rest[: -len("<unfinished ...>")]
        continue
    r = re.match(r"^<\.\.\. \w+ resumed>(.*)$", rest)
    if r:
        rest = pending.pop(pid, "") + r.group(1)
    c = re.match(r"^(\w+)\((.*)\)\s+=\s+(-?\d+)", rest)
    if not c:
        continue
    call, args = c.group(1), c.group(2)
    names = str_re.findall(args)
    if not names:
        continue
    if "libimpactdeck_gmsh_mesher" in names[0]:
        mesher_loaded = True
    if call in ("open", "openat"):
        flags = args.split(", ")[2 if call == "openat" else 1]
        if not any(f in flags for f in ("O_WRONLY", "O_RDWR", "O_CREAT", "O_TRUNC")):
            continue
    if call in ("unlink", "unlinkat") and names[-1].endswith("/"):
        continue
    # Each path argument, made absolute against its directory descriptor (-y names it) or the cwd.
    base = work
    d = dirfd_re.match(args)
    if call.endswith("at") and d and d.group(1):
        base = d.group(1)
    for name in names:
        path = os.path.normpath(name if name.startswith("/") else os.path.join(base, name))
        if path in harmless or any(path == a or path.startswith(a + "/") for a in allowed):
            continue
        writes.append(f"{call}({args}) [pid {pid}]")
        break

print(f"outside_writes_test: mesher plugin loaded: {mesher_loaded}; writes outside the run's folders: {len(writes)}")
if not mesher_loaded:
    sys.exit("FAIL: the Gmsh mesher plugin was not loaded: nothing was meshed")
if writes:
    sys.exit("FAIL: writes outside the run's folders:\n  " + "\n  ".join(writes[:40]))
print("outside_writes_test: ok")
