#!/usr/bin/env python3
"""Writes the CalculiX (ccx 2.20) input deck of the scale benchmark's pad problem.

The mesh is the one adhesim's `block` generator builds for scenarios/scale-pad.toml: a box
[0, width] x [0, height] x [0, width] [m] cut into n x layers x n hex8 (C3D8) elements. The
material is Blatz-Ko, written as *HYPERFOAM, N=2 with mu1 = mu2 = G/2, alpha1 = alpha2 = -2,
nu1 = nu2 = 1/4 (the same strain energy, see README.md). The rigid plane y = 0 is the top face
of one large C3D8 element below the pad whose eight nodes are fixed; the pad's bottom face is
the slave surface of a surface-to-surface contact pair with a linear penalty and Coulomb
friction (ccx's node-to-surface contact with friction does not converge on this problem). The
top face is held in x and z and pushed down by `depth`, geometrically nonlinear, in
increments of 1/`increments` of the load (ccx cuts one back when it does not converge; with
--direct it stops instead).

The contact force on the pad is the reaction at the rigid element's nodes (node set RIGID),
printed in the .dat file once per increment; the reaction at the pad's top (TOP) is printed
too, as a check of equilibrium.

Usage: ccx_pad.py --n 9 [--layers 4 --width 0.01 --height 0.002 --depth 1e-4 --g 1e6
                          --mu 0.3 --increments 5 --penalty 1e13 --stick-slope 1e10 --direct] OUT.inp
"""

import argparse
import sys


def pad_nodes(n, layers, width, height):
    """Node ids and coordinates of the pad: id = 1 + i + (n+1) (k + (n+1) j), with i along x,
    j along y (0 = bottom) and k along z."""
    def node_id(i, j, k):
        return 1 + i + (n + 1) * (k + (n + 1) * j)

    coords = []
    for j in range(layers + 1):
        for k in range(n + 1):
            for i in range(n + 1):
                coords.append((node_id(i, j, k), width * i / n, height * j / layers,
                               width * k / n))
    return node_id, coords


