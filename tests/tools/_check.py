"""What the check tools share: the frac under test (their first argument),
check() which prints and records a failed check, and finish() which exits
1 if any check failed, else 0."""
import os
import sys

FRAC = os.path.abspath(sys.argv[1])
fails = []


def check(cond, what):
    if not cond:
        fails.append(what)
        print("FAIL:", what)
    return cond


def finish():
    sys.exit(1 if fails else 0)
