#!/usr/bin/python3
"""Example 2: a refinement study of a dynamic quantity and its observed order.

Kane's 10 m beam spun up to 6 rad/s: the peak in-plane tip deflection over the first 8 s at
n = 6, 12, 24, 48 rfes. The RFEM discretisation converges with order 2, so each change is about a
quarter of the one before; Richardson extrapolation gives the converged value, and a rerun of the
finest n at 100x tighter tolerances shows the integration error is far below the changes.

    /usr/bin/python3 examples/ex2_refinement.py        (~10 s)
"""
import os

import rfem

here = os.path.dirname(os.path.abspath(__file__))

# 1. The case, shortened to the first peak of the spin-up.
case = rfem.load(os.path.join(here, "..", "cases", "kane_spinup.toml"), {"simulation.t_end": 8.0})

# 2. The study: one run per n, the quantity observed in each, the finest run again at rtol/100.
study = rfem.refine(case, ns=[6, 12, 24, 48], quantities=["peak:u1"], threads=1)
table = study.table("peak:u1")

# 3. The table as `rfem refine` prints it.
def cell(x, fmt):
    return "-" if x != x else format(x, fmt)  # (NaN: not defined for the first rows)


print(f"{'n':>4} {'peak |u1| [m]':>16} {'change':>11} {'order':>7}")
for n, v, d, p in zip(table["n"], table["value"], table["change"], table["order"]):
    print(f"{n:>4} {v:>16.9f} {cell(d, '.3e'):>11} {cell(p, '.3f'):>7}")

# 4. What the series says: order 2, the extrapolated value, and how far the integration error is
#    below the last change (it must be: else the orders would measure the integrator).
print(f"fitted order {table['fitted_order']:.3f}; Richardson value {table['reference']:.7f} m")
print(f"last change over integration error: more than 1000: {abs(table['change'][-1]) > 1000 * table['integration_error']}")
