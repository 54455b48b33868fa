#!/usr/bin/env python3
"""Where a profile's time sits by *source file*, inlined code included.

`perf report --sort sym` charges inlined code to the function it was inlined into, so
the spectral arithmetic (36-bin loops inlined into every integrator and BxDF) never
shows up by name. This script maps every sampled instruction address to its inline
chain (`addr2line -i`) and counts a sample for the first PATTERN found anywhere in the
chain; for those samples it also says whether the instruction was a packed SSE/AVX
operation (`mulps`, `addps`, `maxps`, `cmpeqps`, ...) or a scalar one (`mulss`, ...).

    perf record -F 4000 -o cornell.perf target/release/rust-v render scenes/cornell.ron \\
        --width 128 --height 128 --spp 32 --threads 1 -q -o /tmp/c.exr
    scripts/profile_share.py cornell.perf target/release/rust-v color/spectrum.rs color/cie.rs

Needs perf, addr2line, nm and objdump (binutils); the binary needs line tables
(`debug = 1` in the release profile).
"""
import collections
import re
import subprocess
import sys


def run(*cmd):
    return subprocess.run(cmd, capture_output=True, text=True, check=False).stdout


def main(perf_data, binary, patterns):
    syms = {}
    for line in run("nm", binary).splitlines():
        p = line.split()
        if len(p) == 3:
            syms[p[2]] = int(p[0], 16)
    # perf prints PIE addresses as loaded; symbol + offset gives the file address.
    counts, total = collections.Counter(), 0
    name = binary.rsplit("/", 1)[-1]
    for line in run("perf", "script", "--no-demangle", "-i", perf_data, "-F", "ip,sym,symoff,dso").splitlines():
        p = line.split()
        if not p:
            continue
        total += 1
        m = re.match(r"(\S+)\+0x([0-9a-f]+)", p[1]) if len(p) > 1 else None
        if m and m.group(1) in syms and name in line:
            counts[syms[m.group(1)] + int(m.group(2), 16)] += 1
    addrs = sorted(counts)
    chains, cur = {}, None
    for line in run("addr2line", "-i", "-a", "-e", binary, *[hex(a) for a in addrs]).splitlines():
        if line.startswith("0x"):
            cur = int(line, 16)
            chains[cur] = []
        elif line and cur is not None:
            chains[cur].append(line)
    mnemonic = {}
    for line in run("objdump", "-d", "--no-show-raw-insn", binary).splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s+(\S+)", line)
        if m and int(m.group(1), 16) in counts:
            mnemonic[int(m.group(1), 16)] = m.group(2)
    hits, kinds, lines = collections.Counter(), collections.Counter(), collections.Counter()
    for a, n in counts.items():
        for frame in chains.get(a, []):
            pat = next((p for p in patterns if p in frame), None)
            if pat:
                hits[pat] += n
                lines[frame.rsplit("/src/", 1)[-1].split(" ")[0]] += n
                op = mnemonic.get(a, "?")
                packed = re.search(r"p[sd]$", op) or (op.startswith("p") and op not in ("push", "pop"))
                kinds["packed" if packed else "scalar" if re.search(r"s[sd]$", op) else "other"] += n
                break
    share = sum(hits.values())
    print(f"{perf_data}: {total} samples; {share} ({100 * share / max(total, 1):.1f}%) in {', '.join(patterns)}")
    for p in patterns:
        print(f"  {100 * hits[p] / max(total, 1):5.2f}%  {p}")
    print(f"  instructions there: {dict(kinds)} (packed = SIMD on 4+ lanes; scalar = one float)")
    for k, v in lines.most_common(8):
        print(f"    {100 * v / max(total, 1):5.2f}%  {k}")


if __name__ == "__main__":
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3:])
