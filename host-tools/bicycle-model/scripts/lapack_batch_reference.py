#!/usr/bin/env python3
"""The batched LAPACK eigenvalue call the 1000-speed sweep is measured
against (model.md, Benchmarks): numpy's `linalg.eigvals` (LAPACK dgeev,
eigenvalues only) on a stack of 1000 state matrices of the same size and
structure as the wobble model's, `A(u) = A0 + u A1` at u = 0, 0.01, ..., 9.99.

    python3 scripts/lapack_batch_reference.py PENCIL.csv

PENCIL.csv holds A0 then A1, 14 rows each, comma separated, as written by
`PENCIL_OUT=PENCIL.csv cargo test -p wobble-model --test wobble_model -- --ignored write_pencil`
(not run in CI). Prints the median and best of 20 batched calls, in wall
time and in CPU time (`time.process_time`, which leaves out the waits for
other processes on a loaded machine).
"""
import sys
import time

import numpy as np

rows = np.loadtxt(sys.argv[1], delimiter=",")
n = rows.shape[1]
a0, a1 = rows[:n], rows[n:2 * n]
speeds = np.arange(1000) * 0.01
stack = a0[None, :, :] + speeds[:, None, None] * a1[None, :, :]
times, cpu = [], []
for _ in range(20):
    t, c = time.perf_counter(), time.process_time()
    np.linalg.eigvals(stack)
    times.append(time.perf_counter() - t)
    cpu.append(time.process_time() - c)
print(f"numpy {np.__version__}: 1000 x {n}x{n} eigvals: median {1e3 * np.median(times):.2f} ms "
      f"(min {1e3 * min(times):.2f} ms); CPU time median {1e3 * np.median(cpu):.2f} ms "
      f"(min {1e3 * min(cpu):.2f} ms)")
