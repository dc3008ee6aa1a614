#!/usr/bin/env python3
"""Reads back the files anim-io wrote and compares them with what it meant to write.

Usage: check_meshio.py MANIFEST.json

The manifest (written by anim-io's conformance case "VTK/PLY/OBJ written, read back by
meshio") lists every file with its points, cells and fields. This script reads each file with
meshio (an independent implementation of the formats), or, for .vti image data and .pvd
collections which meshio does not read, with its own ElementTree + base64 decoder, and prints
one JSON object on stdout:

    {"meshio": "5.3.5", "results": [{"name", "max_diff", "checked", "reader", "error"?}, ...]}

`max_diff` is the largest absolute difference between a written and a read value (points and
every field); a structural mismatch (cell types, connectivity, field names or shapes) is reported
as `error`. When meshio is not installed it prints {"skipped": "..."} and exits 0.
"""

import base64
import json
import os
import sys
import xml.etree.ElementTree as ET

try:
    import meshio
    import numpy as np
except ImportError as e:  # pragma: no cover - depends on the machine
    print(json.dumps({"skipped": f"Python package missing ({e.name})"}))
    sys.exit(0)


class Mismatch(Exception):
    pass


def diff(name, expected, got):
    """Largest absolute difference of two arrays of equal size (flattened)."""
    e = np.asarray(expected, dtype=np.float64).reshape(-1)
    g = np.asarray(got, dtype=np.float64).reshape(-1)
    if e.shape != g.shape:
        raise Mismatch(f"{name}: {g.size} values read, {e.size} written")
    if e.size == 0:
        return 0.0
    bad = np.isnan(e) != np.isnan(g)
    if bad.any():
        raise Mismatch(f"{name}: NaN pattern differs")
    return float(np.nanmax(np.abs(e - g))) if e.size else 0.0


def same_cells(name, expected, got):
    e = np.asarray(expected, dtype=np.int64)
    g = np.asarray(got, dtype=np.int64)
    if e.size == 0 and g.size == 0:
        return
    if e.shape != g.shape or not np.array_equal(e, g):
        raise Mismatch(f"{name}: connectivity differs (written {e.shape}, read {g.shape})")


def check_mesh(entry, path):
    m = meshio.read(path)
    worst = diff("points", entry["points"], m.points)
    # Cell blocks in order, same type and connectivity.
    written = [(b["type"], b["data"]) for b in entry["cells"] if len(b["data"]) > 0]
    read = [(b.type, b.data) for b in m.cells if len(b.data) > 0]
    if [t for t, _ in written] != [t for t, _ in read]:
        raise Mismatch(f"cell blocks: wrote {[t for t, _ in written]}, read {[t for t, _ in read]}")
    for (t, w), (_, r) in zip(written, read):
        same_cells(t, w, r)
    for key, f in entry["point_data"].items():
        if key not in m.point_data:
            raise Mismatch(f"point field {key} missing (read {sorted(m.point_data)})")
        worst = max(worst, diff(key, f["values"], m.point_data[key]))
    for key, f in entry["cell_data"].items():
        if key not in m.cell_data:
            raise Mismatch(f"cell field {key} missing (read {sorted(m.cell_data)})")
        got = np.concatenate([np.asarray(a).reshape(len(a), -1) for a in m.cell_data[key]])
        worst = max(worst, diff(key, f["values"], got))
    extra = set(m.point_data) - set(entry["point_data"]) - {"obj:vt", "obj:vn"}
    if extra:
        raise Mismatch(f"unexpected point fields {sorted(extra)}")
    if "lines" in entry:
        # meshio's OBJ reader skips `l` statements: read them here, 1-based.
        segs = []
        with open(path) as fh:
            for line in fh:
                if line.startswith("l "):
                    idx = [int(t.split("/")[0]) - 1 for t in line.split()[1:]]
                    segs += [[a, b] for a, b in zip(idx, idx[1:])]
        same_cells("lines", entry["lines"], segs)
    nf = len(entry["point_data"]) + len(entry["cell_data"])
    blocks = "+".join(t for t, _ in written) or "no cells"
    return worst, f"points, cells ({blocks}), {nf} fields", "meshio"


DTYPES = {"Float64": "<f8", "Float32": "<f4", "Int32": "<i4", "Int64": "<i8", "UInt8": "u1"}


