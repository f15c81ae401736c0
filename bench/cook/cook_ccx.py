#!/usr/bin/env python3
"""Writes the CalculiX (ccx 2.20) input deck of Cook's membrane, plane strain, on an n x n mesh
of 20-node hexahedra one element thick, and reads the tip deflection back from the .dat file.

The membrane: corners (0, 0), (48, 44), (48, 60), (0, 44); the unit square (xi, eta) is mapped
by x = 48 xi, y = 44 xi + eta (44 - 28 xi) (the mapping of the Rust test,
crates/adhesim/tests/fbar_locking.rs), so the n x n elements are straight-sided quadrilaterals
and the mid-edge nodes sit at the midpoints of their edges. Thickness 1 (z in [0, 1]); z fixed
on every node (plane strain), x and y fixed on the clamped edge x = 0. Linear elasticity,
E = 250, nu = 0.4999, small strains (no NLGEOM). The load is a total vertical force F = 100
on the edge x = 48, a uniform shear traction F / 16 on the face x = 48, given as the consistent
nodal forces of each element's 8-node face (*CLOAD): a corner node takes -1/12 of the face's
load, a mid-edge node 1/3 (checked here by Gauss quadrature of the serendipity shape
functions before the deck is written).

Usage:
  cook_ccx.py deck --n N [--element C3D20R --young E --poisson NU --force F] OUT.inp
      writes the deck
  cook_ccx.py tip JOB.dat
      prints the vertical displacement of the corner (48, 60) (mean of its nodes at
      z = 0, 1/2, 1) and its spread over them, then the same for the mid-point (48, 52) of the
      loaded edge
  cook_ccx.py report RUNS
      prints the table of bench/cook/run.sh (RUNS: lines "element n corner mid seconds") with
      the Richardson extrapolations
"""

import argparse
import math
import sys

E = 250.0
NU = 0.4999
FORCE = 100.0


def serendipity8(r, s):
    """Shape functions of the 8-node serendipity quadrilateral on [-1, 1]^2, corners first
    (counter-clockwise from (-1, -1)), then the mid-edge nodes (edge 1-2, 2-3, 3-4, 4-1)."""
    corners = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    n = [0.25 * (1 + r * a) * (1 + s * b) * (r * a + s * b - 1) for a, b in corners]
    n += [0.5 * (1 - r * r) * (1 - s), 0.5 * (1 + r) * (1 - s * s),
          0.5 * (1 - r * r) * (1 + s), 0.5 * (1 - r) * (1 - s * s)]
    return n


def face_shares():
    """Fractions of a uniform traction's resultant that the consistent load vector gives to the
    nodes of a flat, affine 8-node face (3 x 3 Gauss quadrature, exact for these
    polynomials)."""
    g = (3.0 / 5.0) ** 0.5
    points = [(-g, 5.0 / 9.0), (0.0, 8.0 / 9.0), (g, 5.0 / 9.0)]
    shares = [0.0] * 8
    for r, wr in points:
        for s, ws in points:
            for i, v in enumerate(serendipity8(r, s)):
                shares[i] += wr * ws * v / 4.0  # the reference square has area 4
    return shares


def check_face_shares():
    shares = face_shares()
    expected = [-1.0 / 12.0] * 4 + [1.0 / 3.0] * 4
    for got, want in zip(shares, expected):
        if abs(got - want) > 1e-14:
            sys.exit(f"cook_ccx.py: consistent face shares {shares}, expected {expected}")
    return shares


def node_key(i, j, k):
    """Nodes of the serendipity mesh on the (2n + 1) x (2n + 1) x 3 grid of half-element steps:
    at most one of (i, j, k) odd (no face or volume centres)."""
    return (i % 2) + (j % 2) + (k % 2) <= 1


