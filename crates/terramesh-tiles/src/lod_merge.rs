//! The merged DSM's folder exports, `3dtiles/` (Cesium 3D Tiles 1.1) and `terrain/` (Cesium
//! quantized-mesh terrain), written by the one-piece build's own writers on the merged mesh
//! (`terramesh::gltf::write_dsm_tileset`, `terramesh::build::terrain::write`), so each file is
//! byte for byte what a one-piece build writes for that mesh.
//!
//! Neither tree depends on how the region was cut into tiles: the 3D Tiles tree is a quadtree
//! over the whole mesh's bounding box whose leaves cut the mesh and whose coarser levels are
//! terrain-adaptive meshes of the region sampled from it (`terramesh_mesh::lod_tree`); the
//! terrain pyramid samples the surface at each terrain tile's lattice. Both read the mesh
//! anywhere, so they are not streamed: the merge reads the merged mesh from its mapped
//! scratch files ([`super::exports`]) and the writer holds what it needs of it (the terrain's
//! from the mapped positions and triangles; the 3D Tiles' planar mesh copied into memory, as
//! the tree's writer needs a [`terramesh_mesh::Mesh`]). What they hold is bounded by a
//! measured cost per vertex ([`TILESET_BYTES_PER_VERTEX`], [`TERRAIN_BYTES_PER_VERTEX`]),
//! checked against the memory limit (`TERRAMESH_MAX_MEMORY`) before anything is allocated: a
//! mesh past it is not merged in that format, and `merge.json`'s `not_merged` says why.

use std::path::{Path, PathBuf};

use terramesh::georef::Georef;
use terramesh_core::geometry::Region;
use terramesh_core::limits::Estimate;
use terramesh_mesh::{triangle_quality, LodSettings, Mesh};

use crate::error::Result;

/// Peak memory of the 3D Tiles writer on the merged mesh, bytes per vertex: its planar mesh
/// and absolute vertices, the point locator, the adaptive meshes of the coarser levels, the
/// leaves (a copy of the mesh cut into cells, each cell's vertex map of 4 bytes a vertex of the
/// mesh on every thread at once) and their conversion to the tileset's frame. Measured on the
/// Fort Worth plan (1,029,671 vertices, 2 threads): 244 bytes a vertex of peak resident size
/// over a merge without it (docs/scaling.md); about twice that, for the margin.
pub const TILESET_BYTES_PER_VERTEX: f64 = 500.0;

/// Peak memory of the terrain writer on the merged mesh, bytes per vertex: the ellipsoidal
/// positions, the indexed surface's copy of them and of the triangles, its grid index, and the
/// pyramid's tiles (65 x 65 heights and normals each, as many as the region has at the mesh's
/// resolution). Measured as [`TILESET_BYTES_PER_VERTEX`]: 228 bytes a vertex; about twice that.
pub const TERRAIN_BYTES_PER_VERTEX: f64 = 450.0;

/// The merged mesh, as the scratch files hold it, and the labels of the folder exports.
pub(crate) struct FolderInput<'a> {
    /// Absolute planar positions, metres of the plan's CRS.
    pub xy: &'a [[f64; 2]],
    /// The DSM's elevation per vertex.
    pub z: &'a [f64],
    /// Triangles.
    pub triangles: &'a [[u32; 3]],
    /// WGS-84 longitude, latitude and the elevation per vertex (terrain; empty otherwise).
    pub geo: &'a [[f64; 3]],
    /// The planar mesh's origin (the tile grid's south-west corner): its vertices are
    /// relative to it, as a one-piece build's mesh's are to its own origin.
    pub origin: [f64; 2],
    /// The region's outline, as the plan records it (the coarser levels of the 3D Tiles tree
    /// are adaptive meshes of it).
    pub region: &'a [[f64; 2]],
    /// The surface's title.
    pub title: &'a str,
    /// Where the region lies on the Earth, as the one-piece build places it.
    pub georef: &'a Georef,
}

/// Why a folder export was not written: a message for `not_merged`.
pub(crate) type NotWritten = String;

/// The merged mesh as a planar [`Mesh`] around `origin` (its vertices relative to it).
pub(crate) fn planar_mesh(xy: &[[f64; 2]], triangles: &[[u32; 3]], origin: [f64; 2]) -> Mesh {
    Mesh {
        origin,
        points: xy
            .iter()
            .map(|p| [p[0] - origin[0], p[1] - origin[1]])
            .collect(),
        triangles: triangles.to_vec(),
        constraint_edges: Vec::new(),
    }
}

