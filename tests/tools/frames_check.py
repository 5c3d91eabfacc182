#!/usr/bin/python3
"""frames_check.py — `frac run --frames` checked from outside.

    /usr/bin/python3 tests/tools/frames_check.py FRAC

1. Every frame of a range is byte for byte the file `--frames N..N` writes
   for the same frame (a script that uses `frame`, the seed and a random
   stream), on 1 and 3 threads.
2. On a terminal (a pseudo-terminal from Python's pty module) each frame
   prints one progress line `frame N (K of COUNT)` to stderr; with stderr a
   pipe, or with --quiet, none.

Exit 0: all checks passed; 1: a check failed (each failure is printed).
"""
import os
import pty
import select
import subprocess
import sys
import tempfile

from _check import FRAC, check, finish  # noqa: E402


SCRIPT = """
let r = random(frame)
let g = gradient(12, from: [r, 0.2, clock], to: [frame / 10, 1 - r, 0.5], angle: 30 * frame)
save(g, "g%f.png")
save(g, "h%f.ppm")
"""

with tempfile.TemporaryDirectory() as tmp:
    src = os.path.join(tmp, "s.frac")
    with open(src, "w") as f:
        f.write(SCRIPT.replace("clock", "0"))  # clock differs between a range and N..N
    for threads in ("1", "3"):
        whole = os.path.join(tmp, "whole" + threads)
        r = subprocess.run([FRAC, "run", "--quiet", "--threads", threads, "--seed", "7", "--frames", "0..6:3",
                            "-o", whole, src], capture_output=True, text=True, timeout=60)
        check(r.returncode == 0, "--frames 0..6:3 exit %d: %s" % (r.returncode, r.stderr))
        names = sorted(os.listdir(whole)) if os.path.isdir(whole) else []
        check(names == ["g0.png", "g3.png", "g6.png", "h0.ppm", "h3.ppm", "h6.ppm"], "files written: %s" % names)
        for n in (0, 3, 6):
            one = os.path.join(tmp, "one%s_%d" % (threads, n))
            r = subprocess.run([FRAC, "run", "--quiet", "--threads", threads, "--seed", "7", "--frames",
                                "%d..%d" % (n, n), "-o", one, src], capture_output=True, text=True, timeout=60)
            check(r.returncode == 0, "--frames %d..%d exit %d" % (n, n, r.returncode))
            for ext in ("g%d.png", "h%d.ppm"):
                a = open(os.path.join(whole, ext % n), "rb").read()
                b = open(os.path.join(one, ext % n), "rb").read()
                check(a == b, "frame %d of 0..6:3 (%s) equals --frames %d..%d, %s threads" % (n, ext % n, n, n, threads))
        # the frames differ from each other (the script really uses frame)
        check(open(os.path.join(whole, "g0.png"), "rb").read() != open(os.path.join(whole, "g3.png"), "rb").read(),
              "frames 0 and 3 differ")

    # progress lines: on a terminal only
    with open(src, "w") as f:
        f.write("save(image(2), \"p%f.png\")\n")

    def on_pty(args):
        master, slave = pty.openpty()
        p = subprocess.Popen([FRAC] + args, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=slave)
        os.close(slave)
        out = b""
        while True:
            ready, _, _ = select.select([master], [], [], 20)
            if not ready:
                break
            try:
                chunk = os.read(master, 4096)
            except OSError:  # EIO: the child closed the terminal
                break
            if not chunk:
                break
            out += chunk
        p.wait(timeout=60)
        os.close(master)
        return p.returncode, out.decode("utf-8", "replace").replace("\r\n", "\n")

    rc, err = on_pty(["run", "--frames", "3..5", "-o", os.path.join(tmp, "p"), src])
    lines = [l for l in err.split("\n") if l.startswith("frame ")]
    check(rc == 0, "progress run exit %d" % rc)
    check(lines == ["frame 3 (1 of 3)", "frame 4 (2 of 3)", "frame 5 (3 of 3)"], "progress lines on a tty: %r" % err)
    rc, err = on_pty(["run", "--quiet", "--frames", "3..5", "-o", os.path.join(tmp, "q"), src])
    check(rc == 0 and "frame " not in err, "--quiet: no progress lines on a tty: %r" % err)
    r = subprocess.run([FRAC, "run", "--frames", "3..5", "-o", os.path.join(tmp, "r"), src], capture_output=True,
                       text=True, timeout=60)
    check(r.returncode == 0 and "frame " not in r.stderr, "stderr not a tty: no progress lines: %r" % r.stderr)

finish()
