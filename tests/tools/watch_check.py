#!/usr/bin/python3
"""watch_check.py — `frac watch` driven from outside, as a user would.

    /usr/bin/python3 tests/tools/watch_check.py FRAC

Starts `frac watch SCRIPT -o DIR` in the background on a script that imports
a module and loads an image, then:
  1. the first render writes its file;
  2. the module saved by rename (an editor's write-new-then-rename), the
     loaded image rewritten and the script edited in place each give a new
     render whose output shows the change (stdout and the file's bytes);
  3. a syntax error is printed and watching goes on; the fix renders again;
  4. a render of 1e10 chaos-game points (minutes) is cancelled by the next
     edit: the light version's file appears within seconds;
  5. SIGINT ends the watch with exit 0 and "watch: stopped", leaving no
     temporary file in the output folder;
  6. with --show on a pseudo-terminal, the first saved image is drawn
     (24-bit colour half blocks).
Every wait has a timeout; nothing sleeps longer than needed.

Exit 0: all checks passed; 1: a check failed (each failure is printed).
"""
import os
import pty
import select
import signal
import subprocess
import sys
import tempfile
import threading
import time

from _check import FRAC, check, finish  # noqa: E402


def write(path, text, rename=False):
    if rename:
        tmp = path + ".swp"
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    else:
        with open(path, "w") as f:
            f.write(text)


class Proc:
    """A background process whose stdout and stderr are collected."""

    def __init__(self, args, cwd):
        self.p = subprocess.Popen(args, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE)
        self.out, self.err = [], []
        for stream, sink in ((self.p.stdout, self.out), (self.p.stderr, self.err)):
            threading.Thread(target=self.pump, args=(stream, sink), daemon=True).start()

    @staticmethod
    def pump(stream, sink):
        for line in iter(stream.readline, b""):
            sink.append(line.decode("utf-8", "replace").rstrip("\n"))

    def wait_for(self, what, cond, timeout=20):
        t0 = time.time()
        while time.time() - t0 < timeout:
            if cond():
                return True
            if self.p.poll() is not None:
                break
            time.sleep(0.05)
        ok = cond()
        check(ok, "%s (within %d s); stderr so far: %r" % (what, timeout, self.err[-6:]))
        return ok


def file_bytes(path):
    try:
        with open(path, "rb") as f:
            return f.read()
    except OSError:
        return None


SCRIPT = """import "_m.frac" as m
let t = load("tex.png")
print("k", m.k, round(255 * pixel(t, 0, 0)[0]))
save(image(4, colour: [m.k, pixel(t, 0, 0)[0], 0.5]), "o.png")
"""