/// The mean edge length of the planar mesh around `origin`, each triangle's three edges in
/// order: [`terramesh_mesh::Quality::planar`]'s `edge.mean` (the terrain's resolution in a
/// one-piece build), computed the same way from the mapped files without copying the mesh.
pub(crate) fn mean_edge(xy: &[[f64; 2]], triangles: &[[u32; 3]], origin: [f64; 2]) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for t in triangles {
        let q = triangle_quality(t.map(|i| {
            let p = xy[i as usize];
            [p[0] - origin[0], p[1] - origin[1], 0.0]
        }));
        for e in q.edges {
            sum += e;
            n += 1;
        }
    }
    match n {
        0 => 0.0,
        n => sum / n as f64,
    }
}

/// The estimate of a folder writer's memory, checked against the memory limit: the message
/// for `not_merged` when it is past it.
fn fits(what: &str, vertices: usize, bytes_each: f64) -> std::result::Result<(), NotWritten> {
    Estimate::new("vertices", vertices as f64, bytes_each)
        .check()
        .map(|_| ())
        .map_err(|e| {
            format!(
                "{what} holds the whole merged mesh: {e}; not merged (raise the limit, view the \
                 merged dsm.vtu, or build a part of the region in one piece)",
                e = e.describe(&|s| s.to_string())
            )
        })
}

/// Writes `out/3dtiles` (`tileset.json` and its GLB contents) with the one-piece writer on
/// the merged mesh; returns the path of `tileset.json`, or why it was not written.
pub(crate) fn write_tileset(
    out: &Path,
    input: &FolderInput,
) -> Result<std::result::Result<PathBuf, NotWritten>> {
    if let Err(why) = fits(
        "the 3D Tiles level-of-detail tree",
        input.z.len(),
        TILESET_BYTES_PER_VERTEX,
    ) {
        return Ok(Err(why));
    }
    let mesh = planar_mesh(input.xy, input.triangles, input.origin);
    let region = Region::from_ring(input.region.to_vec());
    let dsm = terramesh::gltf::Dsm {
        mesh: &mesh,
        z: input.z,
        georef: input.georef,
        title: input.title,
    };
    let dir = out.join("3dtiles");
    terramesh::gltf::write_dsm_tileset(&dir, &region, &dsm, &LodSettings::default())?;
    Ok(Ok(dir.join("tileset.json")))
}

/// Writes `out/terrain` (`layer.json` and the `.terrain` pyramid) with the one-piece writer
/// on the merged mesh, down to the level of its mean edge length; returns the path of
/// `layer.json`, or why it was not written.
pub(crate) fn write_terrain(
    out: &Path,
    input: &FolderInput,
) -> Result<std::result::Result<PathBuf, NotWritten>> {
    if let Err(why) = fits(
        "the terrain pyramid",
        input.z.len(),
        TERRAIN_BYTES_PER_VERTEX,
    ) {
        return Ok(Err(why));
    }
    let res = mean_edge(input.xy, input.triangles, input.origin);
    let layer =
        terramesh::build::terrain::write(out, input.geo, input.triangles, res, input.title)?;
    Ok(Ok(layer))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mean_edge_is_the_planar_qualitys() {
        let xy = [
            [500_000.25, 5_400_000.5],
            [500_010.0, 5_400_000.0],
            [500_003.0, 5_400_011.75],
            [500_013.5, 5_400_009.0],
        ];
        let tris = [[0, 1, 2], [1, 3, 2]];
        let origin = [499_990.0, 5_399_990.0];
        let mesh = planar_mesh(&xy, &tris, origin);
        let want = terramesh_mesh::Quality::planar(&mesh).edge.mean;
        assert_eq!(mean_edge(&xy, &tris, origin).to_bits(), want.to_bits());
        assert_eq!(mesh.absolute(3), [500_013.5, 5_400_009.0]);
    }

    #[test]
    fn a_mesh_past_the_memory_limit_is_named_not_written() {
        let why = fits("the terrain pyramid", usize::MAX / 2, 1e6).unwrap_err();
        assert!(
            why.contains("the terrain pyramid") && why.contains("memory limit"),
            "{why}"
        );
        assert!(fits("the terrain pyramid", 1000, TERRAIN_BYTES_PER_VERTEX).is_ok());
    }
}
