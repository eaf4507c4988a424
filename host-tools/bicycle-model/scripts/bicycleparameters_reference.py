#!/usr/bin/env python3
"""Reference weave and capsize speeds of BicycleParameters' six measured
bicycles (Moore 2012: Browser, Crescendo, Fisher, Pista, Stratos, Yellow) and
of the benchmark bicycle (Meijaard et al. 2007), with their parameter files
as BicycleParameters writes them.

Run once (needs `pip install bicycleparameters`), from host-tools/bicycle-model:

    python3 scripts/bicycleparameters_reference.py DATA

where DATA is the `data` directory of the BicycleParameters source (it holds
`bicycles/NAME/RawData/NAMEMeasured.txt`). For each bicycle the benchmark
parameters are recomputed from the measured ones (`forceRawCalc=True`), written
by `Bicycle.save_parameters()` (so the file carries every line BicycleParameters
writes: `IRzz`, `IFzz`, `yB`, `yH`, ... with their uncertainties) and copied to
tests/data/bicycleparameters/NAMEBenchmark.txt. The benchmark bicycle has no
measured data; its shipped parameter file is loaded and saved the same way.

The critical speeds come from the saved file, reloaded (its values rounded to
their uncertainties as BicycleParameters writes them), through BicycleParameters'
canonical matrices
(`Bicycle.canonical`, `M q'' + v C1 q' + (g K0 + v^2 K2) q = 0`) by two
closed conditions, each checked against the eigenvalues there:
- capsize: a real eigenvalue crosses zero where det(g K0 + v^2 K2) = 0
  (a polynomial in v^2);
- weave: a pair crosses the imaginary axis where the Hurwitz determinant
  a3 a2 a1 - a4 a1^2 - a0 a3^2 of the characteristic quartic
  det(M s^2 + v C1 s + g K0 + v^2 K2) is zero (root by Brent, scipy).
Written to tests/data/bicycleparameters/critical_speeds.csv.
"""
import os
import shutil
import sys
import tempfile

import numpy as np
from numpy.polynomial import polynomial as P
from scipy.optimize import brentq
import bicycleparameters as bp

MEASURED = ["Browser", "Crescendo", "Fisher", "Pista", "Stratos", "Yellow"]
# Shipped with BicycleParameters with every line it can write (IRzz, IFzz, yB,
# yH): copied as it is, for the parser's tests.
AS_SHIPPED = "Silver"
OUT = os.path.join("tests", "data", "bicycleparameters")


def char_poly(M, C1, K0, K2, g, v):
    """Coefficients (a0 .. a4) of det(M s^2 + v C1 s + g K0 + v^2 K2)."""
    e = [[np.array([g * K0[i, j] + v * v * K2[i, j], v * C1[i, j], M[i, j]])
          for j in range(2)] for i in range(2)]
    return P.polysub(P.polymul(e[0][0], e[1][1]), P.polymul(e[0][1], e[1][0]))


def hurwitz3(M, C1, K0, K2, g, v):
    a0, a1, a2, a3, a4 = char_poly(M, C1, K0, K2, g, v)
    return a3 * a2 * a1 - a4 * a1 * a1 - a0 * a3 * a3


def eigenvalues(M, C1, K0, K2, g, v):
    Mi = np.linalg.inv(M)
    A = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-Mi @ (g * K0 + v * v * K2), -v * Mi @ C1]])
    return np.linalg.eigvals(A)


def critical_speeds(M, C1, K0, K2, g):
    # Capsize: det(g K0 + x K2) = d0 + d1 x + d2 x^2, x = v^2.
    A, B = g * K0, K2
    d0 = np.linalg.det(A)
    d1 = A[0, 0] * B[1, 1] + A[1, 1] * B[0, 0] - A[0, 1] * B[1, 0] - A[1, 0] * B[0, 1]
    d2 = np.linalg.det(B)
    xs = [x.real for x in np.roots([d2, d1, d0]) if abs(x.imag) < 1e-12 and x.real > 0]
    capsize = [np.sqrt(x) for x in xs]
    # Weave: sign changes of the Hurwitz determinant on a fine grid, refined,
    # kept where the eigenvalues there hold a pair on the imaginary axis.
    grid = np.linspace(0.05, 20.0, 4000)
    h = [hurwitz3(M, C1, K0, K2, g, v) for v in grid]
    weave = []
    for k in range(len(grid) - 1):
        if np.sign(h[k]) != np.sign(h[k + 1]):
            v = brentq(lambda s: hurwitz3(M, C1, K0, K2, g, s), grid[k], grid[k + 1],
                       xtol=1e-14, rtol=1e-15)
            ev = eigenvalues(M, C1, K0, K2, g, v)
            if any(abs(e.real) < 1e-7 and abs(e.imag) > 1e-3 for e in ev):
                weave.append(v)
    for v in capsize:
        ev = eigenvalues(M, C1, K0, K2, g, v)
        assert min(abs(ev)) < 1e-7, (v, ev)
    return weave, capsize


def main(data):
    os.makedirs(OUT, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in MEASURED + ["Benchmark"]:
            src = os.path.join(data, "bicycles", name)
            dst = os.path.join(tmp, "bicycles", name)
            shutil.copytree(src, dst)
            measured = name != "Benchmark"
            if measured:
                shutil.rmtree(os.path.join(dst, "Parameters"), ignore_errors=True)
                os.makedirs(os.path.join(dst, "Parameters"))
            bike = bp.Bicycle(name, pathToData=tmp, forceRawCalc=measured)
            if not measured:
                os.remove(os.path.join(dst, "Parameters", name + "Benchmark.txt"))
            bike.save_parameters()
            shutil.copy(os.path.join(dst, "Parameters", name + "Benchmark.txt"), OUT)
            # The values as written (rounded to their uncertainties), so that
            # the file and the speeds agree.
            bike = bp.Bicycle(name, pathToData=tmp)
            M, C1, K0, K2 = bike.canonical(nominal=True)
            g = bike.parameters["Benchmark"]["g"]
            g = float(getattr(g, "nominal_value", g))
            weave, capsize = critical_speeds(M, C1, K0, K2, g)
            for v in weave:
                rows.append((name, "weave", v))
            for v in capsize:
                rows.append((name, "capsize", v))
    shutil.copy(os.path.join(data, "bicycles", AS_SHIPPED, "Parameters",
                             AS_SHIPPED + "Benchmark.txt"), OUT)
    with open(os.path.join(OUT, "critical_speeds.csv"), "w") as f:
        f.write(f"# bicycleparameters {bp.__version__}: weave (Hurwitz determinant) and "
                "capsize (det K) speeds of the Whipple model, m/s\n")
        f.write("bicycle,mode,speed_mps\n")
        for name, mode, v in rows:
            f.write(f"{name},{mode},{v:.12f}\n")


if __name__ == "__main__":
    main(sys.argv[1])