def pad_elements(n, layers, node_id):
    """C3D8 connectivity (positive volume): the face y = y_min of each element is its face S3
    (nodes 1-5-6-2), the face y = y_max is S5 (nodes 3-7-8-4)."""
    offsets = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
               (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    elements = []
    eid = 0
    for j in range(layers):
        for k in range(n):
            for i in range(n):
                eid += 1
                elements.append((eid, j, [node_id(i + a, j + b, k + c) for a, b, c in offsets]))
    return elements


def num(x):
    """x for a CalculiX card: shortest round trip, or 15 significant digits when that is
    longer than the 20 characters CalculiX reads in a field (e.g. 5.8139534883720933e-05,
    a node spacing at n = 172)."""
    s = f"{x:.17g}"
    return s if len(s) <= 20 else f"{x:.15g}"


def write_lines(out, ids, per_line=16):
    for s in range(0, len(ids), per_line):
        out.write(", ".join(str(x) for x in ids[s:s + per_line]) + "\n")


def write_deck(out, a):
    n, layers = a.n, a.layers
    node_id, coords = pad_nodes(n, layers, a.width, a.height)
    elements = pad_elements(n, layers, node_id)
    out.write("** Blatz-Ko pad pressed on a rigid plane (adhesim scale benchmark)\n")
    out.write(f"** n = {n}, layers = {layers}, contact nodes = {(n + 1) ** 2}\n")
    out.write("*NODE, NSET=PAD\n")
    for nid, x, y, z in coords:
        out.write(f"{nid}, {num(x)}, {num(y)}, {num(z)}\n")
    # The rigid block: one element under the pad, overhanging it by half a width.
    first = len(coords) + 1
    lo, hi, depth_block = -0.5 * a.width, 1.5 * a.width, a.height
    block = [(lo, -depth_block, lo), (hi, -depth_block, lo), (hi, 0.0, lo), (lo, 0.0, lo),
             (lo, -depth_block, hi), (hi, -depth_block, hi), (hi, 0.0, hi), (lo, 0.0, hi)]
    out.write("*NODE, NSET=RIGID\n")
    for m, (x, y, z) in enumerate(block):
        out.write(f"{first + m}, {num(x)}, {num(y)}, {num(z)}\n")
    out.write("*ELEMENT, TYPE=C3D8, ELSET=EPAD\n")
    for eid, _, conn in elements:
        out.write(f"{eid}, " + ", ".join(str(c) for c in conn) + "\n")
    rigid_eid = len(elements) + 1
    out.write("*ELEMENT, TYPE=C3D8, ELSET=ERIGID\n")
    out.write(f"{rigid_eid}, " + ", ".join(str(first + m) for m in range(8)) + "\n")
    out.write("*NSET, NSET=TOP\n")
    write_lines(out, [node_id(i, layers, k) for k in range(n + 1) for i in range(n + 1)])
    out.write("*ELSET, ELSET=EBOTTOM\n")
    write_lines(out, [eid for eid, j, _ in elements if j == 0])
    out.write("*SURFACE, NAME=SLAVE\nEBOTTOM, S3\n")
    out.write(f"*SURFACE, NAME=PLANE\n{rigid_eid}, S5\n")
    out.write("*MATERIAL, NAME=BLATZKO\n*HYPERFOAM, N=2\n")
    out.write(f"{a.g / 2:.17g}, -2., {a.g / 2:.17g}, -2., 0.25, 0.25\n")
    out.write("*SOLID SECTION, ELSET=EPAD, MATERIAL=BLATZKO\n")
    # The block's nodes are all fixed: its material never enters the answer.
    out.write("*MATERIAL, NAME=STIFF\n*ELASTIC\n1e11, 0.3\n")
    out.write("*SOLID SECTION, ELSET=ERIGID, MATERIAL=STIFF\n")
    out.write("*CONTACT PAIR, INTERACTION=GROUND, TYPE=SURFACE TO SURFACE\nSLAVE, PLANE\n")
    out.write("*SURFACE INTERACTION, NAME=GROUND\n")
    out.write("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n")
    out.write(f"{a.penalty:.6g}, {a.tension:.6g}\n")
    if a.mu > 0.0:  # ccx rejects a zero friction coefficient: frictionless is no *FRICTION
        out.write(f"*FRICTION\n{a.mu:.17g}, {a.stick_slope:.6g}\n")
    out.write("*BOUNDARY\nRIGID, 1, 3, 0.\nTOP, 1, 1, 0.\nTOP, 3, 3, 0.\n")
    out.write("*AMPLITUDE, NAME=RAMP\n0., 0., 1., 1.\n")
    out.write(f"*STEP, NLGEOM, INC={10 * a.increments}\n")
    if a.direct:
        out.write(f"*STATIC, DIRECT\n{1.0 / a.increments:.17g}, 1.0\n")
    else:  # ccx may cut an increment back (as adhesim does) but never exceed 1/increments
        dt = 1.0 / a.increments
        out.write(f"*STATIC\n{dt:.17g}, 1.0, {dt * 1e-4:.6g}, {dt:.17g}\n")
    out.write(f"*BOUNDARY, AMPLITUDE=RAMP\nTOP, 2, 2, {-a.depth:.17g}\n")
    out.write("*NODE PRINT, NSET=RIGID, TOTALS=ONLY\nRF\n")
    out.write("*NODE PRINT, NSET=TOP, TOTALS=ONLY\nRF\n")
    out.write("*END STEP\n")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out", help="the .inp file to write")
    p.add_argument("--n", type=int, required=True, help="elements along x and z")
    p.add_argument("--layers", type=int, default=4, help="elements through the height")
    p.add_argument("--width", type=float, default=0.01, help="[m]")
    p.add_argument("--height", type=float, default=0.002, help="[m]")
    p.add_argument("--depth", type=float, default=1e-4, help="push of the top face [m]")
    p.add_argument("--g", type=float, default=1e6, help="shear modulus [Pa]")
    p.add_argument("--mu", type=float, default=0.3, help="friction coefficient")
    p.add_argument("--increments", type=int, default=5)
    p.add_argument("--direct", action="store_true",
                   help="fixed increments (*STATIC, DIRECT): stop instead of cutting back")
    p.add_argument("--penalty", type=float, default=1e13,
                   help="normal penalty slope [Pa/m]")
    p.add_argument("--tension", type=float, default=1.0,
                   help="penalty tension at large clearance (ccx's sigma_inf) [Pa]")
    p.add_argument("--stick-slope", type=float, default=1e10,
                   help="tangential penalty (stick slope) [Pa/m]")
    a = p.parse_args(argv)
    if a.n < 1 or a.layers < 1 or a.increments < 1:
        p.error("--n, --layers and --increments must be at least 1")
    with open(a.out, "w") as out:
        write_deck(out, a)


if __name__ == "__main__":
    sys.exit(main())
