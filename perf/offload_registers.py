#!/usr/bin/env python3
"""Registers of the GPU code of an offload build, and the occupancy libgomp
launches it at: why GCC's offload kernels may use a GPU's memory poorly,
measured without a GPU (issue 22, item 6; perf/RESULTS.md §0n).

    python3 perf/offload_registers.py BINARY [--arch sm_90] [--fail-above N]
                                             [--limit IMAGE=N ...]

BINARY is a program of a TRESCA_OFFLOAD build (e.g. build-offload/bin/tresca).
Its device code is one image per executable and shared library (libgomp
loads each as a module of its own): the program's, and the project's
libtresca_launch.so (the launch layer and the vector kernels, CMakeLists.txt).
The script reports each image that BINARY loads (ldd). It needs CUDA's ptxas
and nvlink on PATH (or in /usr/local/cuda/bin); without them it says so and
exits 0.

How it measures. mkoffload keeps the device code in the program as PTX text,
one string per module (ours, libgomp's, libgcc's, newlib's); the libgomp
plugin JIT-links them on the GPU. This script compiles each module with
`ptxas -c` and links them with `nvlink -v`, as the driver's JIT does, and
reads each kernel's register count. Every OpenMP kernel enters through
libgomp's gomp_nvptx_main and GOMP_parallel, which call the region's body
through a function pointer; the linker cannot tell which body, so it gives
every kernel the registers of the most demanding function any pointer may
reach: one heavy body sets the registers of all kernels of the program.
That is why the vector kernels are an image of their own (RESULTS.md §0z):
in the program's they had the apply's registers. To attribute the count, the
script adds one probe kernel per outlined body (`..$_omp_fn$N`), which calls
it directly, and reports the probes.

What it means on the GPU. libgomp (plugin-nvptx.c) starts a kernel with
teams of W warps (the build's TRESCA_DEVICE_WARPS, 8 by default) and as many teams as
its estimate of what is resident at once: floor(R / (registers x 32 x W))
a multiprocessor, R = 65,536 registers an SM on sm_70 to sm_90. An SM holds
at most 64 warps; a memory-bound kernel needs many of them to keep enough
loads in flight."""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile


def tool(name):
    return shutil.which(name) or (f"/usr/local/cuda/bin/{name}" if os.path.exists(f"/usr/local/cuda/bin/{name}") else None)


def modules(binary):
    data = open(binary, "rb").read()
    out = []
    for m in re.finditer(rb"\.version \d", data):
        s = m.start()
        b = data.rfind(b"\0", 0, s) + 1
        out.append(data[b:data.index(b"\0", s)].decode())
    return out


def short_name(mangled):
    base = mangled.split("$")[0]
    d = subprocess.run(["c++filt", base], capture_output=True, text=True).stdout.strip()
    inner = d.split("<", 1)[1] if "<" in d else d
    inner = inner.replace("tresca::", "").replace("(anonymous namespace)::", "")
    inner = re.sub(r"^(float|double), ", "", inner)  # for_each_block_with_scratch<T, ...>
    name = re.split(r"[(<]", inner, 1)[0]
    tmpl = re.match(r"[\w:]+<(float|double)", inner)
    return name + (f"<{tmpl.group(1)}>" if tmpl else "")


def images(binary):
    """binary and the shared libraries it loads that hold PTX: its device images"""
    out = [binary]
    r = subprocess.run(["ldd", binary], capture_output=True, text=True)
    for line in r.stdout.splitlines():
        m = re.search(r"=> (/\S+)", line)
        if m and os.path.basename(m.group(1)).startswith("libtresca"):
            out.append(m.group(1))
    return [f for f in out if modules(f)]


