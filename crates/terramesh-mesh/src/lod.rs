//! Level-of-detail tree of a surface mesh for 3D Tiles: a quadtree of tiles whose leaves cut
//! the full mesh, and whose coarser levels are terrain-adaptive meshes of the same region at
//! increasing error tolerances, each tile carrying its measured error against the full mesh.
//!
//! It lives here, beside [`adaptive_mesh`], because it is meshing and measuring with no file
//! format in it: the facade turns the tiles' vertices into the tileset's frame and
//! `terramesh_io::export::tiles3d` writes them.

use rayon::prelude::*;
use terramesh_core::geometry::Region;

use crate::adaptive::{adaptive_mesh, AdaptiveSettings};
use crate::locate::SurfaceLocator;
use crate::{Mesh, MeshError, DEFAULT_MIN_ANGLE};

/// Settings of [`lod_tree`].
#[derive(Debug, Clone, PartialEq)]
pub struct LodSettings {
    /// Levels of the tree, the root's and the leaves' included (at least 2). `None`: enough
    /// that each leaf holds about `leaf_triangles` of the full mesh, and at least 3.
    pub levels: Option<usize>,
    /// Triangles a leaf aims at when `levels` is `None`. Default 50,000.
    pub leaf_triangles: usize,
    /// Tolerance of the root's adaptive mesh, metres. `None`: a twentieth of the surface's
    /// height range.
    pub root_error: Option<f64>,
    /// Each finer level's tolerance is its parent's times this (in `(0, 1)`). Default 0.25:
    /// the error of a linear surface falls about as the inverse of its triangle count, and
    /// each level has four times the tiles of its parent.
    pub ratio: f64,
    /// Planar minimum angle of the adaptive meshes, degrees. Default [`DEFAULT_MIN_ANGLE`].
    pub min_angle: f64,
}

impl Default for LodSettings {
    fn default() -> Self {
        LodSettings {
            levels: None,
            leaf_triangles: 50_000,
            root_error: None,
            ratio: 0.25,
            min_angle: DEFAULT_MIN_ANGLE,
        }
    }
}

/// A tile of [`lod_tree`]: level `address[0]`, column `address[1]` and row `address[2]` of
/// that level's `2^level x 2^level` grid over the full mesh's bounding box.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LodTile {
    /// Level, column, row.
    pub address: [u32; 3],
    /// Largest `|tile surface - full surface|` over the tile (metres), raised to its
    /// children's largest if that is more, so that errors never grow towards the leaves; 0 at
    /// the leaves.
    pub error: f64,
    /// The error as measured, before raising.
    pub measured_error: f64,
    /// Absolute vertices `[x, y, z]`.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// Finer tiles replacing this one.
    pub children: Vec<LodTile>,
}

/// One level of [`lod_tree`]: its tolerance and mesh size.
#[derive(Debug, Clone, PartialEq)]
pub struct LodLevel {
    /// Tolerance given to the adaptive mesher (`None` for the leaves: the full mesh).
    pub tolerance: Option<f64>,
    /// Vertices and triangles of the level's mesh.
    pub vertices: usize,
    /// Triangles of the level's mesh.
    pub triangles: usize,
    /// Largest measured error of the level's tiles.
    pub max_error: f64,
}

