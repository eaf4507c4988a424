#!/usr/bin/env python3
"""Reference eigenvalues for the torso degree of freedom, from an independent
implementation: BicycleParameters' MooreRiderLean2012Model (the Whipple
bicycle with a rider upper body leaning on a hip spring-damper, Moore 2012),
on its Batavus Browser + rider Jason parameter set, with the passive lean
stiffness and damping of de Lorenzo (1996).

Run once (needs `pip install bicycleparameters`); writes
tests/data/moore_rider_lean_browser_jason.csv, which
tests/rider_lean_reference.rs compares the multibody model with.
"""
import numpy as np
from bicycleparameters.models import MooreRiderLean2012Model
from bicycleparameters.parameter_dicts import mooreriderlean2012_browser_jason
from bicycleparameters.parameter_sets import MooreRiderLean2012ParameterSet

K9, C9 = 128.0, 50.0
SPEEDS = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0]

par = dict(mooreriderlean2012_browser_jason)
par["k9"], par["c9"] = K9, C9
model = MooreRiderLean2012Model(MooreRiderLean2012ParameterSet(par))
with open("tests/data/moore_rider_lean_browser_jason.csv", "w") as f:
    f.write("# MooreRiderLean2012Model (bicycleparameters), Browser + Jason, "
            f"k9 = {K9} N m/rad, c9 = {C9} N m s/rad; nonzero eigenvalues\n")
    f.write("speed_mps,re_per_s,im_rad_per_s\n")
    for v in SPEEDS:
        evals, _ = model.calc_eigen(v=v)
        for e in sorted(np.atleast_1d(evals).ravel(), key=lambda e: (e.real, e.imag)):
            if abs(e) > 1e-6:
                f.write(f"{v},{e.real:.12g},{e.imag:.12g}\n")
