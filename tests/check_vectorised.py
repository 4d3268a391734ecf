#!/usr/bin/env python3
"""Cliff guard at compile time: the loops of SOURCE marked as vector loops
must be vectorised by the build's compiler with the build's own flags.

    check_vectorised.py COMPILE_COMMANDS SOURCE [SOURCE ...]

A loop is marked by the comment `// vector loop (tests/check_vectorised.py)`
at the end of its `#pragma omp simd` line, or on a line of its own before
a loop or a launch of a body (for_each_entry). For every compile of SOURCE in
COMPILE_COMMANDS (CMake's compile_commands.json: the main build's and the
portable one's), the script runs that compile again into /dev/null with
GCC's `-fopt-info-vec-optimized` and requires a "loop vectorized" report on
the loop that follows each mark. A loop that GCC keeps out of
the vector units does not fail a test by its answers, and a timed ratio
cannot tell it on every machine (the transfers' pair sweeps, scalar, still
beat their index lists by 1.15-1.55x): this reads the compiler's own word.
Exit 0 when every marked loop is vectorised in every compile, 1 otherwise."""
import json
import os
import re
import shlex
import subprocess
import sys

MARK = "// vector loop (tests/check_vectorised.py)"


def marked_loops(source):
    """For each mark, the lines where GCC may report its loop."""
    lines = open(source).read().splitlines()
    loops = []
    for n, line in enumerate(lines):
        if MARK not in line:
            continue
        # a mark on a line of its own is for the line after it
        start = n + 1 if line.strip().startswith("//") else n
        if start < len(lines) and "#pragma omp simd" in lines[start]:
            following = [k for k in range(start + 1, min(start + 4, len(lines))) if re.match(r"\s*for \(", lines[k])]
            if not following:
                sys.exit(f"{source}:{n + 1}: no `for` after the marked pragma")
            start = following[0]
        # GCC reports a loop at its `for` or at one of the statements just
        # after it (a loop in a lambda; a launch's loop at its body's first
        # statement): the loop's line and the next two, up to a pragma
        window = [start + 1]
        for k in range(start + 1, min(start + 3, len(lines))):
            if "#pragma" in lines[k]:
                break
            window.append(k + 1)
        loops.append(window)
    return loops


def rerun(entry):
    args = entry["arguments"] if "arguments" in entry else shlex.split(entry["command"])
    out, skip = [], False
    for a in args:
        if skip:
            skip = False
            continue
        if a in ("-o", "-MT", "-MF", "-MQ"):
            skip = True
            continue
        if a in ("-MD", "-MMD"):
            continue
        out.append(a)
    out += ["-o", os.devnull, "-fopt-info-vec-optimized"]
    run = subprocess.run(out, cwd=entry["directory"], capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"the compile failed:\n{' '.join(out)}\n{run.stderr[-2000:]}")
    return run.stderr, out


def check(db, source):
    source = os.path.realpath(source)
    loops = marked_loops(source)
    if not loops:
        sys.exit(f"{source}: no marked loop")
    entries = [e for e in db if os.path.realpath(os.path.join(e["directory"], e["file"])) == source]
    if not entries:
        sys.exit(f"no compile of {source} in the compile commands")
    name = os.path.basename(source)
    failed = False
    for e in entries:
        report, args = rerun(e)
        march = next((a for a in args if a.startswith("-march=")), "(no -march)")
        done = {int(m.group(1)) for m in re.finditer(re.escape(name) + r":(\d+):\d+: optimized: loop vectorized", report)}
        for window in loops:
            ok = any(line in done for line in window)
            failed |= not ok
            print(f"{name}:{window[0]} {march}: {'vectorised' if ok else 'NOT vectorised'}")
    return failed


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    db = json.load(open(sys.argv[1]))
    failed = [check(db, source) for source in sys.argv[2:]]
    return 1 if any(failed) else 0


if __name__ == "__main__":
    sys.exit(main())