/// Builds the tree. A tile's triangles are those of its level's mesh whose centroid lies in
/// its cell, so the tiles of one level join without cracks. The error of a tile is measured
/// both ways: the full surface at the tile's vertices, edge midpoints and centres, and the
/// tile's surface at every vertex of the full mesh that falls on one of the tile's triangles.
/// A level whose adaptive mesh would need more vertices than the full mesh uses the full
/// mesh (error 0).
///
/// # Errors
/// As [`adaptive_mesh`], and [`MeshError::BadParameter`] for settings out of range.
///
/// ```
/// use terramesh_core::geometry::Region;
/// use terramesh_mesh::{adaptive_mesh, lod_tree, AdaptiveSettings, LodSettings};
/// let r = Region::from_ring(vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]]);
/// let hill = |x: f64, y: f64| 20.0 * (-((x - 50.0).powi(2) + (y - 40.0).powi(2)) / 800.0).exp();
/// let (dsm, z, _) = adaptive_mesh(&r, &AdaptiveSettings::new(0.05), &hill)?;
/// let (root, levels) = lod_tree(&r, &dsm, &z, &LodSettings { levels: Some(3), ..Default::default() })?;
/// assert_eq!(levels.len(), 3);
/// assert!(root.error > 0.0 && root.children.iter().all(|c| c.error <= root.error));
/// # Ok::<(), terramesh_mesh::MeshError>(())
/// ```
pub fn lod_tree(
    region: &Region,
    dsm: &Mesh,
    z: &[f64],
    settings: &LodSettings,
) -> Result<(LodTile, Vec<LodLevel>), MeshError> {
    let bad = |name: &'static str, value: f64, why: &str| MeshError::BadParameter {
        name,
        value,
        why: why.into(),
    };
    if !(settings.ratio > 0.0 && settings.ratio < 1.0) {
        return Err(bad("ratio", settings.ratio, "must be in (0, 1)"));
    }
    if z.len() != dsm.points.len() {
        return Err(bad("z", z.len() as f64, "needs one height per vertex"));
    }
    let (zmin, zmax) = z
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let root_error = settings
        .root_error
        .unwrap_or(((zmax - zmin) / 20.0).max(1e-3));
    if !(root_error.is_finite() && root_error > 0.0) {
        return Err(bad("root_error", root_error, "must be positive"));
    }
    let levels = match settings.levels {
        Some(l) if l >= 2 => l,
        Some(l) => return Err(bad("levels", l as f64, "must be at least 2")),
        None => {
            let tiles = dsm.triangles.len() as f64 / settings.leaf_triangles.max(1) as f64;
            ((tiles.max(1.0).ln() / 4f64.ln()).ceil() as usize + 1).max(3)
        }
    };
    let (lo, hi) = bbox(dsm);
    let full = SurfaceLocator::new(dsm, z);
    // Every level but the leaves: an adaptive mesh at its tolerance, in parallel.
    let coarse: Vec<Option<(Mesh, Vec<f64>, f64)>> = (0..levels - 1)
        .into_par_iter()
        .map(|l| {
            let tol = root_error * settings.ratio.powi(l as i32);
            let s = AdaptiveSettings {
                min_angle: settings.min_angle,
                max_vertices: dsm.points.len(),
                improve_3d: false,
                ..AdaptiveSettings::new(tol)
            };
            let f = |x: f64, y: f64| full.height_or_nearest(x, y);
            match adaptive_mesh(region, &s, &f) {
                Ok((m, mz, _)) => Ok(Some((m, mz, tol))),
                Err(MeshError::Incomplete { .. }) => Ok(None),
                Err(e) => Err(e),
            }
        })
        .collect::<Result<_, _>>()?;
    let mut level_tiles: Vec<Vec<LodTile>> = Vec::with_capacity(levels);
    let mut summary = Vec::with_capacity(levels);
    for (l, c) in coarse.iter().enumerate() {
        let (m, mz, tol) = match c {
            Some((m, mz, tol)) => (m, &mz[..], Some(*tol)),
            None => (dsm, z, None),
        };
        let errs = if c.is_some() {
            triangle_errors(m, mz, dsm, z, &full)
        } else {
            vec![0.0; m.triangles.len()]
        };
        let tiles = cut(m, mz, &errs, l as u32, lo, hi);
        summary.push(LodLevel {
            tolerance: tol,
            vertices: m.points.len(),
            triangles: m.triangles.len(),
            max_error: errs.iter().copied().fold(0.0, f64::max),
        });
        level_tiles.push(tiles);
    }
    let leaves = cut(
        dsm,
        z,
        &vec![0.0; dsm.triangles.len()],
        levels as u32 - 1,
        lo,
        hi,
    );
    summary.push(LodLevel {
        tolerance: None,
        vertices: dsm.points.len(),
        triangles: dsm.triangles.len(),
        max_error: 0.0,
    });
    level_tiles.push(leaves);
    // Link bottom-up: each tile's children are the next level's tiles in its four cells.
    let mut below = level_tiles.pop().unwrap_or_default();
    while let Some(mut tiles) = level_tiles.pop() {
        for t in &mut tiles {
            let [_, x, y] = t.address;
            let (kids, rest): (Vec<LodTile>, Vec<LodTile>) = below
                .into_iter()
                .partition(|c| c.address[1] / 2 == x && c.address[2] / 2 == y);
            below = rest;
            t.children = kids;
            t.error = t
                .children
                .iter()
                .map(|c| c.error)
                .fold(t.measured_error, f64::max);
        }
        // Cells of this level without a triangle: an empty tile grouping the children.
        let mut orphans: Vec<([u32; 2], Vec<LodTile>)> = Vec::new();
        for c in below {
            let cell = [c.address[1] / 2, c.address[2] / 2];
            match orphans.iter_mut().find(|o| o.0 == cell) {
                Some(o) => o.1.push(c),
                None => orphans.push((cell, vec![c])),
            }
        }
        let level = tiles.first().map_or(0, |t| t.address[0]);
        for (cell, kids) in orphans {
            let error = kids.iter().map(|c| c.error).fold(0.0, f64::max);
            tiles.push(LodTile {
                address: [level, cell[0], cell[1]],
                error,
                children: kids,
                ..LodTile::default()
            });
        }
        tiles.sort_by_key(|t| (t.address[2], t.address[1]));
        below = tiles;
    }
    let root = below.into_iter().next().unwrap_or_default();
    Ok((root, summary))
}

