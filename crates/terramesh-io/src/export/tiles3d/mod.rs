//! Cesium 3D Tiles 1.1: a `tileset.json` over one GLB per tile, refined by replacement.
//!
//! The caller gives a tree of [`Tile`]s (their content in the tileset's frame: east, north, up
//! metres around the model origin, z up) with each tile's geometric error, and the tileset's
//! `transform` from that frame to Earth-centred, Earth-fixed coordinates. The writer computes
//! every bounding box from the content it encloses (its own and all its descendants'), so that
//! volumes contain their content by construction, and writes each content GLB with its
//! vertices relative to its box centre (the glTF node translation), Y-up as glTF requires:
//! 3D Tiles clients rotate glTF content from Y-up to Z-up before applying the transforms
//! (3D Tiles 1.1, section "glTF transforms"), which [`super::write_glb`] undoes in advance.
//! The level-of-detail tree itself is made elsewhere (`terramesh_mesh::lod_tree`), free of I/O.

mod bounds;
mod tileset;

use std::fs;
use std::io;
use std::path::Path;

use rayon::prelude::*;
use serde_json::Value;

use super::glb::{write_glb, GlbMesh, GlbOptions};
use crate::output::Output;
pub use bounds::{Aabb, BOX_PADDING};

/// The geometry of one tile, in the tileset's frame (z up).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TileContent {
    /// Vertices, metres.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, 0-based, counter-clockwise seen from above.
    pub triangles: Vec<[u32; 3]>,
    /// Linear RGB per vertex (empty: none).
    pub colours: Vec<[f32; 3]>,
}

/// A tile of the tree: its address, its geometric error (metres; a parent's at least its
/// children's, 0 at leaves that are the full model), its content and its children.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tile {
    /// Level (0 at the root) and column, row in that level's grid: names the content file
    /// `tiles/{level}/{x}_{y}.glb`.
    pub address: [u32; 3],
    /// What a client loses by drawing this tile instead of the full model, metres.
    pub geometric_error: f64,
    /// The tile's geometry; `None` for a tile that only groups children.
    pub content: Option<TileContent>,
    /// Finer tiles that replace this one.
    pub children: Vec<Tile>,
}

/// What [`write_tileset`] writes besides the tiles.
#[derive(Debug, Clone)]
pub struct TilesetOptions<'a> {
    /// Column-major 4x4 matrix from the tileset frame to ECEF (the root's `transform`).
    pub transform: [f64; 16],
    /// The tileset's own geometric error: what drawing nothing loses (at least the root's).
    pub geometric_error: f64,
    /// Names the content meshes.
    pub name: &'a str,
    /// `extras` of the tileset and of every content GLB (CRS, datum, origin...).
    pub extras: Value,
}

/// What [`write_tileset`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct TilesetSummary {
    /// Tiles in the tree.
    pub tiles: usize,
    /// Content files (GLB).
    pub contents: usize,
    /// Depth of the tree (levels, the root's included).
    pub levels: usize,
    /// The root's bounding box in the tileset frame.
    pub root_box: Aabb,
}

fn invalid(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, msg)
}

/// Writes `dir/tileset.json` (asset version 1.1, the root's `transform`, boxes, `REPLACE`
/// refinement) and `dir/tiles/{level}/{x}_{y}.glb` for every tile with content, the GLBs in
/// parallel. `dir` must exist; each file is written atomically (write the folder through
/// [`crate::folder::OutputFolder`] to replace a whole tileset atomically).
///
/// # Errors
/// `InvalidInput` when a child's geometric error exceeds its parent's, an error is negative
/// or not finite, or no tile has content; and I/O errors naming the file.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_io::export::tiles3d::{write_tileset, Tile, TileContent, TilesetOptions};
/// let content = |x: f64| TileContent {
///     vertices: vec![[x, 0.0, 1.0], [x + 10.0, 0.0, 2.0], [x, 10.0, 3.0]],
///     triangles: vec![[0, 1, 2]],
///     colours: vec![],
/// };
/// let leaf = |x: u32| Tile { address: [1, x, 0], geometric_error: 0.0, content: Some(content(10.0 * x as f64)), children: vec![] };
/// let root = Tile { address: [0, 0, 0], geometric_error: 1.5, content: Some(content(0.0)), children: vec![leaf(0), leaf(1)] };
/// let mut identity = [0.0; 16];
/// (0..4).for_each(|k| identity[5 * k] = 1.0);
/// let dir = tempfile::tempdir()?;
/// let opts = TilesetOptions { transform: identity, geometric_error: 3.0, name: "dsm", extras: serde_json::json!({}) };
/// let s = write_tileset(dir.path(), &root, &opts)?;
/// assert_eq!((s.tiles, s.contents, s.levels), (3, 3, 2));
/// assert_eq!(s.root_box.max, [20.0, 10.0, 3.0]);
/// let json = std::fs::read_to_string(dir.path().join("tileset.json"))?;
/// assert!(json.contains("\"version\":\"1.1\"") && json.contains("tiles/1/1_0.glb"));
/// # Ok(()) }
/// ```
pub fn write_tileset(dir: &Path, root: &Tile, opts: &TilesetOptions) -> io::Result<TilesetSummary> {
    check_errors(root, f64::INFINITY)?;
    if opts.geometric_error.is_nan() || opts.geometric_error < root.geometric_error {
        return Err(invalid(format!(
            "the tileset's geometric error {} is below the root's {}",
            opts.geometric_error, root.geometric_error
        )));
    }
    let boxes = bounds::tree_boxes(root);
    let Some(root_box) = boxes.first().copied().flatten() else {
        return Err(invalid("no tile of the tileset has content".into()));
    };
    let mut jobs = Vec::new();
    collect(root, &mut jobs);
    let dirs: std::collections::BTreeSet<u32> = jobs.iter().map(|t| t.address[0]).collect();
    for level in dirs {
        let d = dir.join("tiles").join(level.to_string());
        fs::create_dir_all(&d).map_err(|e| named(&d, e))?;
    }
    jobs.par_iter()
        .map(|t| write_content(dir, t, opts))
        .collect::<io::Result<Vec<()>>>()?;
    let json = tileset::tileset_json(root, &boxes, opts);
    let path = dir.join("tileset.json");
    let mut out = Output::create(Some(&path)).map_err(|e| named(&path, e))?;
    serde_json::to_writer(&mut out, &json).map_err(|e| named(&path, io::Error::other(e)))?;
    out.commit().map_err(|e| named(&path, e))?;
    Ok(TilesetSummary {
        tiles: count(root),
        contents: jobs.len(),
        levels: depth(root),
        root_box,
    })
}

