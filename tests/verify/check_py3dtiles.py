"""3dtiles/ read back with py3dtiles (12.1.1, installed without its dependencies: its tileset and
glTF-content readers need numpy, pygltflib and psutil only; numba, which pins numpy < 2.4, is
for its point-cloud tilers): the tree, each tile's box and geometric error as py3dtiles parses
them, every content GLB through py3dtiles' reader (`read_binary_tile_content`) and its
`gltf_utils.get_attribute`, then containment in the tile's box and every ancestor's, and error
monotonicity. Beside check_gltf.check_tileset (our own reader of the same files)."""

from pathlib import Path

import numpy as np

from vcommon import CheckFailed, require

# A tile's content may stick out of its box by this much (metres): float32 rounding.
BOX_TOL = 1e-3


def content_points(tile, root):
    """The tile content's positions in the tileset frame (z up): py3dtiles' glTF reader, each
    node's translation added along the scene (no rotation or scale, as check_gltf asserts),
    glTF's Y-up turned to z-up (3D Tiles 1.1 "glTF transforms")."""
    from py3dtiles.tileset.content import gltf_utils
    from py3dtiles.tileset.content.gltf import Gltf
    content = tile.get_or_fetch_content(root)
    require(isinstance(content, Gltf), f"py3dtiles reads {tile.content_uri} as {type(content).__name__}, not glTF")
    g = content._gltf
    out = []

    def walk(i, offset):
        node = g.nodes[i]
        t = offset + np.array(node.translation or [0.0, 0.0, 0.0], dtype=float)
        if node.mesh is not None:
            for p in g.meshes[node.mesh].primitives:
                acc = g.accessors[p.attributes.POSITION]
                pos = gltf_utils.get_array_from_accessor(acc, g.bufferViews[acc.bufferView], g.binary_blob())
                out.append(pos.astype(float) + t)
        for c in node.children or []:
            walk(c, t)

    for i in g.scenes[g.scene or 0].nodes:
        walk(i, np.zeros(3))
    require(out, f"{tile.content_uri}: no positions")
    # Cross-check with py3dtiles' own attribute reader (indexed: one row per triangle corner).
    corners = gltf_utils.get_attribute(g, "POSITION")
    require(corners is not None and len(corners) > 0, f"{tile.content_uri}: py3dtiles finds no POSITION")
    p = np.vstack(out)
    return np.column_stack([p[:, 0], -p[:, 2], p[:, 1]])


def inside(points, box, what):
    """Fails unless every point lies in the 3D Tiles box (centre + three half-axes)."""
    b = np.asarray(box, dtype=float)
    c, axes = b[:3], b[3:].reshape(3, 3)
    for a in axes:
        n = np.linalg.norm(a)
        require(n > 0, f"{what}: a zero half-axis")
        over = (np.abs((points - c) @ a) / n - n).max()
        require(over <= BOX_TOL, f"{what} box by {over:.4f} m")


def check_py3dtiles(out):
    """3dtiles/tileset.json through py3dtiles: version 1.1, a root transform, boxes, every
    content inside its tile's and every ancestor's box, errors not growing towards the leaves
    and 0 at them, at least two levels with content."""
    try:
        from py3dtiles.tileset import TileSet
    except ImportError as e:
        raise CheckFailed(f"py3dtiles is not installed ({e}): run .ci/verify-setup.sh")
    path = out.path("3dtiles/tileset.json")
    ts = TileSet.from_file(Path(path))
    version = getattr(ts.asset.version, "value", ts.asset.version)
    require(version == "1.1", f"py3dtiles: asset version {version}")
    root = ts.root_tile
    require(root.transform is not None and not np.allclose(root.transform, np.identity(4)),
            "py3dtiles: the root has no transform")
    contents = 0

    def walk(tile, ancestors, depth):
        nonlocal contents
        box = tile.bounding_volume.to_dict().get("box")
        require(box is not None and len(box) == 12, f"py3dtiles: a tile at depth {depth} has no box")
        e = tile.geometric_error
        for a in ancestors[-1:]:
            require(e <= a.geometric_error, f"py3dtiles: a tile's geometricError {e} exceeds its parent's {a.geometric_error}")
        if ancestors:
            require(tile.transform is None or np.allclose(tile.transform, np.identity(4)),
                    f"py3dtiles: a tile at depth {depth} has its own transform (only the root's is expected)")
        if not tile.children:
            require(e == 0, f"py3dtiles: leaf {tile.content_uri} has geometricError {e}, expected 0")
        if tile.has_content():
            contents += 1
            p = content_points(tile, path.parent)
            for owner in (tile, *ancestors):
                inside(p, owner.bounding_volume.to_dict()["box"],
                       f"py3dtiles: {tile.content_uri} sticks out of {'its' if owner is tile else 'an ancestor'}")
        for c in tile.children:
            walk(c, ancestors + [tile], depth + 1)

    walk(root, [], 0)
    require(ts.geometric_error >= root.geometric_error, "py3dtiles: tileset geometricError below the root's")
    require(contents >= 2, f"py3dtiles: only {contents} content tiles")


CHECKS = [
    ("3dtiles: py3dtiles reader", check_py3dtiles),
]
