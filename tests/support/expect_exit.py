#!/usr/bin/env python3
"""expect_exit.py STATUS REGEX -- COMMAND...: runs COMMAND and passes only when it exits with
exactly STATUS (a crash or a signal never does) and its output, stdout and stderr as they came,
matches REGEX (Python syntax, '.' spanning lines). CTest's PASS_REGULAR_EXPRESSION ignores the exit
status and WILL_FAIL is satisfied by a segfault: this checks both."""
import re
import subprocess
import sys

if len(sys.argv) < 5 or sys.argv[3] != "--":
    sys.exit("usage: expect_exit.py STATUS REGEX -- COMMAND...")
want, pattern, command = int(sys.argv[1]), sys.argv[2], sys.argv[4:]
run = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=1200)
out = run.stdout.decode("utf-8", "replace")
problems = []
if run.returncode != want:
    got = f"signal {-run.returncode}" if run.returncode < 0 else f"status {run.returncode}"
    problems.append(f"exited with {got}, expected status {want}")
if pattern and not re.search(pattern, out, re.DOTALL):
    problems.append(f"output does not match {pattern!r}")
if problems:
    sys.stdout.write(out[-4000:])
    print("FAIL: " + "; ".join(problems))
    sys.exit(1)
print(f"ok: status {want}, output matches")
