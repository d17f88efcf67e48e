#!/usr/bin/env python3
"""One impact, computed once and flowing one way (issue 28), checked on the system calls.

Runs `impactdeck run` on a mesh part with an FEM deck and a ccx run (tests/data/trace/box_hit.toml)
under strace, then asserts on what the impactdeck process itself
did (its threads included; the solver processes it starts are left out, from their fork on):
  - the part file's bytes are read through one open of it;
  - no file the run writes (directly, or through a rename of a temporary file) is read afterwards
    by the run (a read(2) that returns bytes; opening a written file to fsync it is no read),
    except the files KNOWN_READ_BACK names.
Usage: one_read_test.py IMPACTDECK SOURCE_DIR WORK_DIR
"""
import os
import re
import shutil
import subprocess
import sys

# Files a run may read back, and why: none. (Gmsh's mesh-part route merged the part's STL copy
# that the deck folder keeps for its .geo until fem_export/src/gmsh_mesh.cpp built the surface from
# memory.) A name listed here that is no longer read back is reported, so that the list only shrinks.
KNOWN_READ_BACK = set()

impactdeck, source, work = (os.path.abspath(a) for a in sys.argv[1:4])
scene = os.path.join(source, "tests/data/trace/box_hit.toml")
part = os.path.realpath(os.path.join(source, "tests/data/box_200x100x60mm.stl"))
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
out = os.path.join(work, "out")
log = os.path.join(work, "strace.log")

# -y: each file descriptor with its path, so that a read names the file it reads.
# --seccomp-bpf: only the traced calls stop the processes (ccx's arithmetic runs at full speed).
cmd = ["strace", "-f", "--seccomp-bpf", "-qq", "-y", "-s", "512", "-o", log,
       "-e", "trace=open,openat,creat,read,pread64,readv,preadv,close,rename,renameat,renameat2,"
             "clone,clone3,fork,vfork,execve,chdir",
       impactdeck, "run", scene, "--out", out, "-q"]
run = subprocess.run(cmd, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if run.returncode != 0:
    sys.exit(f"FAIL: the traced run exited {run.returncode}:\n{run.stderr}")

# One call a line: a call strace split around another thread's ("<unfinished ...>" then
# "<... NAME resumed>") is joined again.
calls = []
pending = {}
for raw in open(log, errors="replace"):
    raw = raw.rstrip("\n")
    m = re.match(r"^(\d+)\s+(.*)$", raw)
    if not m:
        continue
    pid, rest = int(m.group(1)), m.group(2)
    if rest.endswith("<unfinished ...>"):
        pending[pid] = rest[: -len("<unfinished ...>")]
        continue
    r = re.match(r"^<\.\.\. \w+ resumed>(.*)$", rest)
    if r:
        rest = pending.pop(pid, "") + r.group(1)
    c = re.match(r"^(\w+)\((.*)\)\s+=\s+(-?\d+)(<[^>]*>)?", rest)
    if c:
        calls.append((pid, c.group(1), c.group(2), int(c.group(3)), c.group(4) or ""))

# The solver processes: children created by fork/vfork/clone without CLONE_THREAD (ccx and what
# starts it), and anything they create.
first_pid = calls[0][0] if calls else None
solver_pids = set()
for pid, call, args, result, _ in calls:
    if call in ("fork", "vfork") or (call in ("clone", "clone3") and "CLONE_THREAD" not in args):
        if result > 0:
            solver_pids.add(result)
    if call == "execve" and result == 0 and pid != first_pid:
        solver_pids.add(pid)

str_re = re.compile(r'"((?:[^"\\]|\\.)*)"')
fd_re = re.compile(r"^(\d+)<([^>]*)>")
written = set()
part_opens = {}        # (pid, fd) of an open part file -> whether its bytes were read
part_reads = 0
reads_back = {}
for pid, call, args, result, ret_path in calls:
    if pid in solver_pids or result < 0:
        continue
    if call in ("open", "openat", "creat"):
        names = str_re.findall(args)
        if not names:
            continue
        path = os.path.normpath(names[0] if names[0].startswith("/") else os.path.join(work, names[0]))
        flags = "O_WRONLY|O_CREAT" if call == "creat" else args.split(",")[2 if call == "openat" else 1]
        if "O_WRONLY" in flags or "O_RDWR" in flags or "O_CREAT" in flags:
            written.add(path)
        if os.path.realpath(path) == part:
            part_opens[(pid, result)] = False
    elif call == "close":
        fd = fd_re.match(args)
        if fd and (pid, int(fd.group(1))) in part_opens and part_opens[(pid, int(fd.group(1)))]:
            part_reads += 1
            del part_opens[(pid, int(fd.group(1)))]
    elif call in ("read", "pread64", "readv", "preadv") and result > 0:
        fd = fd_re.match(args)
        if not fd:
            continue
        path = os.path.normpath(fd.group(2))
        if os.path.realpath(path) == part:
            part_opens[(pid, int(fd.group(1)))] = True
        if path in written:
            reads_back.setdefault(os.path.basename(path), set()).add(path)
    elif call in ("rename", "renameat", "renameat2"):
        names = [os.path.normpath(p) for p in str_re.findall(args)]
        if len(names) >= 2 and names[0] in written:
            written.add(names[-1])
part_reads += sum(1 for v in part_opens.values() if v)  # opens never closed in the trace

errors = []
if part_reads != 1:
    errors.append(f"the part file {part} was read through {part_reads} opens (expected one)")
unexpected = {n: p for n, p in reads_back.items() if n not in KNOWN_READ_BACK}
if unexpected:
    errors.append("files written by the run and read back by it:\n  " +
                  "\n  ".join(sorted(p for ps in unexpected.values() for p in ps)))
gone = sorted(KNOWN_READ_BACK - set(reads_back))
print(f"part file read through {part_reads} open(s); {len(written)} files written; "
      f"{len(solver_pids)} solver process(es) left out; read back (known): {sorted(set(reads_back) & KNOWN_READ_BACK)}")
if gone:
    print(f"note: no longer read back, remove from KNOWN_READ_BACK: {gone}")
if errors:
    sys.exit("FAIL: " + "\n".join(errors))
