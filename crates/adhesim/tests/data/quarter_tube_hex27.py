"""Writes quarter_tube_hex27_2x4.msh and quarter_tube_hex27_4x8.msh: a quarter of a thick-walled
tube (inner radius 1, outer radius 2, height 0.5, axis z, the quarter x >= 0, y >= 0) meshed by
transfinite hexahedra, 2 x 4 x 1 and 4 x 8 x 1 cells (radial x around x axial), with complete
second-order elements, 27-node hexahedra and nine-node quadrilaterals whose high-order nodes
Gmsh places on the geometry (Mesh.SecondOrderLinear = 0, the default). Physical volume "body",
physical surfaces "inner" (r = 1), "outer" (r = 2), "bottom" (z = 0), "top" (z = 0.5),
"cut_y" (the plane y = 0) and "cut_x" (the plane x = 0).
Run with Python's gmsh package (pip install gmsh): python3 quarter_tube_hex27.py"""
import math

import gmsh

A, B, H = 1.0, 2.0, 0.5


def tube(n_radial, n_around, name):
    gmsh.model.add(name)
    occ = gmsh.model.occ
    centre = occ.addPoint(0, 0, 0)
    p = [occ.addPoint(A, 0, 0), occ.addPoint(B, 0, 0), occ.addPoint(0, B, 0), occ.addPoint(0, A, 0)]
    cut_y = occ.addLine(p[0], p[1])
    outer = occ.addCircleArc(p[1], centre, p[2])
    cut_x = occ.addLine(p[2], p[3])
    inner = occ.addCircleArc(p[3], centre, p[0])
    face = occ.addPlaneSurface([occ.addCurveLoop([cut_y, outer, cut_x, inner])])
    occ.remove([(0, centre)])
    ext = occ.extrude([(2, face)], 0, 0, H, numElements=[1], recombine=True)
    occ.synchronize()
    # extrude returns the top, the volume, then the lateral surfaces in the order of the
    # curve loop's curves.
    top, volume = ext[0][1], ext[1][1]
    lateral = [e[1] for e in ext[2:6]]
    for c, n in [(cut_y, n_radial), (outer, n_around), (cut_x, n_radial), (inner, n_around)]:
        gmsh.model.mesh.setTransfiniteCurve(c, n + 1)
    for s in gmsh.model.getEntities(2):
        gmsh.model.mesh.setTransfiniteSurface(s[1])
        gmsh.model.mesh.setRecombine(2, s[1])
    gmsh.model.mesh.setTransfiniteVolume(volume)
    gmsh.model.addPhysicalGroup(3, [volume], name="body")
    gmsh.model.addPhysicalGroup(2, [face], name="bottom")
    gmsh.model.addPhysicalGroup(2, [top], name="top")
    for tag, group in zip(lateral, ["cut_y", "outer", "cut_x", "inner"]):
        gmsh.model.addPhysicalGroup(2, [tag], name=group)
    gmsh.option.setNumber("Mesh.ElementOrder", 2)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
    gmsh.option.setNumber("Mesh.SecondOrderLinear", 0)
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.write(name + ".msh")
    gmsh.model.remove()


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
tube(2, 4, "quarter_tube_hex27_2x4")
tube(4, 8, "quarter_tube_hex27_4x8")
gmsh.finalize()
