#!/usr/bin/env python3
"""Guards on the GPU code of an offload build, read from the programs: no
device body keeps values on its lanes' private (SIMT) stack, no target
region maps anything, and the host's and the device's tables of variables
agree.

    check_device_code.py BINARY [BINARY ...]
    check_device_code.py --expect-flagged BINARY

The SIMT stack.
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

Maps. A target region that maps anything (a map clause, an implicit map,
a firstprivate scalar such as a thread_limit known only at run time)
allocates device memory at every launch for the mapped addresses, and
GCC 12's nvptx plugin then frees its cached per-warp stacks (128 KiB a
warp; 0.14 to 0.4 GB on an H200) to allocate them again at the launch: 1.5 ms a launch on
the H200 (RESULTS.md §0zf, §0zg). Launches pass what they need through the
device image instead (kernels/launch.hpp, detail::send_to_device). Every
call of libgomp's GOMP_target_ext in the host code (objdump) must pass 0
as its mapnum, its third argument (%edx, x86-64).

The variables' tables. Each translation unit's launch arguments are a
`declare target` variable of its own (kernels/launch.hpp): the host's
offload table (`.gnu.offload_vars`, an address and a size a variable) and
the device image's (mkoffload's list of their PTX names) must have as many
entries, or libgomp refuses the image when it loads it on a GPU ("Cannot
map target functions or variables"), which the host fallback never does.

Team sizes. A teams region with a thread_limit clause makes GOMP_teams4, in
every team on the device, allocate a task for the team's ICVs with the
device's malloc and free it at the team's end (gomp_new_icv, in libgomp's
nvptx PTX); on an H200 a launch then cost about 4 us a team, serialised,
1.3 ms for 396 teams (RESULTS.md §0zm). Without the clause libgomp starts 8
warps a team, the default team size (kernels/launch.hpp: TRESCA_TEAM_SIZE).
Every call of GOMP_teams4 in the PTX must pass 0 as its third argument,
unless --sized-teams (a build with another TRESCA_DEVICE_WARPS, which
needs the clause).

Exit 0 when no body uses that stack, no region maps, the tables agree and no
teams region names a size; 1 (naming what fails) otherwise. With
--expect-flagged, the reverse: exit 0 only if BINARY has a body on the
stack, a region that maps and a teams region that names its size
(tests/device_code_fixture.cpp, written with all three, shows that the
checks still see them with this compiler)."""
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


def team_sizes(ptx):
    """the thread_limit each call of GOMP_teams4 in a PTX module passes (its
    third argument; None where the code does not show a constant)"""
    sizes = []
    for part in re.split(r"\n// BEGIN ", ptx):
        lines = part.split("\n")
        for k, line in enumerate(lines):
            if "GOMP_teams4,(" not in line or "call" not in line:
                continue
            size = None
            for j in range(k - 1, max(0, k - 40), -1):
                m = re.search(r"st\.param\.u32 \[%out_arg3\],\s*(\S+);", lines[j])
                if m:
                    value = m.group(1)
                    if re.fullmatch(r"-?\d+", value):
                        size = int(value)
                    else:
                        for i in range(j - 1, max(0, j - 200), -1):
                            w = re.search(r"mov\.u32 " + re.escape(value) + r",\s*(-?\d+);", lines[i])
                            if w:
                                size = int(w.group(1))
                                break
                    break
            sizes.append(size)
    return sizes


def mapping_regions(binary):
    """the host code's calls of GOMP_target_ext, as (address, mapnum or None
    where the code does not show a constant)"""
    asm = subprocess.run(["objdump", "-d", "--no-show-raw-insn", binary], capture_output=True, text=True).stdout
    lines = asm.split("\n")
    calls = []
    for k, line in enumerate(lines):
        if not re.search(r"call\s.*<GOMP_target_ext@plt>", line):
            continue
        mapnum = None
        for j in range(k - 1, max(0, k - 80), -1):  # the last write of %edx before the call
            m = re.search(r"\s(xor|mov)\s+(\S+),%(e|r)dx\s*$", lines[j])
            if m:
                if m.group(1) == "xor" and m.group(2) in ("%edx", "%rdx"):
                    mapnum = 0
                elif m.group(1) == "mov" and m.group(2).startswith("$"):
                    mapnum = int(m.group(2)[1:], 16)
                break
        calls.append((line.split(":")[0].strip(), mapnum))
    return calls


