#!/usr/bin/env python3
"""The stack bound's resolution of indirect calls, on small crafted images:
`python3 firmware/size-budget/test_stack_bound.py`."""

import struct
import unittest

import stack_bound as sb

RODATA = 0x08001000
TEXT = 0x08000000


def image(rodata_words, text_words=(), vectors=()):
    """An image with `.rodata` at RODATA holding the given words, and
    literal words in `.text` at TEXT + 0x800."""
    sections = [
        (".vector_table", 0x07FFF000, struct.pack("<%dI" % len(vectors), *vectors), False),
        (".rodata", RODATA, struct.pack("<%dI" % len(rodata_words), *rodata_words), False),
        (".text", TEXT + 0x800, struct.pack("<%dI" % len(text_words), *text_words), False),
    ]
    return sb.Image(sections, {})


def dis(functions):
    """objdump-style text: {name: (start, [(mnemonic, operands)])}, each
    instruction 2 bytes."""
    out = []
    for name, (start, insns) in functions.items():
        out.append(f"{start:08x} <{name}>:")
        for k, (m, ops) in enumerate(insns):
            out.append(f" {start + 2 * k:x}:      \t{m}\t{ops}")
        out.append("")
    return "\n".join(out)


def fn(start, frame, *body):
    return (start, [("push", "{" + ", ".join(f"r{i}" for i in range(frame // 4)) + "}")]
            + list(body) + [("pop", "{r4, pc}")])


A, B, C, D = 0x08000100, 0x08000200, 0x08000300, 0x08000400
LITERAL = TEXT + 0x800  # holds B | 1


def leaves():
    return {"alpha": fn(A, 8), "beta": fn(B, 16), "gamma": fn(C, 32), "delta": fn(D, 64)}


class Resolution(unittest.TestCase):
    def analyse(self, functions, img):
        a = sb.Analysis(sb.parse_disassembly(dis(functions)), img)
        return a, {n: [t for _, t in s] for n, s in a.sites.items() if s}

    def test_a_literal_in_a_register_is_that_function(self):
        f = leaves()
        f["caller"] = fn(0x08000500, 8,
                         ("ldr", f"r4, [pc, #4]            @ 0x{LITERAL:x}"),
                         ("blx", "r4"),
                         ("movs", "r0, #1"),
                         ("blx", "r4"))
        # `alpha` and `gamma` are in a vtable too: a literal call must not
        # reach them.
        vt = [0, 4, 4, A | 1, C | 1]
        _, sites = self.analyse(f, image(vt, [B | 1, RODATA]))
        self.assertEqual(sites["caller"], [{"beta"}, {"beta"}])

    def test_a_vtable_slot_reaches_the_functions_at_that_offset_only(self):
        f = leaves()
        f["caller"] = fn(0x08000500, 8,
                         ("ldr", "r1, [r0, #12]"),
                         ("blx", "r1"))
        # Two vtables (drop, size, align, method): alpha and gamma at +12,
        # delta at +16 of the first (its second method), beta nowhere.
        vt = [0, 4, 4, A | 1, D | 1, 0, 8, 8, C | 1]
        img = image(vt, [RODATA, RODATA + 20])
        _, sites = self.analyse(f, img)
        self.assertEqual(sites["caller"], [{"alpha", "gamma"}])

    def test_a_function_stored_by_code_is_counted_at_every_slot(self):
        f = leaves()
        f["storer"] = fn(0x08000600, 8,
                         ("movw", "r0, #513"), ("movt", "r0, #2048"),  # B | 1
                         ("str", "r0, [r5, #40]"))
        f["caller"] = fn(0x08000500, 8, ("ldr", "r1, [r0, #12]"), ("blx", "r1"))
        vt = [0, 4, 4, A | 1]
        _, sites = self.analyse(f, image(vt, [RODATA]))
        self.assertEqual(sites["caller"], [{"alpha", "beta"}])

    def test_branches_join_what_each_path_loaded(self):
        f = leaves()
        f["caller"] = fn(0x08000500, 8,
                         ("cbz", "r0, 0x800050a <caller+0xa>"),
                         ("ldr", f"r4, [pc, #4]            @ 0x{LITERAL:x}"),
                         ("b", "0x800050c <caller+0xc>"),
                         ("ldr", f"r4, [pc, #4]            @ 0x{LITERAL + 4:x}"),
                         ("nop", ""),
                         ("blx", "r4"))
        _, sites = self.analyse(f, image([0], [B | 1, D | 1]))
        self.assertEqual(sites["caller"], [{"beta", "delta"}])

    def test_a_call_clobbers_and_a_spill_is_unknown(self):
        f = leaves()
        f["caller"] = fn(0x08000500, 8,
                         ("ldr", f"r3, [pc, #4]            @ 0x{LITERAL:x}"),
                         ("bl", "0x8000100 <alpha>"),
                         ("blx", "r3"),  # r3 clobbered by the call
                         ("ldr", "r4, [sp, #8]"),
                         ("blx", "r4"))  # reloaded from the stack
        a, sites = self.analyse(f, image([A | 1], [B | 1, C | 1]))
        self.assertEqual(sites["caller"], [a.taken, a.taken])
        self.assertEqual(a.taken, {"alpha", "beta", "gamma"})

    def test_an_it_block_keeps_the_old_value_too(self):
        f = leaves()
        f["caller"] = fn(0x08000500, 8,
                         ("ldr", f"r3, [pc, #4]            @ 0x{LITERAL:x}"),
                         ("it", "ne"),
                         ("ldrne", f"r3, [pc, #4]            @ 0x{LITERAL + 4:x}"),
                         ("blx", "r3"))
        # delta's address is taken too, so "anything" would include it.
        _, sites = self.analyse(f, image([0], [B | 1, C | 1, D | 1]))
        self.assertEqual(sites["caller"], [{"beta", "gamma"}])


class Bound(unittest.TestCase):
    def executor_image(self, task_calls_back):
        """main runs the executor, which polls a task through its header;
        the task makes an unresolved indirect call (a waker: anything)."""
        poll = "_ZN16embassy_executor3raw20TaskStorage$LT$F$GT$4poll17h0E"
        execp = "_ZN16embassy_executor3raw8Executor4poll17h0E"
        body = [("ldr", "r4, [sp, #4]"), ("blx", "r4")] if task_calls_back else []
        f = {
            "main": fn(0x08000100, 8, ("bl", "0x8000200 <%s>" % execp)),
            execp: fn(0x08000200, 16, ("ldr", "r1, [r0, #12]"), ("blx", "r1")),
            poll: fn(0x08000300, 400, *body),
            "wake": fn(0x08000400, 24),
            "spawn": fn(0x08000500, 8, ("movw", "r0, #769"), ("movt", "r0, #2048"),
                        ("str", "r0, [r1, #12]")),
            "IRQ": fn(0x08000600, 32, ("bl", "0x8000400 <wake>")),
            "IRQ2": fn(0x08000700, 48),
        }
        waker_vt = [0x08000401, 0x08000401, 0x08000401, 0x08000401]
        # Vectors: 0 stack, 1 reset, then IRQ 50 (TIM5, P5) and IRQ 0 and
        # IRQ 1 (both priority 0: only the deeper one counts).
        vectors = [0] * 68
        vectors[16 + 50] = 0x08000601
        vectors[16 + 0] = 0x08000601
        vectors[16 + 1] = 0x08000701
        return dis(f), image(waker_vt, [RODATA], vectors)

    def test_a_task_poll_is_entered_from_the_executor_not_from_itself(self):
        text, img = self.executor_image(task_calls_back=True)
        lines, main_bound, interrupts, failures = sb.analyse(sb.parse_disassembly(text), img)
        self.assertEqual(failures, [])
        # main 8 > executor 16 > poll 400 > wake 24: the task's unknown
        # call reaches wake, not the task poll again.
        self.assertEqual(main_bound, 8 + 16 + 400 + 24)
        # Priority 0: IRQ (32, and wake 24) is deeper than IRQ2 (48), and
        # only one of them counts; priority 5: IRQ again.
        frame = sb.EXCEPTION_FRAME
        self.assertEqual(interrupts, 2 * (32 + 24 + frame))

    def test_without_the_executor_poll_symbol_every_site_outside_tasks_dispatches(self):
        text, img = self.executor_image(task_calls_back=False)
        a = sb.Analysis(sb.parse_disassembly(text), img)
        a.graph()
        self.assertEqual(a.dispatchers, {"_ZN16embassy_executor3raw8Executor4poll17h0E"})

    def test_the_memory_plan_holds_statics_plus_the_bound(self):
        self.assertEqual(sb.SRAM_PLAN, 120 * 1024)
        self.assertEqual(sb.plan_failures(42_000, 60_000), [])
        self.assertEqual(sb.plan_failures(60_000, 62_880), [])
        [failure] = sb.plan_failures(60_000, 62_881)
        self.assertIn("122881 B exceeds the memory plan's 122880 B", failure)
        self.assertTrue(sb.plan_failures(1, 1, plan=1))

    def test_recursion_outside_fmt_fails(self):
        f = {"main": fn(0x08000100, 8, ("bl", "0x8000200 <loop>")),
             "loop": fn(0x08000200, 8, ("bl", "0x8000100 <main>"))}
        _, _, _, failures = sb.analyse(sb.parse_disassembly(dis(f)), image([0]))
        self.assertTrue(any("recursion outside core::fmt" in x for x in failures), failures)


if __name__ == "__main__":
    unittest.main()
