"""Progress lines (common/progress.hpp, issue 44 item 4): a sweep, a campaign, a drop sequence and a
ccx run show one redrawn line on stderr (stage, done/total, rate, time left or elapsed) when stderr
is a terminal (a pseudo-terminal here), and nothing when -q is given or stderr is not a terminal.
IMPACTDECK_PROGRESS_DELAY_S=0 shows the line from the start (a user sees it after 2 s of work).
usage: progress_test.py IMPACTDECK SOURCE_DIR WORK_DIR"""
import os
import pty
import select
import shutil
import subprocess
import sys

tool, src, work = sys.argv[1], sys.argv[2], sys.argv[3]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
env = dict(os.environ, IMPACTDECK_PROGRESS_DELAY_S="0")
failures = 0


def run(args, tty):
    """Runs the command with stderr on a pseudo-terminal (tty) or a pipe; returns (exit code, stderr)."""
    if not tty:
        p = subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env, timeout=600)
        return p.returncode, p.stderr.decode(errors="replace")
    master, slave = pty.openpty()
    p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=slave, stdin=subprocess.DEVNULL, env=env)
    os.close(slave)
    out = b""
    while True:
        ready, _, _ = select.select([master], [], [], 1.0)
        if ready:
            try:
                chunk = os.read(master, 65536)
            except OSError:  # EIO: the terminal's last writer is gone
                break
            if not chunk:
                break
            out += chunk
        elif p.poll() is not None:
            break
    p.wait(timeout=600)
    os.close(master)
    return p.returncode, out.decode(errors="replace")


def check(name, ok, detail=""):
    global failures
    if ok:
        print(f"ok: {name}")
    else:
        failures += 1
        print(f"FAILED: {name}" + (f": {detail[-600:]!r}" if detail else ""))


campaign = os.path.join(work, "speeds.toml")
with open(campaign, "w") as f:
    f.write(f'scene = "{src}/samples/paper_table2.toml"\n[product]\n"impacts[0].restitution" = [0.2, 0.3, 0.4]\n')

cases = [
    # (what, command (OUT replaced by a fresh folder), the line's start, what it counts)
    ("sweep", [tool, "sweep", f"{src}/samples/fig4_sweep.toml", "--cloud", "uniform", "--count", "200000",
               "--out", "OUT"], "sweep [", "points/s"),
    ("campaign", [tool, "campaign", "run", "OUT", "--jobs", "2"], "campaign [", "cases/s"),
    ("sequence", [tool, "run", f"{src}/samples/drop_sequence.toml", "--out", "OUT"], "sequence 'drop' [", "impacts/s"),
    ("ccx", [tool, "run", f"{src}/samples/drop_test.toml", "--out", "OUT"], "ccx [", "s simulated"),
]
for what, args, start, rate in cases:
    for mode in ("tty", "quiet", "pipe"):
        out = os.path.join(work, f"{what}_{mode}")
        if what == "campaign":
            subprocess.run([tool, "campaign", "plan", campaign, "--out", out], check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        cmd = [out if a == "OUT" else a for a in args] + (["-q"] if mode == "quiet" else [])
        rc, err = run(cmd, mode != "pipe")
        check(f"{what} ({mode}) exit 0", rc == 0, err)
        shown = start in err
        if mode == "tty":
            check(f"{what}: a progress line on a terminal", shown and rate in err and ("left" in err or "elapsed" in err), err)
            check(f"{what}: the line is redrawn in place", "\r" + start in err, err)
        else:
            check(f"{what}: no progress line ({'-q' if mode == 'quiet' else 'stderr not a terminal'})",
                  not shown and "\r" not in err, err)
shutil.rmtree(work, ignore_errors=True)
sys.exit(1 if failures else 0)
