"""Checks that the programs' own libraries load the files: Gmsh (the `gmsh` wheel: the Gmsh app's
library and API) for dsm.msh and dsm-solid.msh, and VTK (the `vtk` wheel; ParaView reads .vtu with
the same vtkXMLUnstructuredGridReader) for dsm.vtu. See docs/verification.md."""

import json

import numpy as np

from vcommon import (POINT_FIELDS, CELL_FIELDS, REL_DOUBLE, CheckFailed, canonical_triangles, close, require,
                     watertight)

GMSH_TRIANGLE = 2  # Gmsh element type: 3-node triangle
VTK_TRIANGLE = 5
VTK_DOUBLE = 11


def gmsh_read(out, name):
    """Opens `name` with Gmsh; returns node coordinates (n, 3) in tag order, triangles as 0-based
    indices into them, and Gmsh's count of unique mesh edges."""
    import gmsh
    path = out.path(name)
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        try:
            gmsh.open(str(path))
        except Exception as e:  # the API raises on read errors
            raise CheckFailed(f"{name}: Gmsh cannot open it: {e}")
        errors = [m for m in gmsh.logger.get() if m.startswith("Error")]
        require(not errors, f"{name}: Gmsh: {' | '.join(errors)[:600]}")
        tags, coords, _ = gmsh.model.mesh.getNodes()
        types, _, nodes = gmsh.model.mesh.getElements()
        require(GMSH_TRIANGLE in list(types), f"{name}: Gmsh finds no triangles (element types {list(types)})")
        others = sorted(int(t) for t in types if t != GMSH_TRIANGLE)
        require(not others, f"{name}: Gmsh finds element types {others} besides triangles")
        tri_nodes = np.asarray(nodes[list(types).index(GMSH_TRIANGLE)], dtype=np.int64).reshape(-1, 3)
        gmsh.model.mesh.createEdges()
        edge_tags, _ = gmsh.model.mesh.getAllEdges()
        n_edges = len(edge_tags)
    finally:
        gmsh.logger.stop()
        gmsh.finalize()
    tags = np.asarray(tags, dtype=np.int64)
    order = np.argsort(tags)
    sorted_tags = tags[order]
    pos = np.searchsorted(sorted_tags, tri_nodes)
    require(np.all(pos < len(tags)) and np.array_equal(sorted_tags[np.minimum(pos, len(tags) - 1)], tri_nodes),
            f"{name}: triangles refer to nodes Gmsh did not read")
    return np.asarray(coords).reshape(-1, 3)[order], pos, n_edges


def check_gmsh_surface(out):
    """dsm.msh opened by Gmsh: node and triangle counts, coordinates and triangles equal the
    reference (CSV vertices, dsm.vtu triangles)."""
    name = "dsm.msh"
    _, ref_pts, ref_tris = out.ref()
    pts, tris, n_edges = gmsh_read(out, name)
    require(len(pts) == len(ref_pts), f"{name}: Gmsh reads {len(pts)} nodes, dsm-vertices.csv has {len(ref_pts)}")
    require(len(tris) == len(ref_tris), f"{name}: Gmsh reads {len(tris)} triangles, dsm.vtu has {len(ref_tris)}")
    close(pts, ref_pts, REL_DOUBLE, f"{name}: Gmsh node coordinates vs CSV x, y, elevation_uk")
    require(np.array_equal(canonical_triangles(tris), canonical_triangles(ref_tris)),
            f"{name}: Gmsh's triangles differ from dsm.vtu's")
    # An open surface (a disc): V - E + F = 1.
    euler = len(pts) - n_edges + len(tris)
    require(euler == 1, f"{name}: Gmsh counts {len(pts)} nodes, {n_edges} edges, {len(tris)} triangles: "
            f"Euler characteristic {euler}, a single surface patch has 1")


