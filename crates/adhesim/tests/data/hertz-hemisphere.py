"""Writes hertz-hemisphere-tet10.msh and, the same mesh lowered to order 1,
hertz-hemisphere-tet4.msh from hertz-hemisphere.geo (next to this file)."""
import os
import gmsh

here = os.path.dirname(os.path.abspath(__file__))
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(os.path.join(here, "hertz-hemisphere.geo"))
gmsh.model.mesh.generate(3)
gmsh.write(os.path.join(here, "hertz-hemisphere-tet10.msh"))
gmsh.model.mesh.setOrder(1)
gmsh.write(os.path.join(here, "hertz-hemisphere-tet4.msh"))
gmsh.finalize()
