#!/bin/sh
# Runs bench/hex27/box.toml (a Gmsh box of 27-node hexahedra) with the adhesim binary BIN
# into OUT and checks its first ParaView frame with VTK's Python module (pip install vtk):
# every cell is a VTK_TRIQUADRATIC_HEXAHEDRON (29) and every one of its 27 points sits where
# VTK's own parametric coordinates of that point put it in the straight-sided box (the
# trilinear map of the corners), which a node order other than VTK's would break.
# Usage: bench/hex27/run.sh BIN OUT
set -eu
cd "$(dirname "$0")/../.."
bin=$1
out=$2
"$bin" run bench/hex27/box.toml --out "$out" -q --overwrite
python3 - "$out" <<'PY'
import glob, sys
import vtk
frame = sorted(glob.glob(sys.argv[1] + "/vtu/*_body0.vtu"))[0]
reader = vtk.vtkXMLUnstructuredGridReader()
reader.SetFileName(frame)
reader.Update()
grid = reader.GetOutput()
pc = vtk.vtkTriQuadraticHexahedron().GetParametricCoords()
worst, cells = 0.0, 0
for c in range(grid.GetNumberOfCells()):
    assert grid.GetCellType(c) == 29, grid.GetCellType(c)
    cells += 1
    p = grid.GetCell(c).GetPoints()
    x = [p.GetPoint(k) for k in range(27)]
    for k in range(27):
        r, s, t = pc[3 * k:3 * k + 3]
        w = [(1 - r) * (1 - s) * (1 - t), r * (1 - s) * (1 - t), r * s * (1 - t), (1 - r) * s * (1 - t),
             (1 - r) * (1 - s) * t, r * (1 - s) * t, r * s * t, (1 - r) * s * t]
        for i in range(3):
            worst = max(worst, abs(sum(w[a] * x[a][i] for a in range(8)) - x[k][i]))
print(f"{cells} cells of type 29; largest distance of a point from its VTK parametric place: {worst:.1e}")
sys.exit(0 if worst < 1e-12 else 1)
PY
