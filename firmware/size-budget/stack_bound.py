#!/usr/bin/env python3
"""An upper bound on the firmware's stack depth, from the release ELF.

Usage: stack_bound.py ELF [--objdump llvm-objdump]

Method (no compiler support needed: `-Z emit-stack-sizes` is nightly-only):
- Each function's frame is the sum of every stack push and stack-pointer
  decrement in its body (`push`, `vpush`, `stmdb sp!`, `str rX, [sp, #-n]!`,
  `sub sp, #n`). Summing all of them, not only the prologue's, can only
  over-count.
- Its callees are the targets of `bl` and of branches to another function
  (tail calls, counted as if they were calls: again an over-count).
- An indirect call (`blx rN`, a `bx`/`mov pc` to a register other than lr)
  may reach any function whose address the image holds: a word in any
  section, or a `movw`/`movt` pair, equal to a function's start with the
  Thumb bit set. The bound takes the deepest of them.
- The bound of a root is its frame plus its deepest callee's bound. A cycle
  in this conservative call graph (recursion, or a function reachable
  through a pointer from itself) has no bound: it is reported and the
  script fails.
- Interrupts stack on top of whatever runs: each handler named in the
  vector table adds its own bound plus the exception frame (26 words with
  the FPU's lazy context, plus 4 bytes of alignment: 108 bytes). The total
  assumes every handler nests on every other one, which the priorities
  (fewer levels than handlers) make impossible: another over-count.

The printed total is therefore a bound, not an estimate.
"""

import argparse
import re
import struct
import subprocess
import sys
from collections import defaultdict

FUNC = re.compile(r"^([0-9a-f]{8}) <(.+)>:$")
INSN = re.compile(r"^\s*([0-9a-f]+):\s+(\S+)\s*(.*)$")
TARGET = re.compile(r"0x([0-9a-f]+)(?: <([^>+]+)(\+0x[0-9a-f]+)?>)?")
EXCEPTION_FRAME = 26 * 4 + 4
# core::fmt calls itself through `dyn Write` and the formatters of its
# arguments: a Display that uses `write!` re-enters it once per level of
# nesting. No format string of the firmware nests deeper than this.
NESTING = 3
FMT = re.compile(r"core..fmt|4core3fmt|core::fmt|fmt..Display|fmt..Debug|fmt..Write")
unknown = []


def strongly_connected(graph):
    """Tarjan's components, iteratively (the graph is deep)."""
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(graph[root]))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(graph[w])))
                    advanced = True
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                members = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    members.append(w)
                    if w == v:
                        break
                out.append(members)
    return out


def reglist_bytes(ops, unit):
    inside = ops[ops.index("{") + 1 : ops.index("}")]
    count = 0
    for part in inside.split(","):
        part = part.strip()
        if "-" in part:
            lo, hi = part.split("-")
            count += int(hi[1:]) - int(lo[1:]) + 1
        elif part:
            count += 1
    return count * unit


def frame_bytes(mnemonic, ops):
    m = mnemonic.split(".")[0]
    if m == "push":
        return reglist_bytes(ops, 4)
    if m == "vpush":
        return reglist_bytes(ops, 8 if "d" in ops.split("{")[1][:2] else 4)
    if m == "stmdb" and ops.startswith("sp!"):
        return reglist_bytes(ops, 4)
    if m in ("str", "strd") and "[sp, #-" in ops and ops.endswith("]!"):
        return int(re.search(r"#-(\d+)", ops).group(1))
    if m in ("sub", "subw") and re.match(r"sp, (sp, )?#", ops):
        return int(re.search(r"#(\d+)", ops).group(1))
    if m in ("sub", "subw") and re.match(r"sp, (sp, )?r", ops):
        raise ValueError("a frame of run-time size")
    return 0


