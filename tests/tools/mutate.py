#!/usr/bin/env python3
"""mutate.py — the mutation check of tests/README.md ("Mutation table").

Reads tests/tools/mutations.txt: blocks separated by blank lines, each

    id:    chaos-3d-swap            a short name
    file:  runtime/chaos.c          the file to mutate
    old:   m[1] * *y + m[2] * *z    text that occurs exactly once in the file
    new:   m[2] * *y + m[1] * *z    what replaces it
    tests: test_chaos lang/ifs      runner filters (unit test names, test paths)
    why:   ...                      (optional) why a survivor is equivalent

For each mutation (or only the ids given on the command line) it copies the
tracked tree once into a scratch folder (default /tmp/$USER-mut, or
--scratch DIR), builds it there, applies the one mutation, rebuilds, runs
`build/runner` once per filter and restores the file before the next one.
The working tree is never touched. A mutation is "caught" when the build or
any filtered run fails, "survived" when all pass. Prints one line per
mutation and a summary; exit status 1 when a survivor has no `why:`.

    tests/tools/mutate.py                   every mutation
    tests/tools/mutate.py chaos-3d-swap     one
    tests/tools/mutate.py --list            the ids
"""
import os, shutil, subprocess, sys, time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def load(path):
    muts, cur = [], {}
    for line in open(path, encoding="utf-8").read().split("\n") + [""]:
        if line.startswith("#"):
            continue
        if not line.strip():
            if cur:
                muts.append(cur)
            cur = {}
            continue
        key, _, val = line.partition(":")
        key = key.strip()
        val = val[1:] if val.startswith(" ") else val
        val = val.lstrip(" ") if key != "old" and key != "new" else val.strip(" ")
        val = val.replace("\\n", "\n").replace("\\t", "\t")
        cur[key] = cur[key] + "\n" + val if key in cur and key == "why" else val
    for m in muts:
        for k in ("id", "file", "old", "new", "tests"):
            if k not in m:
                sys.exit("mutations.txt: block %r lacks %s:" % (m.get("id", "?"), k))
    return muts


def run(cmd, cwd, timeout=900):
    try:
        r = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout)
        return r.returncode, r.stdout.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        return 124, "timeout"


def make_for(m, scratch):
    """build/frac and the unit tests a mutation's filters select (the runner
    runs every unit binary whose name matches, so all of those are rebuilt)"""
    units = sorted(f[:-2] for f in os.listdir(os.path.join(scratch, "tests/unit"))
                   if f.startswith("test_") and f.endswith(".c"))
    flts = m["tests"].split()
    return ["make", "-j2", "build/frac"] + ["build/tests/" + u for u in units
                                            if any(f in "unit/" + u for f in flts)]


def main():
    args = sys.argv[1:]
    scratch = "/tmp/%s-mut" % os.environ.get("USER", "frac")
    if "--scratch" in args:
        i = args.index("--scratch")
        scratch = args[i + 1]
        del args[i:i + 2]
    muts = load(os.path.join(HERE, "mutations.txt"))
    if "--list" in args:
        for m in muts:
            print(m["id"])
        return 0
    if args:
        unknown = [a for a in args if a not in {m["id"] for m in muts}]
        if unknown:
            sys.exit("unknown mutation: " + " ".join(unknown))
        muts = [m for m in muts if m["id"] in args]
    # a scratch copy of the tracked files (the build folder is kept between runs)
    files = subprocess.run(["git", "ls-files"], cwd=ROOT, stdout=subprocess.PIPE, check=True).stdout.decode().split("\n")
    os.makedirs(scratch, exist_ok=True)
    for f in files:
        if not f:
            continue
        src, dst = os.path.join(ROOT, f), os.path.join(scratch, f)
        if os.path.isfile(src) and (not os.path.exists(dst) or open(src, "rb").read() != open(dst, "rb").read()):
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            shutil.copy(src, dst)  # a new mtime: make rebuilds what depends on it
    make = ["make", "-j2", "build/frac", "unit", "build/runner", "build/ptyrun"]
    rc, out = run(make, scratch)
    if rc:
        print(out[-3000:])
        sys.exit("the unmutated scratch copy does not build")
    bad = 0
    for m in muts:
        path = os.path.join(scratch, m["file"])
        orig = open(path, encoding="utf-8").read()
        if orig.count(m["old"]) != 1:
            print("%-24s ERROR: 'old' occurs %d times in %s" % (m["id"], orig.count(m["old"]), m["file"]))
            bad += 1
            continue
        t0 = time.time()
        try:
            open(path, "w", encoding="utf-8").write(orig.replace(m["old"], m["new"]))
            rc, out = run(make_for(m, scratch), scratch)
            verdict, by = None, ""
            if rc:
                verdict, by = "caught", "build"
            else:
                for flt in m["tests"].split():
                    rc, out = run(["build/runner", "--frac", "build/frac", "--unit", "build/tests",
                                   "--ptyrun", "build/ptyrun", flt], scratch)
                    if out.strip().split("\n")[-1].strip() == "0 passed, 0 failed":
                        verdict, by = "ERROR", "filter %s runs no test" % flt
                        bad += 1
                        break
                    if rc:
                        fails = [l.split()[1] for l in out.split("\n") if l.startswith("FAIL ")]
                        verdict, by = "caught", flt + (" (" + ", ".join(fails[:3]) + ")" if fails else "")
                        break
            if not verdict:
                verdict = "survived" + (" (equivalent)" if "why" in m else "")
                if "why" not in m:
                    bad += 1
        finally:
            open(path, "w", encoding="utf-8").write(orig)
            os.utime(path)
        print("%-24s %-22s %s  [%.0fs]" % (m["id"], verdict, by, time.time() - t0), flush=True)
    run(make, scratch)  # leave the scratch build unmutated
    print("%d mutations, %d survivors without a reason" % (len(muts), bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