fn bbox(m: &Mesh) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for i in 0..m.points.len() {
        let p = m.absolute(i);
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Per triangle of the coarse mesh `m`, the largest `|m - full|` at its vertices, edge
/// midpoints and centre, and at the full mesh's vertices that fall on it.
fn triangle_errors(m: &Mesh, mz: &[f64], dsm: &Mesh, z: &[f64], full: &SurfaceLocator) -> Vec<f64> {
    let o = m.origin;
    let at = |p: [f64; 2], lin: f64| {
        full.height(p[0] + o[0], p[1] + o[1])
            .map_or(0.0, |f| (f - lin).abs())
    };
    let mut errs: Vec<f64> = m
        .triangles
        .par_iter()
        .map(|t| {
            let p = t.map(|i| m.points[i as usize]);
            let h = t.map(|i| mz[i as usize]);
            let mut e = 0.0f64;
            for k in 0..3 {
                e = e.max(at(p[k], h[k]));
                let (a, b) = (k, (k + 1) % 3);
                let mid = [0.5 * (p[a][0] + p[b][0]), 0.5 * (p[a][1] + p[b][1])];
                e = e.max(at(mid, 0.5 * (h[a] + h[b])));
            }
            let c = [
                (p[0][0] + p[1][0] + p[2][0]) / 3.0,
                (p[0][1] + p[1][1] + p[2][1]) / 3.0,
            ];
            e.max(at(c, (h[0] + h[1] + h[2]) / 3.0))
        })
        .collect();
    // The full mesh's vertices, on the coarse surface.
    let coarse = SurfaceLocator::new(m, mz);
    let hits: Vec<(usize, f64)> = (0..dsm.points.len())
        .into_par_iter()
        .filter_map(|i| {
            let q = dsm.absolute(i);
            coarse
                .locate(q[0], q[1])
                .map(|(t, h)| (t, (h - z[i]).abs()))
        })
        .collect();
    for (t, e) in hits {
        errs[t] = errs[t].max(e);
    }
    errs
}

/// Splits a level's mesh into its `2^level` x `2^level` cells by triangle centroid.
fn cut(m: &Mesh, z: &[f64], errs: &[f64], level: u32, lo: [f64; 2], hi: [f64; 2]) -> Vec<LodTile> {
    let n = 1u32 << level;
    let size = [
        ((hi[0] - lo[0]) / n as f64).max(f64::MIN_POSITIVE),
        ((hi[1] - lo[1]) / n as f64).max(f64::MIN_POSITIVE),
    ];
    let cell_of = |t: &[u32; 3]| {
        let c = [0, 1].map(|k| {
            let s: f64 = t.iter().map(|&i| m.points[i as usize][k]).sum::<f64>() / 3.0;
            let v = ((s + m.origin[k] - lo[k]) / size[k]).floor();
            (v.max(0.0) as u32).min(n - 1)
        });
        (c[1] * n + c[0]) as usize
    };
    let mut by_cell: Vec<Vec<usize>> = vec![Vec::new(); (n * n) as usize];
    for (k, t) in m.triangles.iter().enumerate() {
        by_cell[cell_of(t)].push(k);
    }
    by_cell
        .into_par_iter()
        .enumerate()
        .filter(|(_, tris)| !tris.is_empty())
        .map(|(cell, tris)| {
            let mut map = vec![u32::MAX; m.points.len()];
            let mut vertices = Vec::new();
            let mut triangles = Vec::with_capacity(tris.len());
            let mut error = 0.0f64;
            for &k in &tris {
                error = error.max(errs[k]);
                triangles.push(m.triangles[k].map(|i| {
                    let slot = &mut map[i as usize];
                    if *slot == u32::MAX {
                        let p = m.absolute(i as usize);
                        vertices.push([p[0], p[1], z[i as usize]]);
                        *slot = vertices.len() as u32 - 1;
                    }
                    *slot
                }));
            }
            let cell = cell as u32;
            LodTile {
                address: [level, cell % n, cell / n],
                error,
                measured_error: error,
                vertices,
                triangles,
                children: Vec::new(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hill_dsm() -> (Region, Mesh, Vec<f64>) {
        let r = Region::from_ring(vec![[0.0, 0.0], [120.0, 0.0], [120.0, 80.0], [0.0, 80.0]]);
        let hill = |x: f64, y: f64| {
            10.0 * (-((x - 40.0).powi(2) + (y - 30.0).powi(2)) / 400.0).exp() + 0.05 * x
        };
        let (m, z, _) = adaptive_mesh(&r, &AdaptiveSettings::new(0.02), &hill).unwrap();
        (r, m, z)
    }

    fn tiles(t: &LodTile) -> Vec<&LodTile> {
        let mut v = vec![t];
        for c in &t.children {
            v.extend(tiles(c));
        }
        v
    }

    /// The height of a mesh's surface at a local point by trying every triangle.
    fn brute(tris: &[[u32; 3]], p: &[[f64; 3]], q: [f64; 2]) -> Option<f64> {
        tris.iter().find_map(|t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
            let l1 = ((q[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (q[1] - a[1])) / det;
            let l2 = ((b[0] - a[0]) * (q[1] - a[1]) - (q[0] - a[0]) * (b[1] - a[1])) / det;
            let l0 = 1.0 - l1 - l2;
            (l0.min(l1).min(l2) >= -1e-9).then(|| l0 * a[2] + l1 * b[2] + l2 * c[2])
        })
    }

    #[test]
    fn leaves_cut_the_full_mesh_and_errors_never_grow_towards_them() {
        let (r, m, z) = hill_dsm();
        let s = LodSettings {
            levels: Some(3),
            ..LodSettings::default()
        };
        let (root, levels) = lod_tree(&r, &m, &z, &s).unwrap();
        assert_eq!(levels.len(), 3);
        assert!(levels[0].triangles < levels[1].triangles);
        assert!(levels[1].triangles < levels[2].triangles);
        let all = tiles(&root);
        let leaves: Vec<_> = all.iter().filter(|t| t.children.is_empty()).collect();
        assert!(leaves.iter().all(|t| t.address[0] == 2 && t.error == 0.0));
        let n: usize = leaves.iter().map(|t| t.triangles.len()).sum();
        assert_eq!(n, m.triangles.len());
        for t in &all {
            for c in &t.children {
                assert!(
                    c.error <= t.error,
                    "{:?} {} > {}",
                    c.address,
                    c.error,
                    t.error
                );
                assert_eq!(c.address[0], t.address[0] + 1);
                assert_eq!(
                    [c.address[1] / 2, c.address[2] / 2],
                    [t.address[1], t.address[2]]
                );
            }
            assert!(t.measured_error <= t.error);
        }
    }

    #[test]
    fn the_root_error_is_the_largest_difference_found_by_brute_force() {
        let (r, m, z) = hill_dsm();
        let s = LodSettings {
            levels: Some(2),
            ..LodSettings::default()
        };
        let (root, _) = lod_tree(&r, &m, &z, &s).unwrap();
        let full: Vec<[f64; 3]> = (0..m.points.len())
            .map(|i| {
                let p = m.absolute(i);
                [p[0], p[1], z[i]]
            })
            .collect();
        let (rv, rt) = (&root.vertices, &root.triangles);
        let mut want = 0.0f64;
        // The full mesh at the root's vertices, edge midpoints and centres.
        for t in rt {
            let p = t.map(|i| rv[i as usize]);
            let mut probes: Vec<[f64; 3]> = p.to_vec();
            for k in 0..3 {
                let (a, b) = (p[k], p[(k + 1) % 3]);
                probes.push([0, 1, 2].map(|j| 0.5 * (a[j] + b[j])));
            }
            probes.push([0, 1, 2].map(|j| (p[0][j] + p[1][j] + p[2][j]) / 3.0));
            for q in probes {
                let f = brute(&m.triangles, &full, [q[0], q[1]]).unwrap();
                want = want.max((f - q[2]).abs());
            }
        }
        // The root at the full mesh's vertices.
        for v in &full {
            let h = brute(rt, rv, [v[0], v[1]]).unwrap();
            want = want.max((h - v[2]).abs());
        }
        assert!(want > 0.1, "a coarse root differs from the DSM: {want}");
        assert!(
            (root.measured_error - want).abs() < 1e-9,
            "{} vs {want}",
            root.measured_error
        );
    }
}
