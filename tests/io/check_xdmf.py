#!/usr/bin/python3
"""Check a dem2d snapshots.xmf against the snapshots.h5 it describes.

    tests/io/check_xdmf.py DIR/snapshots.xmf [--paraview]

Parses the XDMF with xml.etree and checks, with h5py: the document's shape (one temporal
collection of spatial collections, each at a time not before the previous one, holding a
"particles" grid, an "outlines" grid when the snapshot has particle outlines, and a "walls"
grid when it has a wall outline, and a "shell" grid when it has a shell); that every HDF DataItem names a dataset of the HDF5 file
(path relative to the .xmf) with exactly the stated Dimensions, NumberType and Precision;
that every XML DataItem holds as many numbers as its Dimensions say; that topologies,
geometries and attributes agree on their sizes and the connectivity stays within the points;
that the grids are exactly the file's /snapshots, /outlines, /walls and /shell groups
(the shell's quadrilaterals the four quarters of each 9-node element of /shell_mesh); that each
particle's outline polygon (its cell of the "outlines" grid, in the snapshot's row order) is
counter-clockwise, centred on the particle's position and of the area of its superellipse
(semi_axis_a, semi_axis_b, exponent) less the polygon's discretisation (at most 1.5 %: an
inscribed polygon); and that the material names (Information and the grids' field data) are
the file's /materials/name. With --paraview, also opens the file with ParaView's three XDMF
readers (python3-paraview) and checks what each shows at every time step.

Run by tests/io/test_output.cpp (XdmfSidecar.EveryDataItemMatchesTheHdf5File,
SnapshotWriter.ShapedParticlesCarryTheirShapeAndOutlines). Exit status: 0
when every check passes, 1 otherwise (each problem printed), 2 for a usage error.
"""

import argparse
import math
import os
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np

DTYPES = {("Float", "8"): np.dtype("<f8"), ("Float", "4"): np.dtype("<f4"), ("Int", "8"): np.dtype("<i8"),
          ("Int", "4"): np.dtype("<i4")}


def superellipse_area(a, b, n):
    """4ab Gamma(1+1/n)^2 / Gamma(1+2/n), elementwise."""
    g = np.vectorize(math.gamma)
    return 4.0 * a * b * g(1.0 + 1.0 / n) ** 2 / g(1.0 + 2.0 / n)


