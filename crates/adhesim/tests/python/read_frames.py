"""Reads every frame of an adhesim run with VTK's XML readers and with meshio, and prints
what each reader sees as JSON, for the Rust test `paraview_output` to compare with the
problem and with history.csv.

Usage: python3 read_frames.py OUT_DIR NAME

Output: {"vtk": [frame, ...], "meshio": [frame, ...], "versions": {...}} where a frame is
{"time": t, "datasets": [dataset, ...]} and a dataset is {"group", "name", "points",
"cells", "cell_types", "point_arrays": {name: components}, "cell_arrays": {...},
"nan_arrays": [names of arrays holding a NaN], "sums": {name: [column sums]}, "ids":
{name: [min, max]}}. Any VTK error or warning makes the script fail.
"""

import json
import os
import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np
# Only the data and XML modules of VTK: `import vtk` would load the rendering libraries too.
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkVersion
from vtkmodules.vtkCommonDataModel import vtkCompositeDataSet
from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataReader

ID_ARRAYS = ("node_id", "body_id", "pair_id")


def describe(point_arrays, cell_arrays):
    """Common part of a dataset's description from dicts name -> numpy array."""
    out = {"point_arrays": {}, "cell_arrays": {}, "nan_arrays": [], "sums": {}, "ids": {}}
    for kind, arrays in (("point_arrays", point_arrays), ("cell_arrays", cell_arrays)):
        for name, a in arrays.items():
            a = np.asarray(a)
            comps = 1 if a.ndim == 1 else int(a.shape[1])
            out[kind][name] = comps
            if a.dtype.kind == "f" and np.isnan(a).any():
                out["nan_arrays"].append(name)
            if name in ID_ARRAYS:
                out["ids"][name] = [int(a.min()), int(a.max())] if a.size else []
            elif a.dtype.kind == "f":
                s = np.nansum(a.reshape(len(a), -1), axis=0)
                out["sums"][name] = [float(x) for x in s]
    return out


def read_pvd(out_dir, name):
    root = ET.parse(os.path.join(out_dir, name + ".pvd")).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def vtk_frames(out_dir, name):
    problems = []

    def complain(obj, event):
        problems.append(event)

    frames = []
    for t, file in read_pvd(out_dir, name):
        reader = vtkXMLMultiBlockDataReader()
        reader.AddObserver("ErrorEvent", complain)
        reader.AddObserver("WarningEvent", complain)
        reader.GetExecutive().AddObserver("ErrorEvent", complain)
        reader.SetFileName(os.path.join(out_dir, file))
        reader.Update()
        assert not problems, (file, problems)
        top = reader.GetOutput()
        datasets = []
        for g in range(top.GetNumberOfBlocks()):
            group = top.GetBlock(g)
            gname = top.GetMetaData(g).Get(vtkCompositeDataSet.NAME())
            for d in range(group.GetNumberOfBlocks()):
                grid = group.GetBlock(d)
                dname = group.GetMetaData(d).Get(vtkCompositeDataSet.NAME())
                pd, cd = grid.GetPointData(), grid.GetCellData()
                pa = {pd.GetArrayName(i): vtk_to_numpy(pd.GetArray(i)) for i in range(pd.GetNumberOfArrays())}
                ca = {cd.GetArrayName(i): vtk_to_numpy(cd.GetArray(i)) for i in range(cd.GetNumberOfArrays())}
                entry = {
                    "group": gname,
                    "name": dname,
                    "points": grid.GetNumberOfPoints(),
                    "cells": grid.GetNumberOfCells(),
                    "cell_types": sorted({grid.GetCellType(i) for i in range(grid.GetNumberOfCells())}),
                }
                entry.update(describe(pa, ca))
                datasets.append(entry)
        frames.append({"time": t, "datasets": datasets})
    return frames


MESHIO_TYPES = {"hexahedron": 12, "tetra": 10, "quad": 9, "triangle": 5, "vertex": 1}


def meshio_frames(out_dir, name):
    frames = []
    for t, file in read_pvd(out_dir, name):
        vtm = os.path.join(out_dir, file)
        root = ET.parse(vtm).getroot()
        datasets = []
        for block in root.iter("Block"):
            for ds in block.iter("DataSet"):
                m = meshio.read(os.path.join(os.path.dirname(vtm), ds.get("file")))
                ca = {k: np.concatenate(v) for k, v in m.cell_data.items()}
                entry = {
                    "group": block.get("name"),
                    "name": ds.get("name"),
                    "points": len(m.points),
                    "cells": sum(len(b.data) for b in m.cells),
                    "cell_types": sorted({MESHIO_TYPES[b.type] for b in m.cells}),
                }
                entry.update(describe(m.point_data, ca))
                datasets.append(entry)
        frames.append({"time": t, "datasets": datasets})
    return frames


def main():
    out_dir, name = sys.argv[1], sys.argv[2]
    result = {
        "versions": {"vtk": vtkVersion.GetVTKVersion(), "meshio": meshio.__version__},
        "vtk": vtk_frames(out_dir, name),
        "meshio": meshio_frames(out_dir, name),
    }
    json.dump(result, sys.stdout)


if __name__ == "__main__":
    main()
