"""Writes a Gmsh MSH 4.1 mesh of the sheared 2 x 1 x 0.5 box of tests/data/box_hex20.py,
refined: python3 box.py ORDER LEVEL OUT.msh, ORDER 1 (hex8) or 2 (hex20), LEVEL 0, 1, 2 (each
halving the cells: 3 x 2 x 2, 6 x 4 x 4, 12 x 8 x 8 cells). Physical volume "block", physical
surfaces "bottom" (z = 0) and "top" (z = 0.5)."""
import sys

import gmsh

order, level, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("box")
occ = gmsh.model.occ
pts = [(0, 0, 0), (2, 0, 0), (2.2, 1, 0), (0, 1, 0)]
bottom = [occ.addPoint(*p) for p in pts]
lines = [occ.addLine(bottom[i], bottom[(i + 1) % 4]) for i in range(4)]
face = occ.addPlaneSurface([occ.addCurveLoop(lines)])
ext = occ.extrude([(2, face)], 0, 0, 0.5, numElements=[2 << level], recombine=True)
occ.synchronize()
volume = [e[1] for e in ext if e[0] == 3][0]
for c in gmsh.model.getEntities(1):
    b = gmsh.model.getBoundingBox(*c)
    if abs(b[5] - b[2]) < 1e-3:
        cells = 3 if max(b[3] - b[0], b[4] - b[1]) > 1.5 else 2
        gmsh.model.mesh.setTransfiniteCurve(c[1], (cells << level) + 1)
for s in gmsh.model.getEntities(2):
    gmsh.model.mesh.setTransfiniteSurface(s[1])
    gmsh.model.mesh.setRecombine(2, s[1])
gmsh.model.mesh.setTransfiniteVolume(volume)
gmsh.model.addPhysicalGroup(3, [volume], name="block")
gmsh.model.addPhysicalGroup(2, [face], name="bottom")
gmsh.model.addPhysicalGroup(2, [ext[0][1]], name="top")
gmsh.option.setNumber("Mesh.ElementOrder", order)
gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.write(out)
gmsh.finalize()