class Checker:
    def __init__(self, xmf):
        self.xmf = xmf
        self.problems = []
        self.items = 0

    def fail(self, where, what):
        self.problems.append(f"{where}: {what}")

    def data_item(self, item, where, h5):
        """The values of a DataItem (None after a problem), its Dimensions checked."""
        self.items += 1
        dims = tuple(int(d) for d in item.get("Dimensions", "").split())
        kind = (item.get("NumberType", "Float"), item.get("Precision", "4"))
        if kind not in DTYPES:
            self.fail(where, f"unexpected NumberType/Precision {kind}")
            return None
        fmt = item.get("Format", "XML")
        text = (item.text or "").strip()
        if fmt == "XML":
            values = text.split()
            if len(values) != math.prod(dims):
                self.fail(where, f"{len(values)} inline values for Dimensions {dims}")
                return None
            return np.array([float(v) for v in values]).reshape(dims)
        if fmt != "HDF":
            self.fail(where, f"unexpected Format {fmt}")
            return None
        name, _, path = text.partition(":")
        if name != os.path.basename(h5.filename):
            self.fail(where, f"refers to {name}, not {os.path.basename(h5.filename)}")
            return None
        if path not in h5 or not isinstance(h5[path], h5py.Dataset):
            self.fail(where, f"no dataset {path}")
            return None
        d = h5[path]
        if d.shape != dims:
            self.fail(where, f"{path} has shape {d.shape}, the DataItem says {dims}")
        if d.dtype != DTYPES[kind]:
            self.fail(where, f"{path} is {d.dtype}, the DataItem says {kind}")
        return d[()]

    def grid(self, grid, where, h5):
        """Checks one uniform grid; returns its name and sizes."""
        topology, geometry = grid.find("Topology"), grid.find("Geometry")
        if topology is None or geometry is None:
            self.fail(where, "no Topology or Geometry")
            return None
        if geometry.get("GeometryType") != "XY":
            self.fail(where, f"GeometryType {geometry.get('GeometryType')}")
        points = self.data_item(geometry.find("DataItem"), where + "/Geometry", h5)
        n_points = 0 if points is None else points.shape[0]
        if points is not None and (points.ndim != 2 or points.shape[1] != 2):
            self.fail(where, f"geometry of shape {points.shape}, not (N, 2)")
        elements = int(topology.get("NumberOfElements"))
        nodes = int(topology.get("NodesPerElement"))
        kind = topology.get("TopologyType")
        expected = {"particles": ("Polyvertex", 1), "walls": ("Polyline", 2),
                    "outlines": ("Polygon", max(nodes, 3)),
                    "shell": ("Quadrilateral", 4)}.get(grid.get("Name"))
        if expected != (kind, nodes):
            self.fail(where, f"grid {grid.get('Name')} has topology {kind} of {nodes} nodes")
        item, cells = topology.find("DataItem"), None
        if item is None:
            if elements != 0 or n_points != 0:
                self.fail(where, f"no connectivity for {elements} elements of {n_points} points")
        else:
            cells = self.data_item(item, where + "/Topology", h5)
            if cells is not None:
                if cells.size != elements * nodes:
                    self.fail(where, f"{cells.size} connectivity values for {elements} x {nodes}")
                if cells.size and (cells.min() < 0 or cells.max() >= n_points):
                    self.fail(where, f"connectivity outside the {n_points} points")
        fields, cell_values = [], {}
        for attribute in grid.findall("Attribute"):
            at = f"{where}/Attribute[{attribute.get('Name')}]"
            values = self.data_item(attribute.find("DataItem"), at, h5)
            center = attribute.get("Center")
            want_center = "Cell" if grid.get("Name") == "outlines" else "Node"
            if grid.get("Name") == "shell" and attribute.get("Name") == "bar":
                want_center = "Cell"
            if center == "Grid":
                fields.append((attribute.get("Name"), values))
            elif center != want_center:
                self.fail(at, f"Center {center}")
            elif values is not None:
                rows = elements if center == "Cell" else n_points
                if values.shape[0] != rows:
                    self.fail(at, f"{values.shape[0]} values for {rows} {center.lower()}s")
                cell_values[attribute.get("Name")] = values
                want = "Scalar" if values.ndim == 1 else "Vector"
                if attribute.get("AttributeType") != want:
                    self.fail(at, f"AttributeType {attribute.get('AttributeType')}, not {want}")
        if grid.get("Name") == "outlines" and points is not None and item is not None and cells is not None:
            self.outlines(where, points, cells.reshape(elements, nodes), cell_values)
        return grid.get("Name"), n_points, elements, fields

    def outlines(self, where, points, cells, values):
        """Each cell a counter-clockwise polygon centred on its particle's position with nearly
        the area of its superellipse."""
        missing = {"position", "semi_axis_a", "semi_axis_b", "exponent"} - set(values)
        if missing:
            self.fail(where, f"no cell attributes {sorted(missing)}")
            return
        if cells.size == 0:
            return
        x, y = points[cells, 0].astype(float), points[cells, 1].astype(float)  # (N, K)
        area = 0.5 * np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)
        exact = superellipse_area(values["semi_axis_a"], values["semi_axis_b"], values["exponent"])
        ratio = area / exact
        bad = np.flatnonzero((ratio < 0.985) | (ratio > 1.0))
        if bad.size:
            self.fail(where, f"{bad.size} outlines whose area is not their superellipse's "
                      f"(row {bad[0]}: {area[bad[0]]:.6g} m^2, the superellipse {exact[bad[0]]:.6g})")
        size = np.maximum(values["semi_axis_a"], values["semi_axis_b"])
        centre = np.stack([x.mean(axis=1), y.mean(axis=1)], axis=1)
        off = np.linalg.norm(centre - values["position"], axis=1)
        scale = 1e-6 * (np.abs(values["position"]).max(axis=1) + size)
        bad = np.flatnonzero(off > scale)
        if bad.size:
            self.fail(where, f"{bad.size} outlines not centred on their particle (row {bad[0]}: "
                      f"{off[bad[0]]:.3g} m off)")

    def document(self, h5):
        try:
            root = ET.parse(self.xmf).getroot()
        except ET.ParseError as e:
            self.fail(self.xmf, f"not well-formed XML: {e}")
            return None
        if root.tag != "Xdmf" or root.get("Version") != "3.0":
            self.fail("/Xdmf", "not an XDMF 3 document")
        domain = root.find("Domain")
        names = [n.decode() if isinstance(n, bytes) else str(n) for n in h5["materials/name"][()]]
        info = domain.find("Information")
        lookup = ",".join(f"{k}={n}" for k, n in enumerate(names))
        if names and (info is None or info.get("Name") != "material_names" or info.get("Value") != lookup):
            self.fail("/Domain/Information", f"not material_names = {lookup}")
        temporal = domain.findall("Grid")
        if len(temporal) != 1 or temporal[0].get("CollectionType") != "Temporal":
            self.fail("/Domain", "not one temporal collection")
            return
        last, seen_snapshots, seen_walls, seen_outlines, seen_shell = -math.inf, [], [], [], []
        for step in temporal[0].findall("Grid"):
            where = f"/Domain/Grid/Grid[{step.get('Name')}]"
            if step.get("CollectionType") != "Spatial":
                self.fail(where, "not a spatial collection")
                continue
            time = float(step.find("Time").get("Value"))
            if time < last:
                self.fail(where, f"time {time} before {last}")
            last = time
            snapshot = step.get("Name").removeprefix("snapshot_")
            grids = [self.grid(g, f"{where}/Grid[{g.get('Name')}]", h5) for g in step.findall("Grid")]
            kinds = [g[0] for g in grids if g]
            if kinds and kinds[-1] == "shell":
                seen_shell.append(snapshot)
                self.shell(where, snapshot, grids[-1], h5)
                kinds = kinds[:-1]
            if kinds not in (["particles"], ["particles", "walls"], ["particles", "outlines"],
                             ["particles", "outlines", "walls"]):
                self.fail(where, f"grids {kinds}")
                continue
            seen_snapshots.append(snapshot)
            if "walls" in kinds:
                seen_walls.append(snapshot)
            if "outlines" in kinds:
                seen_outlines.append(snapshot)
                outline = grids[1]
                n = h5["snapshots"][snapshot]["id"].shape[0]
                k = h5["outlines"][snapshot]["points"].shape[0] // max(n, 1)
                if outline[2] != n or outline[1] != n * k:
                    self.fail(where, f"outlines of {outline[2]} cells, {outline[1]} points for {n} particles")
                if dict(outline[3]).keys() != dict(grids[0][3]).keys():
                    self.fail(where, "outlines' material field data differ from the particles'")
            if float(h5["snapshots"][snapshot].attrs["time"]) != time:
                self.fail(where, "time differs from the group's attribute")
            fields = dict(grids[0][3])
            wanted = {f"material: {n}": k for k, n in enumerate(names)}
            if set(fields) != set(wanted) or any(fields[f] is None or fields[f].tolist() != [wanted[f]] for f in wanted):
                self.fail(where, f"material field data {sorted(fields)}, not {sorted(wanted)}")
        if seen_snapshots != sorted(h5["snapshots"]):
            self.fail("/Domain/Grid", f"lists {seen_snapshots}, the file holds {sorted(h5['snapshots'])}")
        walls = sorted(h5["walls"]) if "walls" in h5 else []
        if seen_walls != walls:
            self.fail("/Domain/Grid", f"walls of {seen_walls}, the file holds {walls}")
        outlines = sorted(h5["outlines"]) if "outlines" in h5 else []
        if seen_outlines != outlines:
            self.fail("/Domain/Grid", f"outlines of {seen_outlines}, the file holds {outlines}")
        shell = sorted(h5["shell"]) if "shell" in h5 else []
        if seen_shell != shell:
            self.fail("/Domain/Grid", f"shell of {seen_shell}, the file holds {shell}")
        return seen_snapshots

    def shell(self, where, snapshot, grid, h5):
        """The shell grid: the nodes of /shell/NNNNNN, four quadrilaterals per element of
        /shell_mesh/elements, each over its element's nodes, with displacement and von_mises."""
        name, n_points, cells, fields = grid
        if "shell_mesh" not in h5 or snapshot not in h5.get("shell", {}):
            self.fail(where, "a shell grid without /shell_mesh or its /shell group")
            return
        elements = h5["shell_mesh/elements"][()]
        quads = h5["shell_mesh/quadrilaterals"][()]
        if n_points != h5["shell"][snapshot]["points"].shape[0] or cells != 4 * elements.shape[0]:
            self.fail(where, f"shell of {cells} cells, {n_points} points")
            return
        for e in range(elements.shape[0]):
            if set(quads[4 * e:4 * e + 4].ravel()) != set(elements[e]):
                self.fail(where, f"element {e}'s quadrilaterals are not over its nodes")
                return