def write_deck(out, n, element, young=E, poisson=NU, force=FORCE):
    shares = check_face_shares()
    ids = {}
    lines = []
    for k in range(3):
        for j in range(2 * n + 1):
            for i in range(2 * n + 1):
                if not node_key(i, j, k):
                    continue
                ids[(i, j, k)] = len(ids) + 1
                xi, eta, z = i / (2 * n), j / (2 * n), k / 2
                x = 48.0 * xi
                y = 44.0 * xi + eta * (44.0 - 28.0 * xi)
                lines.append(f"{ids[(i, j, k)]}, {x:.15g}, {y:.15g}, {z:.15g}\n")
    out.write("** Cook's membrane, plane strain, written by bench/cook/cook_ccx.py\n")
    out.write(f"** n = {n}, element {element}, E = {young}, nu = {poisson}, F = {force}\n")
    out.write("*NODE, NSET=NALL\n")
    out.writelines(lines)

    out.write(f"*ELEMENT, TYPE={element}, ELSET=EALL\n")
    eid = 0
    for b in range(n):
        for a in range(n):
            i, j = 2 * a, 2 * b
            # ccx / Abaqus C3D20 numbering: corners of z = 0 (counter-clockwise seen from +z),
            # corners of z = 1, mid-edge nodes of z = 0, of z = 1, then the edges along z.
            corners = [(i, j), (i + 2, j), (i + 2, j + 2), (i, j + 2)]
            mids = [(i + 1, j), (i + 2, j + 1), (i + 1, j + 2), (i, j + 1)]
            conn = ([ids[(p, q, 0)] for p, q in corners] + [ids[(p, q, 2)] for p, q in corners]
                    + [ids[(p, q, 0)] for p, q in mids] + [ids[(p, q, 2)] for p, q in mids]
                    + [ids[(p, q, 1)] for p, q in corners])
            eid += 1
            out.write(f"{eid}, " + ", ".join(map(str, conn[:15])) + ",\n")
            out.write(", ".join(map(str, conn[15:])) + "\n")

    left = [v for (i, j, k), v in ids.items() if i == 0]
    tip = [ids[(2 * n, 2 * n, k)] for k in range(3)]
    # The mid-point (48, 52) of the loaded edge (its node at z = 1/2 exists when n is even).
    mid = [ids[(2 * n, n, k)] for k in range(3) if (2 * n, n, k) in ids]
    write_set(out, "LEFT", left)
    write_set(out, "TIP", tip)
    write_set(out, "MID", mid)

    out.write("*MATERIAL, NAME=M\n*ELASTIC\n")
    out.write(f"{young!r}, {poisson!r}\n")
    out.write("*SOLID SECTION, ELSET=EALL, MATERIAL=M\n")
    out.write("*BOUNDARY\nNALL, 3, 3\nLEFT, 1, 2\n")

    # Consistent nodal forces of the uniform shear traction on the face x = 48, element face by
    # element face: the face of the element in row b spans y in [44 + 16 b / n, 44 + 16 (b+1) / n]
    # and z in [0, 1]; its load is F / n.
    load = {}
    i = 2 * n
    face_load = force / n
    for b in range(n):
        j = 2 * b
        # The face's nodes in the order of serendipity8 (r along y, s along z).
        face = [(j, 0), (j + 2, 0), (j + 2, 2), (j, 2), (j + 1, 0), (j + 2, 1), (j + 1, 2), (j, 1)]
        for (q, k), share in zip(face, shares):
            node = ids[(i, q, k)]
            load[node] = load.get(node, 0.0) + share * face_load
    total = sum(load.values())
    if abs(total - force) > 1e-9 * abs(force):
        sys.exit(f"cook_ccx.py: nodal forces add up to {total}, not {force}")

    out.write("*STEP\n*STATIC\n*CLOAD\n")
    for node in sorted(load):
        out.write(f"{node}, 2, {load[node]:.17g}\n")
    out.write("*NODE PRINT, NSET=TIP\nU\n*NODE PRINT, NSET=MID\nU\n*END STEP\n")
    return len(ids), eid


def write_set(out, name, nodes, per_line=16):
    out.write(f"*NSET, NSET={name}\n")
    for s in range(0, len(nodes), per_line):
        out.write(", ".join(map(str, nodes[s:s + per_line])) + ",\n")


def read_sets(path):
    """Vertical displacements of the nodes of each node set printed in a .dat file (the last
    block of each set)."""
    sets = {}
    name = None
    with open(path) as f:
        for line in f:
            words = line.split()
            if line.lstrip().startswith("displacements") and "for set" in line:
                name = words[words.index("set") + 1]
                sets[name] = []
                continue
            if name is None:
                continue
            if len(words) == 4:
                try:
                    sets[name].append(float(words[2]))
                    continue
                except ValueError:
                    pass
            if sets[name] and not words:
                name = None
    return sets


def det(a):
    """Determinant by Gaussian elimination with partial pivoting."""
    a = [row[:] for row in a]
    n = len(a)
    d = 1.0
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(a[r][c]))
        if a[p][c] == 0.0:
            return 0.0
        if p != c:
            a[c], a[p] = a[p], a[c]
            d = -d
        d *= a[c][c]
        for r in range(c + 1, n):
            f = a[r][c] / a[c][c]
            for k in range(c, n):
                a[r][k] -= f * a[c][k]
    return d


def wedge_det(lam, angle, nu):
    """Williams' eigenvalue problem of a wedge of opening `angle`, traction-free on the face
    theta = 0 and clamped on theta = angle, plane strain: Airy function
    r^(lam+1) (A sin (lam+1)t + B cos (lam+1)t + C sin (lam-1)t + D cos (lam-1)t), stresses
    ~ r^(lam-1). Returns the determinant of the four boundary conditions on (A, B, C, D)."""
    k = 3.0 - 4.0 * nu
    a, b = lam + 1.0, lam - 1.0
    s, c = math.sin, math.cos
    t = angle
    return det([
        [0.0, 1.0, 0.0, 1.0],                 # sigma_tt(0) = 0
        [a, 0.0, b, 0.0],                     # sigma_rt(0) = 0
        [-a * s(a * t), -a * c(a * t), (k - lam) * s(b * t), (k - lam) * c(b * t)],  # u_r = 0
        [-a * c(a * t), a * s(a * t), -(k + lam) * c(b * t), (k + lam) * s(b * t)],  # u_t = 0
    ])


