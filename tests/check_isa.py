#!/usr/bin/env python3
"""AVX-512 only where the program dispatches to it (kernels/isa.hpp).

Disassembles a linked program with objdump and lists every function that
holds an AVX-512 instruction: EVEX-encoded (first opcode byte 0x62 after
segment or address-size prefixes; 0x62 is never anything else in 64-bit
code), or naming a zmm register, a mask register k0-k7, or xmm/ymm 16-31.
Such functions must belong to the x86-64-v4 variant (their name holds
`isa_x86_64_v4`): any other would run on a processor without AVX-512, or
under valgrind, and stop it with SIGILL.

    check_isa.py PROGRAM [--expect-variant]

Exit 0 when none lies outside the variant (with --expect-variant, also
when the variant's own functions were found: the check sees AVX-512 where
it is); 1 otherwise, naming the functions.
"""
import re
import subprocess
import sys

VARIANT = "isa_x86_64_v4"
PREFIXES = {"26", "2e", "36", "3e", "64", "65", "67"}
REGISTERS = re.compile(r"%(zmm\d+|k[0-7]\b|[xy]mm(1[6-9]|2\d|3[01])\b)")
FUNCTION = re.compile(r"^[0-9a-f]+ <(.*)>:$")
INSTRUCTION = re.compile(r"^\s*[0-9a-f]+:\t([0-9a-f ]+)\t(.*)$")


def avx512_functions(program):
    out = subprocess.run(["objdump", "-d", "-C", "-w", program],
                         check=True, capture_output=True, text=True).stdout
    found = {}
    function = None
    for line in out.splitlines():
        m = FUNCTION.match(line)
        if m:
            function = m.group(1)
            continue
        m = INSTRUCTION.match(line)
        if not m or function is None:
            continue
        raw, text = m.group(1).split(), m.group(2)
        opcode = next((b for b in raw if b not in PREFIXES), "")
        if opcode == "62" or REGISTERS.search(text):
            found.setdefault(function, text.strip())
    return found


def main():
    args = sys.argv[1:]
    expect = "--expect-variant" in args
    args = [a for a in args if a != "--expect-variant"]
    if len(args) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    found = avx512_functions(args[0])
    inside = sorted(f for f in found if VARIANT in f)
    outside = sorted(f for f in found if VARIANT not in f)
    print(f"{args[0]}: {len(inside)} functions with AVX-512 in the {VARIANT} variant, {len(outside)} outside it")
    for f in outside:
        print(f"  outside: {f}: {found[f]}")
    if outside:
        return 1
    if expect and not inside:
        print(f"  expected the {VARIANT} variant's AVX-512 functions, found none")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