/// Whether a tile has content to write (a mesh with vertices).
pub(crate) fn has_content(t: &Tile) -> bool {
    t.content.as_ref().is_some_and(|c| !c.vertices.is_empty())
}

/// The content file of a tile, relative to the tileset.
pub fn content_uri(address: [u32; 3]) -> String {
    format!("tiles/{}/{}_{}.glb", address[0], address[1], address[2])
}

fn named(path: &Path, e: io::Error) -> io::Error {
    io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

fn check_errors(t: &Tile, parent: f64) -> io::Result<()> {
    let e = t.geometric_error;
    if !(e.is_finite() && e >= 0.0) {
        return Err(invalid(format!(
            "tile {:?}: geometric error {e} is not a finite non-negative number",
            t.address
        )));
    }
    if e > parent {
        return Err(invalid(format!(
            "tile {:?}: geometric error {e} exceeds its parent's {parent}",
            t.address
        )));
    }
    t.children.iter().try_for_each(|c| check_errors(c, e))
}

fn collect<'t>(t: &'t Tile, out: &mut Vec<&'t Tile>) {
    if has_content(t) {
        out.push(t);
    }
    t.children.iter().for_each(|c| collect(c, out));
}

fn count(t: &Tile) -> usize {
    1 + t.children.iter().map(count).sum::<usize>()
}

fn depth(t: &Tile) -> usize {
    1 + t.children.iter().map(depth).max().unwrap_or(0)
}

fn write_content(dir: &Path, t: &Tile, opts: &TilesetOptions) -> io::Result<()> {
    let c = t.content.as_ref().expect("tiles with content");
    let b = Aabb::of(&c.vertices).unwrap_or_default();
    let name = format!(
        "{}-{}-{}-{}",
        opts.name, t.address[0], t.address[1], t.address[2]
    );
    let mesh = GlbMesh {
        name: &name,
        vertices: &c.vertices,
        triangles: &c.triangles,
        colours: (!c.colours.is_empty()).then_some(&c.colours[..]),
    };
    let glb = GlbOptions {
        name: &name,
        origin: b.centre(),
        extras: opts.extras.clone(),
    };
    let path = dir.join(content_uri(t.address));
    let mut out = Output::create(Some(&path)).map_err(|e| named(&path, e))?;
    write_glb(&mut out, &[mesh], &glb).map_err(|e| named(&path, e))?;
    out.commit().map_err(|e| named(&path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(z: f64) -> TileContent {
        TileContent {
            vertices: vec![[0.0, 0.0, z], [1.0, 0.0, z], [0.0, 1.0, z]],
            triangles: vec![[0, 1, 2]],
            colours: vec![],
        }
    }

    fn opts() -> TilesetOptions<'static> {
        TilesetOptions {
            transform: [0.0; 16],
            geometric_error: 10.0,
            name: "t",
            extras: Value::Null,
        }
    }

    #[test]
    fn a_child_with_more_error_than_its_parent_is_refused() {
        let child = Tile {
            address: [1, 0, 0],
            geometric_error: 2.0,
            content: Some(tri(0.0)),
            children: vec![],
        };
        let root = Tile {
            geometric_error: 1.0,
            content: Some(tri(0.0)),
            children: vec![child],
            ..Tile::default()
        };
        let dir = tempfile::tempdir().unwrap();
        let e = write_tileset(dir.path(), &root, &opts())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("[1, 0, 0]") && e.contains("exceeds its parent's 1"),
            "{e}"
        );
    }

    #[test]
    fn parent_boxes_enclose_their_childrens_content() {
        let child = Tile {
            address: [1, 0, 0],
            geometric_error: 0.0,
            content: Some(tri(50.0)),
            children: vec![],
        };
        let root = Tile {
            geometric_error: 1.0,
            content: Some(tri(0.0)),
            children: vec![child],
            ..Tile::default()
        };
        let dir = tempfile::tempdir().unwrap();
        let s = write_tileset(dir.path(), &root, &opts()).unwrap();
        assert_eq!(s.root_box.min[2], 0.0);
        assert_eq!(s.root_box.max[2], 50.0);
        let json: Value =
            serde_json::from_slice(&fs::read(dir.path().join("tileset.json")).unwrap()).unwrap();
        let bx = &json["root"]["boundingVolume"]["box"];
        assert_eq!(bx[2].as_f64().unwrap(), 25.0);
        assert!(bx[11].as_f64().unwrap() >= 25.0);
        assert_eq!(json["root"]["refine"], "REPLACE");
        assert!(dir.path().join("tiles/1/0_0.glb").exists());
    }
}