def corner_exponent(angle, nu):
    """Smallest real root lam in (0, 1) of wedge_det: the displacements near the corner go as
    r^lam."""
    steps = 1000
    xs = [0.01 + 0.98 * i / steps for i in range(steps + 1)]
    for x0, x1 in zip(xs, xs[1:]):
        f0, f1 = wedge_det(x0, angle, nu), wedge_det(x1, angle, nu)
        if f0 == 0.0:
            return x0
        if f0 * f1 < 0.0:
            for _ in range(100):
                xm = 0.5 * (x0 + x1)
                fm = wedge_det(xm, angle, nu)
                if f0 * fm <= 0.0:
                    x1 = xm
                else:
                    x0, f0 = xm, fm
            return 0.5 * (x0 + x1)
    return None


def richardson(values, order=None):
    """Extrapolation of the last three values of a sequence of meshes halving h: with the
    observed order, or with a given one."""
    f1, f2, f3 = values[-3:]
    observed = math.log2((f2 - f1) / (f3 - f2)) if (f2 - f1) * (f3 - f2) > 0 else float("nan")
    p = observed if order is None else order
    return observed, f3 + (f3 - f2) / (2.0 ** p - 1.0)


def report(path, poisson=NU, title=None):
    """Tables of the runs listed in `path` (lines: element n corner mid seconds) with the
    Richardson extrapolations of the three finest meshes."""
    runs = {}
    for line in open(path):
        w = line.split()
        if len(w) == 5:
            runs.setdefault(w[0], {})[int(w[1])] = (float(w[2]), float(w[3]), float(w[4]))
    elements = list(runs)
    sizes = sorted({n for r in runs.values() for n in r})
    # The clamped corner (0, 44) between the clamp x = 0 and the top edge towards (48, 60): the
    # top edge rises by 16 over 48, so the material angle there is 90 + atan(16/48) degrees.
    # Its singularity limits the convergence of any point value to the order 2 lambda.
    angle = math.pi / 2 + math.atan2(16.0, 48.0)
    lam = corner_exponent(angle, poisson)
    theory = 2.0 * lam
    if title:
        print(title)
    for k, point in ((0, "corner (48, 60)"), (1, "mid-point (48, 52) of the loaded edge")):
        print()
        print(f"vertical displacement of the {point}")
        print()
        print("| n | " + " | ".join(elements) + " |")
        print("|---|" + "---|" * len(elements))
        for n in sizes:
            cells = [f"{runs[e][n][k]:.4f}" if n in runs[e] else "-" for e in elements]
            print(f"| {n} | " + " | ".join(cells) + " |")
        rows = {"observed order (three finest meshes)": [],
                "extrapolated with the observed order": [],
                f"extrapolated with the order 2 lambda = {theory:.3f}": []}
        for e in elements:
            v = [runs[e][n][k] for n in sizes if n in runs[e]]
            if len(v) < 3:
                for r in rows.values():
                    r.append("-")
                continue
            observed, ext = richardson(v)
            cells = [f"{observed:.2f}", f"{ext:.4f}", f"{richardson(v, theory)[1]:.4f}"]
            for r, c in zip(rows.values(), cells):
                r.append(c)
        for name, cells in rows.items():
            print(f"| {name} | " + " | ".join(cells) + " |")
    print()
    print(f"corner (0, 44): opening {math.degrees(angle):.2f} degrees, clamped-free, "
          f"nu = {poisson}: displacements ~ r^lambda with lambda = {lam:.4f}, so a point value "
          f"converges as h^(2 lambda) = h^{theory:.3f}")
    print("ccx wall time [s]: " + ", ".join(
        f"{e} n = {n}: {runs[e][n][2]:.2f}" for e in elements for n in sizes if n in runs[e]))


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    deck = sub.add_parser("deck")
    deck.add_argument("--n", type=int, required=True)
    deck.add_argument("--element", default="C3D20R")
    deck.add_argument("--young", type=float, default=E)
    deck.add_argument("--poisson", type=float, default=NU)
    deck.add_argument("--force", type=float, default=FORCE)
    deck.add_argument("out")
    tip = sub.add_parser("tip")
    tip.add_argument("dat")
    rep = sub.add_parser("report")
    rep.add_argument("--poisson", type=float, default=NU)
    rep.add_argument("--title")
    rep.add_argument("runs")
    a = parser.parse_args()
    if a.command == "deck":
        with open(a.out, "w") as out:
            nodes, elements = write_deck(out, a.n, a.element, a.young, a.poisson, a.force)
        print(f"{a.out}: {nodes} nodes, {elements} {a.element}", file=sys.stderr)
    elif a.command == "report":
        report(a.runs, a.poisson, a.title)
    else:
        sets = read_sets(a.dat)
        words = []
        for name in ("TIP", "MID"):
            v = sets.get(name)
            if not v:
                sys.exit(f"cook_ccx.py: no displacements of set {name} in {a.dat}")
            words += [f"{sum(v) / len(v):.10g}", f"{max(v) - min(v):.3g}"]
        print(" ".join(words))


if __name__ == "__main__":
    main()
