"""Frames of a run as numpy arrays.

A run writes `DIR/<name>.pvd`, a time collection of multiblock files `DIR/vtu/*.vtm`; each
groups one unstructured grid (`.vtu`) per body and per contact surface. The grids are VTK
XML with inline binary arrays: base64 of a little-endian UInt64 byte count followed by the
little-endian values (docs/output.md). This reader handles exactly what adhesim writes; a
general VTK reader (vtk, pyvista, meshio) reads the same files.
"""

from __future__ import annotations

import base64
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

_DTYPES = {
    "Float64": "<f8",
    "Float32": "<f4",
    "Int64": "<i8",
    "Int32": "<i4",
    "UInt8": "u1",
    "UInt64": "<u8",
}


@dataclass
class Grid:
    """One data set of a frame: a body's mesh or a contact surface."""

    name: str
    """Data set name (the body's name, or the contact pair's)."""
    group: str
    """The multiblock group: "bodies" or "contacts" (as the .vtm names it)."""
    points: np.ndarray
    """Current positions, shape (n, 3) [m]."""
    connectivity: np.ndarray
    offsets: np.ndarray
    types: np.ndarray
    """VTK cell types (12 hexahedron, 10 tetrahedron, 9 quad, 5 triangle, 1 vertex)."""
    point_data: dict[str, np.ndarray] = field(default_factory=dict)
    """Nodal fields: shape (n,) or (n, components)."""
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)

    def cells(self) -> list[np.ndarray]:
        """The point indices of every cell."""
        starts = np.concatenate([[0], self.offsets[:-1]])
        return [self.connectivity[a:b] for a, b in zip(starts, self.offsets)]


@dataclass
class Frame:
    """One frame of a run: its time, its bodies' grids and its contact surfaces' grids,
    each by name."""

    t: float
    """Time [s]."""
    file: Path
    """The .vtm file."""
    bodies: dict[str, Grid]
    """Each body's grid: positions, cells, displacement, stress fields."""
    contacts: dict[str, Grid]
    """Each contact pair's slave surface: beta, forces, tractions, gaps per node."""


def _decode(array: ET.Element) -> np.ndarray:
    if array.get("format") != "binary":
        raise ValueError(f"DataArray {array.get('Name')!r}: only binary arrays are read")
    raw = base64.b64decode("".join((array.text or "").split()))
    (nbytes,) = np.frombuffer(raw[:8], dtype="<u8")
    dtype = np.dtype(_DTYPES[array.get("type")])
    values = np.frombuffer(raw[8 : 8 + int(nbytes)], dtype=dtype).copy()
    ncomp = int(array.get("NumberOfComponents", "1"))
    return values.reshape(-1, ncomp) if ncomp > 1 else values


def read_vtu(path: str | os.PathLike, name: str = "", group: str = "") -> Grid:
    """One `.vtu` file written by adhesim (its first piece)."""
    root = ET.parse(path).getroot()
    piece = root.find("UnstructuredGrid/Piece")
    if piece is None:
        raise ValueError(f"{path}: no UnstructuredGrid piece")
    arrays = lambda tag: {a.get("Name"): _decode(a) for a in piece.findall(f"{tag}/DataArray")}
    points = next(iter(arrays("Points").values()))
    cells = arrays("Cells")
    return Grid(
        name=name or Path(path).stem,
        group=group,
        points=points,
        connectivity=cells["connectivity"],
        offsets=cells["offsets"],
        types=cells["types"],
        point_data=arrays("PointData"),
        cell_data=arrays("CellData"),
    )


def read_vtm(path: str | os.PathLike, t: float = float("nan")) -> Frame:
    """A multiblock frame file and every grid it lists."""
    path = Path(path)
    root = ET.parse(path).getroot()
    bodies, contacts = {}, {}
    for block in root.findall("vtkMultiBlockDataSet/Block"):
        group = block.get("name", "")
        into = contacts if group.startswith("contact") else bodies
        for ds in block.findall("DataSet"):
            name = ds.get("name", "")
            into[name] = read_vtu(path.parent / ds.get("file"), name, group)
    return Frame(t=t, file=path, bodies=bodies, contacts=contacts)


def _collection(run_dir: Path) -> list[tuple[float, Path]]:
    pvds = sorted(run_dir.glob("*.pvd"))
    if not pvds:
        raise FileNotFoundError(f"{run_dir}: no .pvd file (was the run started here?)")
    root = ET.parse(pvds[0]).getroot()
    return [
        (float(ds.get("timestep")), run_dir / ds.get("file"))
        for ds in root.findall("Collection/DataSet")
    ]


def frame_times(run_dir: str | os.PathLike) -> np.ndarray:
    """The times of a run's frames [s]."""
    return np.array([t for t, _ in _collection(Path(run_dir))])


def read_frame(run_dir: str | os.PathLike, index: int) -> Frame:
    """Frame `index` of a run (negative counts from the end)."""
    t, file = _collection(Path(run_dir))[index]
    return read_vtm(file, t)


def read_frames(run_dir: str | os.PathLike) -> list[Frame]:
    """Every frame of a run."""
    return [read_vtm(file, t) for t, file in _collection(Path(run_dir))]