def decode(da):
    """Values of a VTK XML DataArray: inline base64 with a UInt64 byte count, or ASCII."""
    dtype = np.dtype(DTYPES[da.get("type")])
    text = "".join((da.text or "").split())
    if da.get("format") == "binary":
        raw = base64.b64decode(text, validate=True)
        nbytes = int(np.frombuffer(raw[:8], "<u8")[0])
        if nbytes != len(raw) - 8:
            raise Mismatch(f"{da.get('Name')}: header says {nbytes} bytes, {len(raw) - 8} follow")
        return np.frombuffer(raw[8:], dtype)
    return np.array((da.text or "").split(), dtype=dtype)


def check_vti(entry, path):
    root = ET.parse(path).getroot()
    if root.get("type") != "ImageData" or root.get("header_type") != "UInt64":
        raise Mismatch(f"VTKFile type {root.get('type')}, header_type {root.get('header_type')}")
    img = root.find("ImageData")
    ext = [int(v) for v in img.get("WholeExtent").split()]
    dims = [ext[1] - ext[0] + 1, ext[3] - ext[2] + 1, ext[5] - ext[4] + 1]
    if dims != entry["dims"]:
        raise Mismatch(f"dims {dims}, wrote {entry['dims']}")
    worst = diff("origin", entry["origin"], [float(v) for v in img.get("Origin").split()])
    worst = max(worst, diff("spacing", entry["spacing"], [float(v) for v in img.get("Spacing").split()]))
    piece = img.find("Piece")
    for tag, key in (("PointData", "point_data"), ("CellData", "cell_data")):
        node = piece.find(tag)
        arrays = {} if node is None else {da.get("Name"): da for da in node.findall("DataArray")}
        if set(arrays) != set(entry[key]):
            raise Mismatch(f"{tag}: read {sorted(arrays)}, wrote {sorted(entry[key])}")
        for name, f in entry[key].items():
            da = arrays[name]
            if int(da.get("NumberOfComponents", "1")) != f["components"]:
                raise Mismatch(f"{name}: {da.get('NumberOfComponents')} components")
            worst = max(worst, diff(name, f["values"], decode(da)))
    n = len(entry["point_data"]) + len(entry["cell_data"])
    return worst, f"extent, origin, spacing, {n} fields", "ElementTree+base64 (meshio reads no .vti)"


def check_pvd(entry, path):
    root = ET.parse(path).getroot()
    sets = root.find("Collection").findall("DataSet")
    if len(sets) != len(entry["frames"]):
        raise Mismatch(f"{len(sets)} datasets, wrote {len(entry['frames'])}")
    worst = 0.0
    for ds, fr in zip(sets, entry["frames"]):
        worst = max(worst, diff("timestep", [fr["time"]], [float(ds.get("timestep"))]))
        if ds.get("file") != fr["file"]:
            raise Mismatch(f"file {ds.get('file')}, wrote {fr['file']}")
        m = meshio.read(os.path.join(os.path.dirname(path), ds.get("file")))
        worst = max(worst, diff("points", fr["points"], m.points))
        worst = max(worst, diff("speed", fr["speed"], m.point_data["speed"]))
        if [b.type for b in m.cells] != ["tetra"]:
            raise Mismatch(f"frame cells {[b.type for b in m.cells]}")
        same_cells("tetra", entry["cells"], m.cells[0].data)
    return worst, f"{len(sets)} timesteps and files, each frame's points, tetrahedra, field", "ElementTree + meshio"


def check_reader(entry, path):
    """The committed Gmsh/TetGen files: meshio's reading must equal anim-io's."""
    m = meshio.read(path)
    worst = diff("points", entry["points"], m.points)
    for t in ("tetra", "triangle"):
        blocks = [b.data for b in m.cells if b.type == t]
        got = np.concatenate(blocks) if blocks else np.zeros((0, 4 if t == "tetra" else 3), dtype=np.int64)
        same_cells(t, entry[t], got)
    return worst, "points, tetrahedra, triangles vs anim-io's reader", "meshio"


def main():
    with open(sys.argv[1]) as fh:
        manifest = json.load(fh)
    results = []
    for entry in manifest["files"]:
        path = entry.get("path") or os.path.join(manifest["dir"], entry["name"])
        check = {"mesh": check_mesh, "vti": check_vti, "pvd": check_pvd, "reader": check_reader}[entry["kind"]]
        try:
            worst, checked, reader = check(entry, path)
            results.append({"name": entry["name"], "max_diff": worst, "checked": checked, "reader": reader})
        except Exception as e:  # report, never crash: every file gets a row
            results.append({"name": entry["name"], "error": f"{type(e).__name__}: {e}"})
    print(json.dumps({"meshio": meshio.__version__, "results": results}))


if __name__ == "__main__":
    main()
