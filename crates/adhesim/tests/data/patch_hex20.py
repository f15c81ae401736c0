"""Writes patch_hex20.msh: two blocks of 20-node hexahedra for the contact patch test on
non-matching meshes, each 1 x 0.5 x 1 with 2 cells through y: "coarse" (3 x 2 x 3 cells) at
the origin and "fine" (4 x 2 x 4 cells) at x = 2 (move it back with the body's offset), with
the physical surfaces <block>_bottom (y = 0), _top (y = 0.5), _left (x = 0 of the block)
and _back (z = 0). Run with Python's gmsh package: python3 patch_hex20.py"""
import gmsh

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("patch_hex20")
occ = gmsh.model.occ
blocks = {"coarse": (0.0, 3), "fine": (2.0, 4)}
tags = {name: occ.addBox(x0, 0, 0, 1, 0.5, 1) for name, (x0, _) in blocks.items()}
occ.synchronize()
for name, (x0, n) in blocks.items():
    vol = tags[name]
    _, faces = gmsh.model.getAdjacencies(3, vol)
    for f in faces:
        _, curves = gmsh.model.getAdjacencies(2, f)
        for c in curves:
            b = gmsh.model.getBoundingBox(1, c)
            along_y = b[4] - b[1] > 0.25
            gmsh.model.mesh.setTransfiniteCurve(c, 3 if along_y else n + 1)
        gmsh.model.mesh.setTransfiniteSurface(f)
        gmsh.model.mesh.setRecombine(2, f)
    gmsh.model.mesh.setTransfiniteVolume(vol)
    gmsh.model.addPhysicalGroup(3, [vol], name=name)
    sides = {"bottom": (1, 0.0), "top": (1, 0.5), "left": (0, x0), "back": (2, 0.0)}
    for side, (axis, value) in sides.items():
        found = []
        for f in faces:
            b = gmsh.model.getBoundingBox(2, f)
            if abs(b[axis] - value) < 1e-6 and abs(b[axis + 3] - value) < 1e-6:
                found.append(f)
        gmsh.model.addPhysicalGroup(2, found, name=f"{name}_{side}")
gmsh.option.setNumber("Mesh.ElementOrder", 2)
gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.write("patch_hex20.msh")
gmsh.finalize()