def image_registers(path, arch, ptxas, nvlink):
    """(registers of each kernel as linked, [(registers, body) of each body called directly])"""
    mods = modules(path)
    bodies = []
    for k, t in enumerate(mods):
        names = sorted(set(re.findall(r"^\.func (\S+\$_omp_fn\$\d+) \(\.param \.u64 %in_ar0\)", t, re.M)))
        for n in names:  # visible, so that a probe in another module may call it
            t = re.sub(r"^\.func " + re.escape(n) + " ", ".visible .func " + n + " ", t, flags=re.M)
        bodies += names
        mods[k] = t
    probe = [".version 7.0", ".target sm_80", ".address_size 64"]
    for i, n in enumerate(bodies):
        probe.append(f".extern .func {n} (.param .u64 %in_ar0);")
        probe.append(f".visible .entry probe{i} (.param .u64 %p) {{ .reg .u64 %r; ld.param.u64 %r,[%p]; "
                     f"{{ .param .u64 %a; st.param.u64 [%a],%r; call {n},(%a); }} ret; }}")
    mods.append("\n".join(probe) + "\n")
    with tempfile.TemporaryDirectory() as tmp:
        cubins = []
        for k, t in enumerate(mods):
            p = os.path.join(tmp, f"m{k}.ptx")
            open(p, "w").write(t)
            subprocess.run([ptxas, f"-arch={arch}", "-c", "-O3", p, "-o", p + ".cubin"], check=True)
            cubins.append(p + ".cubin")
        r = subprocess.run([nvlink, f"-arch={arch}", "-v"] + cubins + ["-o", os.path.join(tmp, "image.cubin")],
                           capture_output=True, text=True, check=True)
    regs, name = {}, None
    for line in (r.stdout + r.stderr).splitlines():
        m = re.search(r"Function properties for '(\S+)'", line)
        if m:
            name = m.group(1)
            continue
        m = re.search(r"used (\d+) registers", line)
        if m and name:
            regs[name] = int(m.group(1))
            name = None
    kernels = [v for n, v in regs.items() if not n.startswith("probe")]
    rows = sorted(((regs[f"probe{i}"], short_name(n)) for i, n in enumerate(bodies) if f"probe{i}" in regs),
                  reverse=True)
    return kernels, rows


def report(path, arch, warps, kernels, rows):
    worst = max(kernels)
    print(f"{path}: {len(kernels)} kernels, {len(rows)} outlined bodies, linked for {arch}")
    print(f"registers of every kernel as linked: {min(kernels)}..{worst}")
    print("warps a team (the build's TRESCA_DEVICE_WARPS) -> libgomp's teams an SM, warps an SM (of 64), what the SM holds:")
    granted = -(-worst // 8) * 8  # registers a thread as the SM grants them (in steps of 256 a warp)
    for w in sorted({1, 2, 4, 8, 16, warps}):
        w = min(w, 32, 65536 // (granted * 32))  # libgomp caps a team at the kernel's largest block
        teams = 65536 // (worst * 32 * w)  # libgomp's estimate (plugin-nvptx.c)
        # the hardware's: registers granted per warp in units of 256, at most 32 teams and 64 warps an SM
        held = min(32, 65536 // (granted * 32 * w), 64 // w)
        note = "" if teams <= held else f"  (holds {held}: the last teams wait for a second round)"
        mark = " <- this build" if w == warps else ""
        print(f"  {w:2d} -> {teams:2d} team(s), {teams * w:2d} warps ({100.0 * teams * w / 64:4.1f} %){note}{mark}")
    print("registers of each body (called directly):")
    for rg, n in rows:
        print(f"  {rg:4d}  {n}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("binary")
    ap.add_argument("--arch", default="sm_90", help="GPU to link for (sm_90: H100)")
    ap.add_argument("--warps", type=int, default=int(os.environ.get("TRESCA_DEVICE_WARPS", "8")),
                    help="warps a team (the build's TRESCA_DEVICE_WARPS; libgomp's default 8)")
    ap.add_argument("--fail-above", type=int, default=0,
                    help="exit 1 if the kernels of any image use more registers than this")
    ap.add_argument("--limit", action="append", default=[], metavar="IMAGE=N",
                    help="exit 1 if the kernels of the image whose file name contains IMAGE use more than N")
    a = ap.parse_args()
    if not os.path.isfile(a.binary):
        ap.error(f"{a.binary}: no such program")
    limits = []
    for spec in a.limit:
        m = re.fullmatch(r"([^=]+)=(\d+)", spec)
        if not m:
            ap.error(f"--limit {spec}: want IMAGE=N")
        limits.append((m.group(1), int(m.group(2))))
    ptxas, nvlink = tool("ptxas"), tool("nvlink")
    if not ptxas or not nvlink:
        print("offload_registers: skipped: CUDA's ptxas and nvlink are not installed")
        return 0
    found = images(a.binary)
    if not found:
        print(f"offload_registers: {a.binary} and its libraries hold no PTX (not an offload build?)")
        return 2
    failed = False
    for path in found:
        kernels, rows = image_registers(path, a.arch, ptxas, nvlink)
        report(path, a.arch, a.warps, kernels, rows)
        worst, name = max(kernels), os.path.basename(path)
        for what, limit in [("any image", a.fail_above)] + [(f"an image named *{k}*", n) for k, n in limits
                                                           if k in name]:
            if limit and worst > limit:
                print(f"offload_registers: the kernels of {name} use {worst} registers, more than {limit} ({what})")
                failed = True
    for k, _ in limits:
        if not any(k in os.path.basename(p) for p in found):
            print(f"offload_registers: no image named *{k}* (--limit)")
            failed = True
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