with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "out")
    opng = os.path.join(out, "o.png")
    subprocess.run([FRAC, "-q", "-e", 'save(image(2, colour: 0.2), "%s")' % os.path.join(tmp, "tex.png")],
                   check=True, capture_output=True)
    write(os.path.join(tmp, "_m.frac"), "let k = 0.25\n")
    write(os.path.join(tmp, "s.frac"), SCRIPT)
    w = Proc([FRAC, "watch", "s.frac", "-o", "out"], tmp)
    w.wait_for("first render", lambda: "k 0.25 51" in w.out and file_bytes(opng))
    w.wait_for("status line", lambda: any(l.startswith("watch: rendered in ") and
                                          l.endswith("watching 3 files for changes (Ctrl-C ends)") for l in w.err))
    first = file_bytes(opng)

    write(os.path.join(tmp, "_m.frac"), "let k = 0.75\n", rename=True)
    w.wait_for("module saved by rename: new render", lambda: "k 0.75 51" in w.out)
    w.wait_for("output rewritten", lambda: file_bytes(opng) not in (None, first))
    check(any(l == "watch: %s changed; rendering again" % os.path.join(tmp, "_m.frac") or
              l.endswith("_m.frac changed; rendering again") for l in w.err), "change reported: %r" % w.err)

    time.sleep(0.05)
    subprocess.run([FRAC, "-q", "-e", 'save(image(2, colour: 0.6), "%s")' % os.path.join(tmp, "tex.png")],
                   check=True, capture_output=True)
    w.wait_for("loaded image rewritten: new render", lambda: "k 0.75 153" in w.out)

    write(os.path.join(tmp, "s.frac"), SCRIPT.replace('print("k"', 'print("K"'))
    w.wait_for("script edited in place: new render", lambda: "K 0.75 153" in w.out)

    write(os.path.join(tmp, "s.frac"), SCRIPT + "let = 3\n")
    w.wait_for("syntax error shown", lambda: any(l.startswith("s.frac:5:5: error: ") for l in w.err))
    check(w.p.poll() is None, "still watching after an error")
    w.wait_for("failure status", lambda: any(l.startswith("watch: failed in ") for l in w.err))
    write(os.path.join(tmp, "s.frac"), SCRIPT.replace('print("k"', 'print("fixed"'))
    w.wait_for("fixed script renders", lambda: "fixed 0.75 153" in w.out)

    # cancel a long render: 1e10 points would take minutes
    heavy = os.path.join(out, "heavy.png")
    write(os.path.join(tmp, "s.frac"), 'import "ifs"\nsave(chaos(fern, points: 1e10, size: 64), "heavy.png")\n')
    w.wait_for("heavy render starts", lambda: any(l == "watch: s.frac changed; rendering again" for l in w.err[-3:]))
    time.sleep(0.5)
    t0 = time.time()
    write(os.path.join(tmp, "s.frac"), 'import "ifs"\nsave(chaos(fern, points: 1e3, size: 64), "light.png")\n')
    w.wait_for("heavy render cancelled, light one written", lambda: os.path.exists(os.path.join(out, "light.png")),
               timeout=15)
    check(time.time() - t0 < 15 and not os.path.exists(heavy), "cancelled quickly, no heavy.png")
    check(not any("interrupted" in l for l in w.err), "a cancelled render is not an error: %r" % w.err)

    w.p.send_signal(signal.SIGINT)
    try:
        rc = w.p.wait(timeout=15)
    except subprocess.TimeoutExpired:
        w.p.kill()
        rc = "timeout"
    time.sleep(0.1)
    check(rc == 0, "Ctrl-C ends watch with exit 0, got %r" % rc)
    check(w.err and w.err[-1] == "watch: stopped", "last line 'watch: stopped': %r" % w.err[-3:])
    check(sorted(os.listdir(out)) == ["light.png", "o.png"], "no temporary files: %r" % os.listdir(out))

    # --show on a terminal
    write(os.path.join(tmp, "s.frac"), 'save(gradient([8, 4], from: [1, 0, 0], to: [0, 0, 1]), "g.png")\n')
    master, slave = pty.openpty()
    env = dict(os.environ, TERM="xterm-256color")
    env.pop("NO_COLOR", None)
    p = subprocess.Popen([FRAC, "watch", "--show", "s.frac", "-o", "out"], cwd=tmp, stdin=slave, stdout=slave,
                         stderr=slave, env=env)
    os.close(slave)
    got, t0 = b"", time.time()
    while time.time() - t0 < 30 and b"watching 1 file" not in got:
        r, _, _ = select.select([master], [], [], 0.5)
        if r:
            try:
                got += os.read(master, 65536)
            except OSError:
                break
    p.send_signal(signal.SIGINT)
    try:
        rc = p.wait(timeout=15)
    except subprocess.TimeoutExpired:
        p.kill()
        rc = "timeout"
    os.close(master)
    text = got.decode("utf-8", "replace")
    check("\x1b[38;2;" in text and "\u2580" in text, "--show draws the image: %r" % text[-300:])
    check(rc == 0, "--show watch ends with exit 0, got %r" % rc)

    r = subprocess.run([FRAC, "watch", "-"], capture_output=True, text=True, timeout=30)
    check(r.returncode == 64 and r.stderr.startswith("frac: watch needs a script file to watch"),
          "watch - is a usage error: %r" % r.stderr)
    r = subprocess.run([FRAC, "run", "--show", "x.frac"], capture_output=True, text=True, timeout=30)
    check(r.returncode == 64 and r.stderr.startswith("frac: --show goes with `frac watch`"),
          "--show without watch: %r" % r.stderr)

finish()
