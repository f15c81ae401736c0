#!/usr/bin/env python3
"""Checks that CalculiX's *HYPERFOAM, N=2 with mu1 = mu2 = G/2, alpha1 = alpha2 = -2,
nu1 = nu2 = 1/4 is adhesim's Blatz-Ko material W = G/2 (I2/I3 + 2 sqrt(I3) - 5).

One C3D8 unit cube with symmetry conditions on x = 0, y = 0, z = 0 is stretched along x to
l (uniaxial stress, geometrically nonlinear). For Blatz-Ko the lateral stretch is l^(-1/4)
and the first Piola-Kirchhoff stress P11 = G (l^(-1/2) - l^(-3)) (docs: model notes). The
script runs ccx for a stretch path in tension and one in compression and compares the reaction
on x = 1 (= P11, the reference area being 1) and the lateral stretch with these closed forms.

Usage: uniaxial.py [--g 1e6] [--workdir DIR] [--tol 1e-3]; exit 1 if a difference exceeds tol.
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile


def deck(g, stretch, increments):
    return f"""*NODE, NSET=NALL
1, 0, 0, 0
2, 1, 0, 0
3, 1, 1, 0
4, 0, 1, 0
5, 0, 0, 1
6, 1, 0, 1
7, 1, 1, 1
8, 0, 1, 1
*ELEMENT, TYPE=C3D8, ELSET=EALL
1, 1, 2, 3, 4, 5, 6, 7, 8
*NSET, NSET=X0
1, 4, 5, 8
*NSET, NSET=X1
2, 3, 6, 7
*NSET, NSET=Y0
1, 2, 5, 6
*NSET, NSET=Z0
1, 2, 3, 4
*NSET, NSET=CORNER
7
*MATERIAL, NAME=BLATZKO
*HYPERFOAM, N=2
{g / 2:.17g}, -2., {g / 2:.17g}, -2., 0.25, 0.25
*SOLID SECTION, ELSET=EALL, MATERIAL=BLATZKO
*AMPLITUDE, NAME=RAMP
0., 0., 1., 1.
*STEP, NLGEOM, INC=1000
*STATIC, DIRECT
{1.0 / increments:.17g}, 1.0
*BOUNDARY
X0, 1, 1, 0.
Y0, 2, 2, 0.
Z0, 3, 3, 0.
*BOUNDARY, AMPLITUDE=RAMP
X1, 1, 1, {stretch - 1.0:.17g}
*NODE PRINT, NSET=X1, TOTALS=ONLY
RF
*NODE PRINT, NSET=CORNER
U
*END STEP
"""


def run_case(g, stretch, increments, workdir, name):
    with open(os.path.join(workdir, name + ".inp"), "w") as f:
        f.write(deck(g, stretch, increments))
    subprocess.run(["ccx", name], cwd=workdir, check=True, stdout=subprocess.DEVNULL)
    text = open(os.path.join(workdir, name + ".dat")).read()
    forces = re.findall(r"total force \(fx,fy,fz\) for set X1 and time\s+(\S+)\s+(\S+)", text)
    disps = re.findall(r"displacements \(vx,vy,vz\) for set CORNER and time\s+(\S+)\s+7\s+(\S+)\s+(\S+)", text)
    rows = []
    for (t, fx), (_, ux, uy) in zip(forces, disps):
        rows.append((1.0 + float(ux), float(fx), 1.0 + float(uy)))
    return rows


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--g", type=float, default=1e6, help="shear modulus [Pa]")
    p.add_argument("--workdir", default=None)
    p.add_argument("--tol", type=float, default=1e-3,
                   help="largest relative difference accepted (ccx's Newton tolerance is "
                        "about 1e-4 of the force)")
    a = p.parse_args(argv)
    workdir = a.workdir or tempfile.mkdtemp(prefix="ccx-uniaxial-")
    os.makedirs(workdir, exist_ok=True)
    worst = 0.0
    print("| stretch l | P11 ccx [Pa] | G (l^-1/2 - l^-3) [Pa] | rel. diff | lateral ccx | l^-1/4 |")
    print("|---:|---:|---:|---:|---:|---:|")
    for name, stretch in (("tension", 1.5), ("compression", 0.6)):
        for l, p11, lat in run_case(a.g, stretch, 10, workdir, name):
            exact = a.g * (l ** -0.5 - l ** -3)
            rel = abs(p11 - exact) / abs(exact)
            rel_lat = abs(lat - l ** -0.25) / l ** -0.25
            worst = max(worst, rel, rel_lat)
            print(f"| {l:.2f} | {p11:.6g} | {exact:.6g} | {rel:.1e} | {lat:.6f} | {l ** -0.25:.6f} |")
    print(f"\nlargest relative difference: {worst:.1e} (tolerance {a.tol:g})")
    return 0 if worst <= a.tol else 1


if __name__ == "__main__":
    sys.exit(main())