def variable_tables(binary):
    """(the host offload table's variables, the device image's): the host's
    from the section's size, the device's as the PTX variables whose names
    also stand as strings of their own (mkoffload's table)"""
    head = subprocess.run(["objdump", "-h", binary], capture_output=True, text=True).stdout
    m = re.search(r"\s\.gnu\.offload_vars\s+([0-9a-f]+)", head)
    host = int(m.group(1), 16) // 16 if m else 0
    data = open(binary, "rb").read()
    names = set(re.findall(rb"// BEGIN VAR DEF: (\S+)", data))
    device = sum(1 for n in names if b"\0" + n + b"\0" in data)
    return host, device


def demangled(name):
    base = name.split("$")[0]
    return subprocess.run(["c++filt", base], capture_output=True, text=True).stdout.strip()[:220]


def main():
    args = sys.argv[1:]
    expect = "--expect-flagged" in args
    sized_teams = "--sized-teams" in args
    binaries = [a for a in args if a not in ("--expect-flagged", "--sized-teams")]
    if not binaries:
        sys.exit(__doc__)
    flagged, scanned, maps, regions, tables, sized, teams = [], 0, [], 0, [], [], 0
    for binary in binaries:
        for image in images(binary):
            for module in modules(image):
                scanned += 1
                for name, n in simt_stack_users(module):
                    flagged.append((os.path.basename(image), name, n))
                for size in team_sizes(module):
                    teams += 1
                    if size != 0 and not sized_teams:
                        sized.append((os.path.basename(image), size))
            for address, mapnum in mapping_regions(image):
                regions += 1
                if mapnum != 0:
                    maps.append((os.path.basename(image), address, mapnum))
            host, device = variable_tables(image)
            if host != device:
                tables.append((os.path.basename(image), host, device))
    if scanned == 0:
        sys.exit(f"no device code (PTX) in {' '.join(binaries)}: not an offload build?")
    unique = sorted(set(flagged))
    for image, name, n in unique:
        print(f"{image}: {n} accesses to the SIMT stack in {demangled(name)}")
    for image, address, mapnum in maps:
        what = f"maps {mapnum}" if mapnum is not None else "maps what the code does not show"
        print(f"{image}: the target region launched at {address} {what}")
    for image, host, device in tables:
        print(f"{image}: {host} variables in the host's offload table, {device} in the device image's")
    for image, size in sorted(set(sized)):
        print(f"{image}: a teams region with thread_limit {size if size is not None else '(not a constant)'}")
    print(f"{scanned} PTX modules scanned, {len(unique)} bodies on the SIMT stack; "
          f"{regions} target regions, {len(maps)} that map; {len(tables)} images whose variable tables differ; "
          f"{teams} teams regions, {len(sized)} that name a team size"
          + (" (allowed: --sized-teams)" if sized_teams else ""))
    if expect:
        seen = bool(unique) and bool(maps) and bool(sized)
        print("the fixture is flagged by all three checks: they see the patterns" if seen
              else "FAILED: the fixture was not flagged by all three checks (they no longer see the patterns)")
        sys.exit(0 if seen else 1)
    if unique:
        print("FAILED: device bodies above keep locals on the lanes' private stack (see this script's header)")
    if maps:
        print("FAILED: target regions above map (see this script's header)")
    if tables:
        print("FAILED: the offload tables above differ: libgomp would refuse the image on a GPU")
    if sized:
        print("FAILED: teams regions above name a team size (see this script's header)")
    sys.exit(1 if unique or maps or tables or sized else 0)


if __name__ == "__main__":
    main()
