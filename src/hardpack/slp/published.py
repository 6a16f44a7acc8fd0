"""Table II of Torquato & Jiao, Phys. Rev. E 82, 061302 (2010), for the densest-packing figure.

The validation targets (Table I, the SLP column of Table II) live in
``hardpack/validation/targets.yaml``; this table adds the paper's LS column for the figure.
Densities printed as "0.7408..." are a misprint of pi/sqrt(18) = 0.74048 and "0.9068..." a
truncation of pi/sqrt(12); the exact values stand in for them.
"""

import math

# Table II: densest packings from N = 3^d random starts
TABLE_II = {
    # d: (N, LS phi, SLP phi, exact target, name of the densest known packing)
    # printed "0.9068..." (truncated pi/sqrt(12)) and "0.7408..." (misprint of 0.74048)
    2: (9, math.pi / math.sqrt(12), math.pi / math.sqrt(12), math.pi / math.sqrt(12), "triangular"),
    3: (27, math.pi / math.sqrt(18), math.pi / math.sqrt(18), math.pi / math.sqrt(18), "FCC"),
    4: (81, 0.5608, 0.6168, math.pi**2 / 16, "D4"),
    5: (243, 0.4154, 0.4652, math.sqrt(2) * math.pi**2 / 30, "D5"),
    6: (729, 0.3287, 0.3729, math.sqrt(3) * math.pi**3 / 144, "E6"),
}
