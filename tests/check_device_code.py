#!/usr/bin/env python3
"""Guard against a GCC 12 miscompile of GPU code: no device body of an
offload build may keep values on its lanes' private (SIMT) stack.

    check_device_code.py BINARY [BINARY ...]
    check_device_code.py --expect-flagged BINARY

Found on the test machine (an H200, RESULTS.md §0zg): in a body a launch
runs in a warp's lanes (`parallel for simd`: for_each_entry, and
sum_over_blocks' device form), a local whose address a call takes (an
array passed to a function, a temporary bound to std::max's references, an
out-parameter the call does not inline away) becomes a per-lane copy on
the SIMT stack (`%simtstack_ar` in the PTX), and GCC 12 then drops the
callee's writes or reads: the Newton-step operator returned values it never
computed, and the approximation step read its t and d_4 as 0. The host
fallback of the same build computes them right, so no host test can see
it; the PTX shows it. mkoffload keeps each device image as PTX text in the
program (perf/offload_registers.py: modules, images); this reads every
function of every image BINARY loads and reports each one that stores to
or loads from its SIMT stack (other than the frame link every simd region
saves). Write such bodies with scalars passed and returned by value.

Exit 0 when no body uses that stack; 1 (naming them) otherwise. With
--expect-flagged, the reverse: exit 0 only if some body of BINARY is
reported (tests/device_code_fixture.cpp, the pattern that failed, shows
that the check still sees it with this compiler)."""
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "perf"))
from offload_registers import images, modules  # noqa: E402


def simt_stack_users(ptx):
    """(mangled name, accesses) of each function of a PTX module that loads
    from or stores to its SIMT stack"""
    found = []
    for part in re.split(r"\n// BEGIN ", ptx):
        head = part.split("\n", 1)[0]
        if not re.match(r"(GLOBAL )?FUNCTION DEF: ", head):
            continue
        name = head.split(": ", 1)[1]
        regs = set(re.findall(r"cvta\.local\.u64 (%r\d+),\s*%simtstack_ar", part))
        if not regs:
            continue
        access = re.compile(r"\b(ld|st)\.\S+\s.*\[(" + "|".join(re.escape(r) for r in regs) + r")\s*(\+\s*(-?\d+))?\]")
        uses = [m for m in (access.search(line) for line in part.split("\n")) if m]
        uses = [m for m in uses if m.group(4) != "-8"]  # the frame link
        if uses:
            found.append((name, len(uses)))
    return found


def demangled(name):
    base = name.split("$")[0]
    return subprocess.run(["c++filt", base], capture_output=True, text=True).stdout.strip()[:220]


def main():
    args = sys.argv[1:]
    expect = "--expect-flagged" in args
    binaries = [a for a in args if a != "--expect-flagged"]
    if not binaries:
        sys.exit(__doc__)
    flagged, scanned = [], 0
    for binary in binaries:
        for image in images(binary):
            for module in modules(image):
                scanned += 1
                for name, n in simt_stack_users(module):
                    flagged.append((os.path.basename(image), name, n))
    if scanned == 0:
        sys.exit(f"no device code (PTX) in {' '.join(binaries)}: not an offload build?")
    unique = sorted(set(flagged))
    for image, name, n in unique:
        print(f"{image}: {n} accesses to the SIMT stack in {demangled(name)}")
    print(f"{scanned} PTX modules scanned, {len(unique)} bodies on the SIMT stack")
    if expect:
        print("the fixture's body is flagged: the check sees the pattern" if unique
              else "FAILED: the fixture's body was not flagged (the check no longer sees the pattern)")
        sys.exit(0 if unique else 1)
    if unique:
        print("FAILED: device bodies above keep locals on the lanes' private stack (see this script's header)")
    sys.exit(1 if unique else 0)


if __name__ == "__main__":
    main()