def check_paraview(xmf, h5, snapshots, problems):
    """Opens `xmf` with ParaView's three XDMF readers; each must show, at every time step, the
    particles (a point per particle), their outlines (a polygon cell per particle, its points,
    speed as cell data, each cell of the area of its polygon in the file) and the wall outline
    (a cell per segment)."""
    from paraview import servermanager
    from paraview import simple
    from vtkmodules.vtkFiltersVerdict import vtkCellSizeFilter

    readers = {"XDMF Reader": lambda: simple.XDMFReader(FileNames=[xmf]),
               "Xdmf3 Reader S": lambda: simple.Xdmf3ReaderS(FileName=[xmf]),
               "Xdmf3 Reader T": lambda: simple.Xdmf3ReaderT(FileName=[xmf])}
    for label, make in readers.items():
        reader = make()
        reader.UpdatePipelineInformation()
        values = reader.TimestepValues
        times = [float(t) for t in values] if hasattr(values, "__iter__") else [float(values)]
        if not times and len(snapshots) == 1:  # one snapshot: no time steps
            times = [float(h5["snapshots"][snapshots[0]].attrs["time"])]
        if len(times) != len(snapshots):
            problems.append(f"{label}: {len(times)} time steps for {len(snapshots)} snapshots")
            continue
        for name, time in zip(snapshots, times):
            reader.UpdatePipeline(time)
            data = servermanager.Fetch(reader)
            blocks = []
            it = data.NewIterator()
            it.InitTraversal()
            while not it.IsDoneWithTraversal():
                ds = it.GetCurrentDataObject()
                speed = ds.GetPointData().GetArray("speed") is not None or ds.GetCellData().GetArray("speed") is not None
                blocks.append((ds.GetNumberOfPoints(), ds.GetNumberOfCells(), speed))
                if "outlines" in h5 and name in h5["outlines"] and ds.GetNumberOfCells() and ds.GetCellType(0) == 7:
                    sizes = vtkCellSizeFilter()  # the polygons as ParaView sees them
                    sizes.SetInputData(ds)
                    sizes.SetComputeArea(True)
                    sizes.Update()
                    area = sizes.GetOutput().GetCellData().GetArray("Area")
                    seen = np.array([area.GetValue(i) for i in range(area.GetNumberOfTuples())])
                    pts = h5["outlines"][name]["points"][()].astype(float).reshape(len(seen), -1, 2)
                    x, y = pts[..., 0], pts[..., 1]
                    want_area = 0.5 * np.abs((x * np.roll(y, -1, 1) - np.roll(x, -1, 1) * y).sum(1))
                    if not np.allclose(seen, want_area, rtol=1e-9, atol=0):
                        problems.append(f"{label}: snapshot {name}: ParaView's polygon areas differ from the file's")
                it.GoToNextItem()
            n = h5["snapshots"][name]["id"].shape[0]
            want = [(n, n, True)]
            if "outlines" in h5 and name in h5["outlines"]:
                want.append((h5["outlines"][name]["points"].shape[0], n, True))
            if "walls" in h5 and name in h5["walls"]:
                w = h5["walls"][name]
                want.append((w["points"].shape[0], w["segments"].shape[0], False))
            if n == 0:  # no particles: the readers show an empty block without arrays, or none
                blocks = [b for b in blocks if b[:2] != (0, 0)]
                want = want[1:]
            if blocks != want:
                problems.append(f"{label}: snapshot {name} at t = {time}: blocks (points, cells, speed) "
                                f"{blocks}, not {want}")
        simple.Delete(reader)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("xmf", help="snapshots.xmf written by dem2d")
    parser.add_argument("--paraview", action="store_true", help="also open it with ParaView's readers")
    args = parser.parse_args(argv)
    xmf = os.path.abspath(args.xmf)  # the Xdmf3 readers resolve the .h5 from the .xmf's folder
    h5_path = os.path.join(os.path.dirname(xmf), "snapshots.h5")
    checker = Checker(xmf)
    with h5py.File(h5_path, "r") as h5:
        snapshots = checker.document(h5)
        if args.paraview and snapshots and not checker.problems:
            check_paraview(xmf, h5, snapshots, checker.problems)
    for p in checker.problems:
        print(p)
    if checker.problems:
        print(f"check_xdmf: {xmf}: {len(checker.problems)} problems")
        return 1
    print(f"check_xdmf: {xmf}: {len(snapshots or [])} time steps, {checker.items} DataItems, all match"
          + (", and ParaView's three XDMF readers show them" if args.paraview else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
