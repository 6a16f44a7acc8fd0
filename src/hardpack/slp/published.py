"""Published SLP / LS numbers of Torquato & Jiao, PRE 82, 061302 (2010) (seed 003; SLP note sec. 3).

Line numbers refer to ``seeds/003_9d332fbc06090510.txt``. Densities printed as "0.7408..." are a
misprint of pi/sqrt(18) = 0.74048 and "0.9068..." a truncation of pi/sqrt(12) (note sec. 0,
items 2 and 4); the exact values stand in for them.
"""

import math

# Table II (L1428-1454): densest packings from N = 3^d random starts
TABLE_II = {
    # d: (N, LS phi, SLP phi, exact target, name of the densest known packing)
    # printed "0.9068..." (truncated pi/sqrt(12)) and "0.7408..." (misprint of 0.74048; note sec. 0)
    2: (9, math.pi / math.sqrt(12), math.pi / math.sqrt(12), math.pi / math.sqrt(12), "triangular"),
    3: (27, math.pi / math.sqrt(18), math.pi / math.sqrt(18), math.pi / math.sqrt(18), "FCC"),
    4: (81, 0.5608, 0.6168, math.pi**2 / 16, "D4"),
    5: (243, 0.4154, 0.4652, math.sqrt(2) * math.pi**2 / 30, "D5"),
    6: (729, 0.3287, 0.3729, math.sqrt(3) * math.pi**3 / 144, "E6"),
}
TABLE_II_LINES = "L1428-1454"

# Table I (L1300-1324): MRJ-like packings, mean +- std over 5 configurations
TABLE_I = {
    # d: (N used by SLP, LS phi, LS rattler fraction, SLP phi, SLP rattler fraction)
    3: (2000, (0.642, 0.005), (0.030, 0.003), (0.640, 0.004), (0.028, 0.003)),
    4: (4000, (0.460, 0.006), (0.012, 0.002), (0.465, 0.005), (0.014, 0.002)),
    5: (8000, (0.315, 0.005), (0.008, 0.002), (0.310, 0.005), (0.006, 0.002)),
    6: (12000, (0.201, 0.005), (0.005, 0.001), (0.199, 0.005), (0.005, 0.001)),
}
TABLE_I_LINES = "L1300-1324"
# 2-D polydisperse disks, diameters uniform in [D, 2D], N = 500 (L1356-1359)
MRJ_2D_POLYDISPERSE = {"phi": 0.846, "rattler_fraction": 0.03, "lines": "L1356-1359"}