def check_gmsh_solid(out):
    """dsm-solid.msh opened by Gmsh: a closed surface (every edge in two triangles, V - E + F = 2),
    node and triangle counts equal to dsm-solid.json's, watertight with consistent orientation."""
    name = "dsm-solid.msh"
    info = json.loads(out.path("dsm-solid.json").read_text())
    require({"vertices", "triangles"} <= set(info), f"dsm-solid.json: keys {sorted(info)} lack vertices, triangles")
    pts, tris, n_edges = gmsh_read(out, name)
    require(len(pts) == info["vertices"], f"{name}: Gmsh reads {len(pts)} nodes, dsm-solid.json says {info['vertices']}")
    require(len(tris) == info["triangles"],
            f"{name}: Gmsh reads {len(tris)} triangles, dsm-solid.json says {info['triangles']}")
    require(3 * len(tris) == 2 * n_edges, f"{name}: Gmsh counts {n_edges} edges for {len(tris)} triangles; "
            f"a closed surface has {3 * len(tris) // 2} (each edge in two triangles)")
    euler = len(pts) - n_edges + len(tris)
    require(euler == 2, f"{name}: Euler characteristic V - E + F = {euler}, a closed surface has 2")
    watertight(tris, f"{name} (Gmsh)")


def vtk_read(out, name):
    """Reads `name` with VTK's vtkXMLUnstructuredGridReader; fails on any VTK error message."""
    from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
    path = out.path(name)
    log = vtkStringOutputWindow()
    previous = vtkOutputWindow.GetInstance()
    vtkOutputWindow.SetInstance(log)
    try:
        r = vtkXMLUnstructuredGridReader()
        r.SetFileName(str(path))
        r.Update()
    finally:
        vtkOutputWindow.SetInstance(previous)
    msgs = log.GetOutput().strip()
    require("ERROR" not in msgs and "Error" not in msgs, f"{name}: VTK: {msgs[:600]}")
    ug = r.GetOutput()
    require(ug is not None and ug.GetPoints() is not None, f"{name}: VTK read no points")
    return ug


def check_vtk(out):
    """dsm.vtu read by VTK (ParaView's reader): Float64 points equal to the CSV, triangles only and
    equal to the reference, point data arrays equal to the CSV, cell data present."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    name = "dsm.vtu"
    cols, ref_pts, ref_tris = out.ref()
    ug = vtk_read(out, name)
    n, m = ug.GetNumberOfPoints(), ug.GetNumberOfCells()
    require(n == len(ref_pts), f"{name}: VTK reads {n} points, dsm-vertices.csv has {len(ref_pts)}")
    require(m == len(ref_tris), f"{name}: VTK reads {m} cells, dsm.vtu's triangles (meshio) are {len(ref_tris)}")
    dt = ug.GetPoints().GetDataType()
    require(dt == VTK_DOUBLE, f"{name}: VTK point type {ug.GetPoints().GetData().GetDataTypeAsString()}, "
            "expected Float64 (double)")
    close(vtk_to_numpy(ug.GetPoints().GetData()), ref_pts, REL_DOUBLE, f"{name}: VTK points vs CSV")
    types = vtk_to_numpy(ug.GetCellTypes())
    require(np.all(types == VTK_TRIANGLE), f"{name}: VTK cell types {sorted(set(types.tolist()))}, expected 5 "
            "(triangle)")
    conn = vtk_to_numpy(ug.GetCells().GetConnectivityArray()).reshape(-1, 3)
    require(np.array_equal(canonical_triangles(conn), canonical_triangles(ref_tris)),
            f"{name}: VTK's triangles differ from the reference")
    pd = ug.GetPointData()
    have = sorted(pd.GetArrayName(k) for k in range(pd.GetNumberOfArrays()))
    want = {k: cols[k] for k in ["elevation_uk", "kriging_std", "elevation_idw"]}
    want["uk_minus_idw"] = cols["elevation_uk"] - cols["elevation_idw"]
    for field in POINT_FIELDS:
        arr = pd.GetArray(field)
        require(arr is not None, f"{name}: VTK finds no point data '{field}' (has {have})")
        close(vtk_to_numpy(arr), want[field], REL_DOUBLE, f"{name}: VTK point data {field} vs CSV", atol=1e-9)
    cd = ug.GetCellData()
    for field in CELL_FIELDS:
        arr = cd.GetArray(field)
        require(arr is not None and arr.GetNumberOfTuples() == m, f"{name}: VTK finds no cell data '{field}' "
                f"with {m} values")


CHECKS = [
    ("gmsh: dsm.msh", check_gmsh_surface),
    ("gmsh: dsm-solid.msh closed", check_gmsh_solid),
    ("vtk: dsm.vtu (ParaView's reader)", check_vtk),
]