def read_elf_words(path):
    """Every aligned 32-bit word of every allocated section, and the
    interrupt vector table (the first 98 words of .vector_table)."""
    data = open(path, "rb").read()
    (shoff,) = struct.unpack_from("<I", data, 0x20)
    shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x2E)
    sections = []
    for i in range(shnum):
        name, typ, flags, addr, off, size = struct.unpack_from(
            "<IIIIII", data, shoff + i * shentsize
        )
        sections.append((name, typ, flags, addr, off, size))
    strtab_off = sections[shstrndx][4]

    def name_of(n):
        end = data.index(b"\0", strtab_off + n)
        return data[strtab_off + n : end].decode()

    words, vectors = [], []
    for name, typ, flags, addr, off, size in sections:
        if not flags & 2 or typ == 8:  # not allocated, or NOBITS
            continue
        chunk = data[off : off + size - size % 4]
        ws = list(struct.unpack_from("<%dI" % (len(chunk) // 4), chunk))
        # The vector table's entries are reached by exceptions, never by
        # an indirect call: they are not pointers the code can call.
        if name_of(name) == ".vector_table":
            vectors = ws
        else:
            words.extend(ws)
    return words, vectors


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("elf")
    ap.add_argument("--objdump", default="llvm-objdump")
    ap.add_argument("--top", type=int, default=12)
    ap.add_argument(
        "--direct-only",
        action="store_true",
        help="ignore indirect calls: the depth of the direct call chains, NOT a bound",
    )
    args = ap.parse_args()
    dis = subprocess.run(
        [args.objdump, "-d", "--no-show-raw-insn", args.elf],
        check=True,
        capture_output=True,
        text=True,
    ).stdout

    starts = {}  # address -> name
    frame = defaultdict(int)
    calls = defaultdict(set)
    indirect = set()
    movw = {}
    pointers = set()
    dynamic = []
    current = None
    for line in dis.splitlines():
        f = FUNC.match(line)
        if f:
            current = f.group(2)
            starts[int(f.group(1), 16)] = current
            movw = {}
            continue
        i = INSN.match(line)
        if not i or current is None:
            continue
        mnemonic, ops = i.group(2), i.group(3).split(" @")[0].strip()
        try:
            frame[current] += frame_bytes(mnemonic, ops)
        except ValueError:
            dynamic.append(current)
        base = mnemonic.split(".")[0]
        if base in ("bl", "b") or (base.startswith("b") and base[1:3] in ("eq", "ne")):
            t = TARGET.search(ops)
            if t and t.group(2) and t.group(2) != current and not t.group(3):
                calls[current].add(t.group(2))
            elif t and base == "bl" and t.group(2):
                calls[current].add(t.group(2))
        if base == "blx" or (base == "bx" and ops != "lr") or (
            base == "mov" and ops.startswith("pc,")
        ):
            indirect.add(current)
        if base == "movw":
            m = re.match(r"(r\d+|lr|ip), #(\d+)", ops)
            if m:
                movw[m.group(1)] = int(m.group(2))
        if base == "movt":
            m = re.match(r"(r\d+|lr|ip), #(\d+)", ops)
            if m and m.group(1) in movw:
                pointers.add((int(m.group(2)) << 16) | movw[m.group(1)])

    words, vectors = read_elf_words(args.elf)
    pointers.update(words)
    taken = {starts[p & ~1] for p in pointers if p & 1 and (p & ~1) in starts}

    graph = {}
    for fn in starts.values():
        callees = {c for c in calls.get(fn, ()) if c in frame or c in calls}
        if fn in indirect and not args.direct_only:
            callees |= taken
        graph[fn] = callees
    sccs = strongly_connected(graph)
    scc_of = {fn: k for k, members in enumerate(sccs) for fn in members}
    memo = {}

    def bound(fn):
        """Bound of `fn`'s component (see the module docs)."""
        k = scc_of[fn]
        if k in memo:
            return memo[k]
        members = sccs[k]
        outside = {c for m in members for c in graph[m] if scc_of[c] != k}
        deepest = max((bound(c) for c in outside), default=0)
        cyclic = len(members) > 1 or fn in graph[fn]
        if cyclic:
            cycles.append(members)
            own = NESTING * sum(frame[m] for m in members)
        else:
            own = frame[fn]
        memo[k] = own + deepest
        return memo[k]

    sys.setrecursionlimit(100000)
    if dynamic:
        print("frames of run-time size in:", ", ".join(sorted(set(dynamic))))
        sys.exit(1)
    cycles = []
    main_bound = bound("main")
    handlers = {starts[v & ~1] for v in vectors[2:] if v & 1 and (v & ~1) in starts}
    handlers.discard("Reset")
    per_handler = sorted(((bound(h), h) for h in handlers), reverse=True)
    for members in {tuple(sorted(m)) for m in cycles}:
        names = ", ".join(sorted(members)[:4])
        print(f"recursion, counted {NESTING} times deep: {len(members)} functions "
              f"({sum(frame[m] for m in members)} B of frames): {names}...")
        if not all(FMT.search(m) for m in members):
            print("  not core::fmt: the nesting depth is not known")
            unknown.append(members)
    interrupts = sum(b + EXCEPTION_FRAME for b, _ in per_handler)
    print(f"functions: {len(starts)}, address-taken: {len(taken)}, "
          f"with indirect calls: {len(indirect)}")
    print(f"main (thread mode and its callees): {main_bound} B")
    for b, h in per_handler[: args.top]:
        print(f"  handler {b:6} B + {EXCEPTION_FRAME} B frame  {h}")
    print(f"interrupt handlers, all nested: {interrupts} B over {len(per_handler)} handlers")
    print(f"bound: {main_bound + interrupts} B")
    if args.direct_only:
        print("(direct calls only: not a bound)")
    if unknown:
        sys.exit(1)


if __name__ == "__main__":
    main()
