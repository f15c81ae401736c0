"""Writes box_hex27.msh: box_hex20.py's box (a 2 x 1 x 0.5 box, a transfinite 3 x 2 x 2 grid,
its x = 2 face sheared) with complete second-order elements, 27-node hexahedra and nine-node
quadrilaterals, the physical volume "block" and the physical surfaces "bottom" (z = 0) and
"top" (z = 0.5). Run with Python's gmsh package (pip install gmsh): python3 box_hex27.py"""
import gmsh

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("box_hex27")
occ = gmsh.model.occ
pts = [(0, 0, 0), (2, 0, 0), (2.2, 1, 0), (0, 1, 0)]
bottom = [occ.addPoint(*p) for p in pts]
lines = [occ.addLine(bottom[i], bottom[(i + 1) % 4]) for i in range(4)]
face = occ.addPlaneSurface([occ.addCurveLoop(lines)])
ext = occ.extrude([(2, face)], 0, 0, 0.5, numElements=[2], recombine=True)
occ.synchronize()
volume = [e[1] for e in ext if e[0] == 3][0]
top = ext[0][1]
for c in gmsh.model.getEntities(1):
    b = gmsh.model.getBoundingBox(*c)
    length = max(b[3] - b[0], b[4] - b[1])
    if abs(b[5] - b[2]) < 1e-3:
        gmsh.model.mesh.setTransfiniteCurve(c[1], 4 if length > 1.5 else 3)
for s in gmsh.model.getEntities(2):
    gmsh.model.mesh.setTransfiniteSurface(s[1])
    gmsh.model.mesh.setRecombine(2, s[1])
gmsh.model.mesh.setTransfiniteVolume(volume)
gmsh.model.addPhysicalGroup(3, [volume], name="block")
gmsh.model.addPhysicalGroup(2, [face], name="bottom")
gmsh.model.addPhysicalGroup(2, [top], name="top")
gmsh.option.setNumber("Mesh.ElementOrder", 2)
gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.write("box_hex27.msh")
gmsh.finalize()
