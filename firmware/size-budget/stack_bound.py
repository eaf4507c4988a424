#!/usr/bin/env python3
"""An upper bound on the firmware's stack depth, from the release ELF.

Usage: stack_bound.py ELF [--objdump llvm-objdump] [--check]

No compiler support is needed (`-Z emit-stack-sizes` is nightly-only); the
disassembly (`llvm-objdump -d`) and the ELF's own bytes are enough.

Frames. Each function's frame is the sum of every stack push and
stack-pointer decrement in its body (`push`, `vpush`, `stmdb sp!`,
`str rX, [sp, #-n]!`, `sub sp, #n`). Summing all of them, not only the
prologue's, can only over-count. A frame of run-time size fails the script.

Direct calls. The targets of `bl` and of branches to another function
(tail calls, counted as calls: an over-count).

Indirect calls (`blx rN`, `bx rN` other than `bx lr`, `mov pc, rN`). A
data-flow pass over each function's branches follows every register from
its definitions to the call, and resolves the call by what the register
can hold there:
- a constant (`ldr rN, [pc, #k]` of a literal, a `movw`/`movt` pair), as
  the size-optimised code calls a function it calls often: that function;
- a word loaded from memory at offset k (`ldr rN, [rM, #k]`, not from the
  stack): a slot of a table. Its targets are every function stored at
  offset k from any address of `.rodata` that the image refers to (the
  vtables: `RawWakerVTable`s, `dyn Trait` vtables), plus every function
  whose address is taken outside `.rodata` (a literal or `movw`/`movt` in
  the code, a word of `.data`: pointers the code can store anywhere, as
  `core::fmt` stores its arguments' formatters);
- anything else (a register spilled to the stack, an argument, an
  arithmetic result): every function whose address the image holds.
What this assumes: a function pointer that exists only in `.rodata` is
called through a pointer to the object holding it (a vtable), at its
offset in that object; every other function pointer is counted at every
slot.

Task polls. embassy-executor 0.10 stores `TaskStorage::<F>::poll` in each
task's header and calls it from `SyncExecutor::poll` alone (raw/mod.rs),
which the thread executor runs in `main` and each interrupt executor in
its interrupt; no task polls an executor. So a task's poll is never
entered from inside a task's poll: a call site in a function reachable
from a task poll is not given the task polls as targets. The script fails
if the executor's poll is reachable from a task poll, or if no task poll
is reachable at all (a changed executor that this rule would not fit).

Recursion. A cycle left in the call graph is counted NESTING times deep if
all its functions are `core::fmt`'s (a `Display` that uses `write!`
re-enters it once per nesting level; no format string of the firmware
nests deeper); any other cycle fails the script.

Interrupts nest by priority: a handler preempts only a lower priority, and
handlers of one priority never nest on each other. The bound adds, for
each priority level, the deepest handler of that level plus the exception
frame (26 words with the FPU's extended frame, plus 4 bytes of alignment:
108 bytes). NMI (-2) and HardFault (-1) are levels of their own; every
interrupt and configurable exception is at priority 0 (the NVIC's and
SHPR's reset value) unless PRIORITIES below says otherwise, which must
match the firmware's `set_priority` calls.

The printed total is therefore a bound, not an estimate. `--check`
fails (exit 1) when it exceeds the stack the image reserves: from the end
of the statics (`_stack_end`) to the top of RAM (`_stack_start`), less the
MPU guard at its bottom; and when the memory plan does not hold: the
statics in SRAM (`__sdata`, the start of RAM, to `_stack_end`) plus the
bound at most SRAM_PLAN (120 KiB of the 128 KiB; CPU-only state goes to
CCM, firmware/docs/board.md).
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
COMMENT_ADDR = re.compile(r"@ 0x([0-9a-f]+)")
REG = re.compile(r"\b(r\d+|sb|sl|fp|ip|sp|lr|pc)\b")
ALIASES = {"sb": "r9", "sl": "r10", "fp": "r11", "ip": "r12"}
CONDS = {"eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc",
         "hi", "ls", "ge", "lt", "gt", "le", "al"}
CALL_CLOBBERS = ("r0", "r1", "r2", "r3", "r12", "lr")
NO_REG_WRITE = {"cmp", "cmn", "tst", "teq", "nop", "dmb", "dsb", "isb",
                "cpsid", "cpsie", "bkpt", "wfi", "wfe", "sev", "msr",
                "vcmp", "vcmpe", "udf", "svc", "pld", "b", "bl", "cbz",
                "cbnz", "tbb", "tbh", "bx", "blx"}
STORES = {"str", "strb", "strh", "strd", "stm", "stmia", "stmdb", "push",
          "vstr", "vpush", "vstmia", "vstmdb"}
# Facts a register can hold; more than this many at once is "anything".
MAX_FACTS = 16
EXCEPTION_FRAME = 26 * 4 + 4
NESTING = 3
FMT = re.compile(r"core..fmt|4core3fmt|core::fmt|fmt..Display|fmt..Debug|fmt..Write"
                 # core's str slicing error re-slices at a char boundary
                 # (which cannot fail again) to print the string.
                 r"|4core3str\d+slice_error_fail"
                 # The machine outliner's fragments belong to their callers.
                 r"|^OUTLINED_FUNCTION_"
                 r"|3fmt\d+[A-Z]")  # v0-mangled `impl fmt::Trait`
PANIC = re.compile(r"rust_begin_unwind")
TASK_POLL = re.compile(r"TaskStorage\$LT\$F\$GT\$4poll|poll_exited")
EXECUTOR_POLL = re.compile(r"embassy_executor3raw(8|12Sync)Executor4poll")
# Vector-table index (16 + IRQn) -> NVIC priority set by the firmware
# (`firmware/stm32f405/src/main.rs`, `adapters/wheel.rs`); all others are 0.
PRIORITIES = {16 + 50: 5, 16 + 52: 6, 16 + 53: 7}  # TIM5, UART4, UART5
FIXED_LEVELS = {2: -2, 3: -1}  # NMI, HardFault
# The MPU guard at the stack's bottom (`startup::GUARD_BYTES`).
GUARD_BYTES = 256
# The memory plan: static SRAM plus the stack bound, at most (bytes).
SRAM_PLAN = 120 * 1024


def plan_failures(statics, bound, plan=SRAM_PLAN):
    """The memory plan's verdict: [] when SRAM statics plus the stack bound
    fit `plan`, else the failure to report."""
    if statics + bound <= plan:
        return []
    return [f"static SRAM {statics} B + stack bound {bound} B = {statics + bound} B "
            f"exceeds the memory plan's {plan} B (firmware/docs/board.md)"]


class Image:
    """The parts of an ELF the bound needs: allocated sections' bytes,
    symbols, and the vector table."""

    def __init__(self, sections, symbols=None):
        # sections: [(name, addr, bytes, writable)]
        self.sections = sections
        self.symbols = symbols or {}

    def words(self):
        """(section name, address, value) of every aligned word."""
        for name, addr, data, _ in self.sections:
            start = (-addr) % 4
            for off in range(start, len(data) - 3, 4):
                yield name, addr + off, struct.unpack_from("<I", data, off)[0]

    def word_at(self, address):
        for _, addr, data, _ in self.sections:
            if addr <= address and address + 4 <= addr + len(data):
                return struct.unpack_from("<I", data, address - addr)[0]
        return None

    def section(self, name):
        for s in self.sections:
            if s[0] == name:
                return s
        return None


def read_elf(path):
    data = open(path, "rb").read()
    (shoff,) = struct.unpack_from("<I", data, 0x20)
    shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x2E)
    headers = [struct.unpack_from("<IIIIIIIIII", data, shoff + i * shentsize)
               for i in range(shnum)]
    strtab_off = headers[shstrndx][4]

    def cstr(table_off, n):
        end = data.index(b"\0", table_off + n)
        return data[table_off + n: end].decode()

    sections, symbols = [], {}
    for name, typ, flags, addr, off, size, link, _, _, entsize in headers:
        if typ == 2:  # SYMTAB
            str_off = headers[link][4]
            for k in range(size // entsize):
                st_name, value = struct.unpack_from("<II", data, off + k * entsize)
                if st_name:
                    symbols[cstr(str_off, st_name)] = value
        if flags & 2 and typ != 8:  # allocated, with bytes
            sections.append((cstr(strtab_off, name), addr, data[off: off + size], bool(flags & 1)))
    return Image(sections, symbols)


class Function:
    def __init__(self, name, start):
        self.name, self.start = name, start
        self.insns = []  # (address, mnemonic, operands)


def parse_disassembly(text):
    """Functions of `llvm-objdump -d --no-show-raw-insn`; mapping symbols
    (`$t`, `$d`) continue the function they are in, data is skipped."""
    functions, current, in_data = [], None, False
    for line in text.splitlines():
        f = FUNC.match(line)
        if f:
            name = f.group(2)
            if name.startswith("$"):
                in_data = name.startswith("$d")
                continue
            current, in_data = Function(name, int(f.group(1), 16)), False
            functions.append(current)
            continue
        i = INSN.match(line)
        if not i or current is None or in_data or i.group(2).startswith("."):
            continue
        current.insns.append((int(i.group(1), 16), i.group(2), i.group(3).strip()))
    return functions


def reglist_bytes(ops, unit):
    inside = ops[ops.index("{") + 1: ops.index("}")]
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


def regs(text):
    return [ALIASES.get(r, r) for r in REG.findall(text)]


def split_cond(mnemonic, in_it):
    """Base mnemonic (no `.w`, no condition inside an IT block)."""
    base = mnemonic.split(".")[0]
    if in_it and len(base) > 2 and base[-2:] in CONDS:
        base = base[:-2]
    return base


def is_indirect(base, ops):
    return (base == "blx" and not TARGET.match(ops)) or (
        base == "bx" and ops != "lr") or (base == "mov" and ops.startswith("pc,"))


def successors(fn, index, base, ops, conditional, addr_index):
    """Indexes of the instructions that may run after insns[index]."""
    nxt = [index + 1] if index + 1 < len(fn.insns) else []
    if base in ("tbb", "tbh"):
        return list(range(index + 1, len(fn.insns)))
    if base in ("b", "cbz", "cbnz") or (base.startswith("b") and base[1:] in CONDS):
        t = TARGET.search(ops)
        inside = [addr_index[int(t.group(1), 16)]] if t and int(t.group(1), 16) in addr_index else []
        if base == "b" and not conditional:
            return inside
        return nxt + inside
    ends = (base == "bx" or (base == "pop" and "pc" in ops)
            or (base == "mov" and ops.startswith("pc,"))
            or (base.startswith("ldr") and ops.startswith("pc,")))
    if ends and not conditional:
        return []
    return nxt


def transfer(state, base, ops, comment_addr, image, conditional):
    """Register facts after one instruction. A fact: ('c', value) a
    constant, ('s', k) a word loaded at offset k, ('lo', v) half a movw."""
    out = dict(state)
    written = {}
    operands = regs(ops.split("[")[0]) if "[" in ops else regs(ops)
    first = operands[0] if operands else None
    mem = re.search(r"\[(\w+)(?:, #(-?\d+))?\](!?)", ops)
    post = re.search(r"\], #-?\d+$", ops)
    if base in ("bl", "blx"):
        for r in CALL_CLOBBERS:
            out.pop(r, None)
        return out
    if base in ("ldr", "ldrd") and mem:
        rbase = ALIASES.get(mem.group(1), mem.group(1))
        k = int(mem.group(2) or 0)
        dests = operands[:2] if base == "ldrd" else operands[:1]
        for n, d in enumerate(dests):
            if rbase == "pc" and comment_addr is not None and base == "ldr":
                v = image.word_at(comment_addr)
                written[d] = None if v is None else frozenset({("c", v)})
            elif rbase in ("pc", "sp"):
                written[d] = None
            else:
                written[d] = frozenset({("s", k + 4 * n)})
        if mem.group(3) or post:
            written[rbase] = None
    elif base == "movw" and first:
        m = re.search(r"#(\d+)", ops)
        written[first] = frozenset({("lo", int(m.group(1)))}) if m else None
    elif base == "movt" and first:
        m = re.search(r"#(\d+)", ops)
        old = state.get(first)
        if m and old and all(f[0] == "lo" for f in old):
            written[first] = frozenset(("c", (int(m.group(1)) << 16) | f[1]) for f in old)
        else:
            written[first] = None
    elif base == "mov" and re.fullmatch(r"(\w+), (\w+)", ops) and len(operands) == 2:
        written[first] = state.get(operands[1])
    elif base in NO_REG_WRITE or base.startswith("it"):
        pass
    elif base in STORES:
        if mem and (mem.group(3) or post):
            written[ALIASES.get(mem.group(1), mem.group(1))] = None
        if "!" in ops.split(",")[0]:
            written[first] = None
    else:
        for r in regs(ops):
            written[r] = None
    for r, facts in written.items():
        if conditional and facts is not None and state.get(r) is not None:
            facts = facts | state[r]
        elif conditional:
            facts = None
        if facts is None or len(facts) > MAX_FACTS:
            out.pop(r, None)
        else:
            out[r] = facts
    return out


def join(a, b):
    out = {}
    for r in a.keys() & b.keys():
        facts = a[r] | b[r]
        if len(facts) <= MAX_FACTS:
            out[r] = facts
    return out


def indirect_sites(fn, image):
    """[(address, facts or None)] for each indirect call of `fn`: what the
    called register may hold there (None: anything)."""
    addr_index = {a: k for k, (a, _, _) in enumerate(fn.insns)}
    n = len(fn.insns)
    # IT blocks: which instructions are conditional.
    conditional = [False] * n
    for k, (_, m, _) in enumerate(fn.insns):
        if m.startswith("it") and re.fullmatch(r"it[te]{0,3}", m):
            for j in range(k + 1, min(n, k + len(m))):
                conditional[j] = True
    states = [None] * n
    if n:
        states[0] = {}
    work = [0] if n else []
    sites = {}
    while work:
        k = work.pop()
        addr, mnem, ops = fn.insns[k]
        base = split_cond(mnem, conditional[k])
        ops_main = ops.split(" @")[0].strip()
        c = COMMENT_ADDR.search(ops)
        comment = int(c.group(1), 16) if c else None
        state = states[k]
        if is_indirect(base, ops_main):
            reg = regs(ops_main.split(",")[-1] if base == "mov" else ops_main)[0]
            sites[addr] = state.get(reg)
        after = transfer(state, base, ops_main, comment, image, conditional[k])
        for s in successors(fn, k, base, ops_main, conditional[k], addr_index):
            new = after if states[s] is None else join(states[s], after)
            if states[s] is None or new != states[s]:
                states[s] = new
                work.append(s)
    return sorted(sites.items())


class Analysis:
    def __init__(self, functions, image, direct_only=False):
        self.functions = functions
        self.image = image
        self.by_name = {f.name: f for f in functions}
        self.starts = {f.start: f.name for f in functions}
        self.frame = defaultdict(int)
        self.calls = defaultdict(set)
        self.dynamic = []
        self.sites = {}  # function name -> [(addr, targets)]
        self._collect(direct_only)

    def _fn_at(self, value):
        if value & 1 and (value & ~1) in self.starts:
            return self.starts[value & ~1]
        return None

    def _address_tables(self):
        rodata = self.image.section(".rodata")
        lo, hi = (rodata[1], rodata[1] + len(rodata[2])) if rodata else (0, 0)
        taken, free, bases = set(), set(), set()
        movw_consts = set()
        for f in self.functions:
            for k, (_, m, ops) in enumerate(f.insns):
                c = COMMENT_ADDR.search(ops)
                if m.startswith("adr") and c:
                    movw_consts.add(int(c.group(1), 16) | 1)
        for f in self.functions:
            state = {}
            for _, m, ops in f.insns:
                base = m.split(".")[0]
                mm = re.match(r"(\w+), #(\d+)", ops)
                if base == "movw" and mm:
                    state[mm.group(1)] = int(mm.group(2))
                elif base == "movt" and mm and mm.group(1) in state:
                    movw_consts.add((int(mm.group(2)) << 16) | state[mm.group(1)])
        vector = self.image.section(".vector_table")
        for name, addr, value in self.image.words():
            if vector and name == ".vector_table":
                continue  # reached by exceptions, never by a call
            fn = self._fn_at(value)
            if fn:
                taken.add(fn)
                if name != ".rodata":
                    free.add(fn)
            if lo <= value < hi and value % 4 == 0:
                bases.add(value)
        for value in movw_consts:
            fn = self._fn_at(value)
            if fn:
                taken.add(fn)
                free.add(fn)
            if lo <= value < hi and value % 4 == 0:
                bases.add(value)
        slot = defaultdict(set)
        for b in bases:
            for k in range(0, min(256, hi - b), 4):
                fn = self._fn_at(self.image.word_at(b + k) or 0)
                if fn:
                    slot[k].add(fn)
        return taken, free, slot

    def _collect(self, direct_only):
        taken, free, slot = self._address_tables()
        self.taken = taken
        for f in self.functions:
            for _, mnemonic, ops in f.insns:
                ops = ops.split(" @")[0].strip()
                try:
                    self.frame[f.name] += frame_bytes(mnemonic, ops)
                except ValueError:
                    self.dynamic.append(f.name)
                base = mnemonic.split(".")[0]
                if base in ("bl", "b") or (base.startswith("b") and base[1:] in CONDS) \
                        or base in ("cbz", "cbnz") or (base == "blx" and TARGET.match(ops)):
                    t = TARGET.search(ops)
                    if t:
                        callee = self.starts.get(int(t.group(1), 16))
                        if callee and callee != f.name:
                            self.calls[f.name].add(callee)
            if direct_only:
                continue
            resolved = []
            for addr, facts in indirect_sites(f, self.image):
                if facts is None:
                    targets = set(taken)
                else:
                    targets = set()
                    for kind, v in facts:
                        if kind == "c" and self._fn_at(v):
                            targets.add(self._fn_at(v))
                        elif kind == "s":
                            targets |= slot.get(v, set()) | free
                        else:
                            targets |= taken
                resolved.append((addr, targets))
            self.sites[f.name] = resolved

    def graph(self):
        """Call graph with the task-poll rule applied (module docs)."""
        polls = {n for n in self.starts.values() if TASK_POLL.search(n)}
        g = {}
        for name in self.starts.values():
            callees = set(self.calls.get(name, ()))
            for _, targets in self.sites.get(name, ()):
                callees |= targets - polls
            g[name] = callees
        in_task = reachable(g, polls)
        executors = {n for n in self.starts.values() if EXECUTOR_POLL.search(n)}
        if executors & in_task:
            raise SystemExit("the executor's poll is reachable from a task poll: "
                             "the task-poll rule does not hold for this image")
        # The poll_fn call is in SyncExecutor::poll: where a symbol of the
        # executor's poll survived inlining, only it dispatches; otherwise
        # every call site outside the tasks may.
        may_dispatch = [n for n in executors if self.sites.get(n)] or [
            n for n in self.starts.values() if n not in in_task]
        dispatchers = set()
        for name in may_dispatch:
            for _, targets in self.sites.get(name, ()):
                if targets & polls:
                    g[name] |= targets & polls
                    dispatchers.add(name)
        self.polls, self.dispatchers = polls, dispatchers
        # panic-probe 1.0 prints only on its handler's first entry (a static
        # flag); a panic inside the print re-enters it, which goes straight
        # to `udf` (a HardFault): its own frame, no callees.
        for handler in [n for n in self.starts.values() if PANIC.search(n)]:
            again = handler + " (re-entered)"
            self.frame[again] = self.frame[handler]
            g[again] = set()
            for name in reachable(g, {handler}):
                if handler in g[name]:
                    g[name] = (g[name] - {handler}) | {again}
        return g


def reachable(graph, roots):
    seen, stack = set(roots), list(roots)
    while stack:
        for c in graph.get(stack.pop(), ()):
            if c not in seen:
                seen.add(c)
                stack.append(c)
    return seen


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


class Bound:
    """Stack bounds of every function of a call graph (module docs)."""

    def __init__(self, graph, frame):
        self.graph, self.frame = graph, frame
        self.sccs = strongly_connected(graph)
        self.scc_of = {fn: k for k, members in enumerate(self.sccs) for fn in members}
        self.memo, self.cycles, self.path = {}, [], {}

    def of(self, fn):
        k = self.scc_of[fn]
        if k in self.memo:
            return self.memo[k]
        members = self.sccs[k]
        outside = {c for m in members for c in self.graph[m] if self.scc_of[c] != k}
        deepest = max(((self.of(c), c) for c in outside), default=(0, None))
        if len(members) > 1 or fn in self.graph[fn]:
            self.cycles.append(members)
            own = NESTING * sum(self.frame[m] for m in members)
        else:
            own = self.frame[fn]
        self.memo[k] = own + deepest[0]
        self.path[fn] = deepest[1]
        return self.memo[k]

    def chain(self, fn):
        out = []
        while fn is not None:
            out.append(fn)
            fn = self.path.get(fn)
        return out


def handler_levels(image, starts):
    """{priority level: [handler names]} from the vector table."""
    vector = image.section(".vector_table")
    levels = defaultdict(set)
    if not vector:
        return levels
    _, _, data, _ = vector
    for index in range(2, len(data) // 4):
        (v,) = struct.unpack_from("<I", data, index * 4)
        name = starts.get(v & ~1) if v & 1 else None
        if name is None:
            continue
        level = FIXED_LEVELS.get(index, PRIORITIES.get(index, 0))
        levels[level].add(name)
    return levels


def analyse(functions, image, direct_only=False):
    """(report lines, main's bound, interrupts' bound, failures)."""
    a = Analysis(functions, image, direct_only)
    lines, failures = [], []
    if a.dynamic:
        failures.append("frames of run-time size in: " + ", ".join(sorted(set(a.dynamic))))
    g = a.graph()
    if not direct_only:
        if not a.polls:
            failures.append("no task poll in the image: the task-poll rule cannot be checked")
        elif not (a.polls & reachable(g, {"main"})):
            failures.append("no task poll reachable from main")
        lines.append("task polls entered from: " + ", ".join(sorted(a.dispatchers)))
    b = Bound(g, a.frame)
    sys.setrecursionlimit(100000)
    main_bound = b.of("main")
    lines.append(f"main (thread mode and its callees): {main_bound} B")
    lines.append("  deepest chain: " + " > ".join(
        f"{n[:60]} ({a.frame[n]})" for n in b.chain("main")))
    interrupts = 0
    for level, names in sorted(handler_levels(image, a.starts).items()):
        worst = max((b.of(h), h) for h in names)
        interrupts += worst[0] + EXCEPTION_FRAME
        lines.append(f"  priority {level:2}: {worst[0]:6} B + {EXCEPTION_FRAME} B frame  "
                     f"{worst[1]} (deepest of {len(names)})")
    lines.append(f"interrupts, one per priority level: {interrupts} B")
    for members in {tuple(sorted(m)) for m in b.cycles}:
        lines.append(f"recursion, counted {NESTING} times deep: {len(members)} functions "
                     f"({sum(a.frame[m] for m in members)} B of frames): "
                     f"{', '.join(members[:3])}...")
        if not all(FMT.search(m) for m in members):
            failures.append(f"recursion outside core::fmt, depth unknown: {', '.join(members[:6])}")
    sites = sum(len(s) for s in a.sites.values())
    unknown = sum(1 for s in a.sites.values() for _, t in s if t == a.taken)
    lines.append(f"functions: {len(a.starts)}, address-taken: {len(a.taken)}, "
                 f"indirect call sites: {sites} ({unknown} unresolved: any address-taken function)")
    return lines, main_bound, interrupts, failures


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("elf")
    ap.add_argument("--objdump", default="llvm-objdump")
    ap.add_argument("--direct-only", action="store_true",
                    help="ignore indirect calls: the depth of the direct call chains, NOT a bound")
    ap.add_argument("--check", action="store_true",
                    help="fail when the bound exceeds the stack the image reserves")
    args = ap.parse_args()
    dis = subprocess.run([args.objdump, "-d", "--no-show-raw-insn", args.elf],
                         check=True, capture_output=True, text=True).stdout
    image = read_elf(args.elf)
    lines, main_bound, interrupts, failures = analyse(
        parse_disassembly(dis), image, args.direct_only)
    print("\n".join(lines))
    total = main_bound + interrupts
    print(f"bound: {total} B" + ("  (direct calls only: NOT a bound)" if args.direct_only else ""))
    top, end = image.symbols.get("_stack_start"), image.symbols.get("_stack_end")
    if top is not None and end is not None:
        guard = -(-end // GUARD_BYTES) * GUARD_BYTES + GUARD_BYTES
        reserved = top - guard
        print(f"stack reserved: {reserved} B (_stack_end 0x{end:08x} to _stack_start "
              f"0x{top:08x}, less the {GUARD_BYTES} B guard and its alignment)")
        if args.check and total > reserved:
            failures.append(f"the bound {total} B exceeds the reserved stack {reserved} B")
    elif args.check:
        failures.append("no _stack_start/_stack_end symbols: cannot compare")
    ram = image.symbols.get("__sdata")
    if ram is not None and end is not None:
        statics = end - ram
        print(f"memory plan: static SRAM {statics} B + stack bound {total} B = "
              f"{statics + total} B of {SRAM_PLAN} B")
        if args.check:
            failures += plan_failures(statics, total)
    elif args.check:
        failures.append("no __sdata/_stack_end symbols: cannot check the memory plan")
    for f in failures:
        print("FAIL:", f, file=sys.stderr)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
