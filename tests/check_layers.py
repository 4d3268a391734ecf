#!/usr/bin/env python3
"""The layers of the code point one way (CMakeLists.txt, README "Code map").

Every #include "..." of a project header in kernels/ and core/<layer>/ must
name its own layer or one below it:

    kernels -> util -> parallel, solvers -> fem -> multigrid -> contact -> io

(parallel and solvers are side by side: neither includes the other). Exits 1
and lists the offending lines otherwise. Usage: check_layers.py [SOURCE_DIR]
"""
import pathlib
import re
import sys

BELOW = {
    "kernels": [],
    "util": ["kernels"],
    "parallel": ["util"],
    "solvers": ["util"],
    "fem": ["parallel", "solvers"],
    "multigrid": ["fem"],
    "contact": ["multigrid"],
    "io": ["contact"],
}


def allowed(layer):
    seen, todo = {layer}, [layer]
    while todo:
        for d in BELOW[todo.pop()]:
            if d not in seen:
                seen.add(d)
                todo.append(d)
    return seen


def layer_of(path):
    parts = pathlib.PurePosixPath(path).parts
    if parts[0] == "kernels":
        return "kernels"
    if parts[0] == "core" and len(parts) > 2:
        return parts[1]
    return None


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    bad, files = [], 0
    include = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
    for f in sorted(list(root.glob("kernels/*.[ch]pp")) + list(root.glob("core/*/*.[ch]pp"))):
        rel = f.relative_to(root).as_posix()
        me = layer_of(rel)
        if me not in BELOW:
            bad.append(f"{rel}: directory core/{me} is not a layer of check_layers.py")
            continue
        files += 1
        ok = allowed(me)
        for n, line in enumerate(f.read_text().splitlines(), 1):
            m = include.match(line)
            if not m:
                continue
            target = m.group(1)
            if "/" not in target:  # a header of the same directory ("grid.hpp" in kernels/)
                continue
            other = layer_of(target)
            if other is None or other not in ok:
                bad.append(f"{rel}:{n}: {me} includes {target} ({other or 'outside the layers'})")
    if files == 0:
        print(f"check_layers: no sources under {root}")
        return 1
    for b in bad:
        print(b)
    print(f"check_layers: {files} files, {len(bad)} includes against the layering")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
