//! The layered background mesh (`MeshSettings::layered`, off by default): the columns' levels
//! follow the interfaces, so that inside a fault block every interface is already a set of
//! prism faces and the interface cut has work near the faults only.
//!
//! Unit u owns the level indices `S_u ..= S_u + N_u` in every column (`S_0 = 0`, the
//! terrain; `S_{u+1} = S_u + N_u`; the last level is the base), `N_u` the number of
//! sub-layers `max_cell_height` asks for where the unit is thickest. In a column, level `S_u`
//! lies on the unit's top (the terrain or interface u - 1 of the fault block of the column's
//! terrain node), level `S_u + N_u` on its base, and the unit's `n = ceil(t / max_cell_height)`
//! sub-layers of its thickness t there evenly between; its levels beyond `n` coincide with its
//! base, and where it pinches out (t within [`ON_SURFACE`]) all of them coincide with its top.
//! Coinciding levels are one node, and a prism with collapsed vertical edges is split by the
//! same lowest-global-index rule as the others, its zero-volume tetrahedra (a repeated node)
//! dropped: every quadrilateral with four distinct nodes is still split by the diagonal
//! through its lowest node, and a collapsed one is one triangle whichever diagonal is taken,
//! so neighbours still agree (the mesh stays conforming), and each of a prism's three
//! tetrahedra holds one whole vertical edge and has a volume in proportion to its length, so
//! a tetrahedron with four distinct nodes has a positive volume.

use rayon::prelude::*;

use crate::mesh::{checked_thickest, split_prism, State, BASE, SIDE, TOP};
use crate::{FaultError, FaultSet, InterfaceFn, MeshSettings, Terrain, ON_SURFACE};

/// The elevations of a column's unit boundaries, top to bottom: the terrain `h`, every
/// interface (`at(k)`, clamped between the boundary above and the base; one that is not a
/// number takes the boundary above: the interface cut refuses it, naming its place) and the
/// base. A run of boundaries within [`ON_SURFACE`] of its first takes that first's elevation
/// exactly (the base's where the run ends at the base, the terrain's where it starts there;
/// the base is never merged with the terrain).
pub(crate) fn boundaries(
    h: f64,
    base: f64,
    interfaces: usize,
    at: impl Fn(usize) -> f64,
) -> Vec<f64> {
    let mut z = Vec::with_capacity(interfaces + 2);
    z.push(h);
    for k in 0..interfaces {
        let above = z[k];
        let raw = at(k);
        z.push(if raw.is_finite() {
            raw.clamp(base, above)
        } else {
            above
        });
    }
    z.push(base);
    let last = z.len() - 1;
    let mut i = 0;
    while i <= last {
        let first = z[i];
        let mut j = i + 1;
        while j <= last && first - z[j] <= ON_SURFACE {
            j += 1;
        }
        if i == 0 && j > last {
            j = last;
        }
        let value = if j > last { base } else { first };
        for x in &mut z[i..j] {
            *x = value;
        }
        i = j;
    }
    z
}

/// The number of sub-layers of a unit `t` thick: 0 where it pinches out, else enough for
/// `max_cell_height`.
fn sublayers(t: f64, max_cell_height: f64) -> usize {
    if t <= 0.0 {
        0
    } else {
        ((t / max_cell_height).ceil() as usize).max(1)
    }
}

/// The layered background of the planar mesh `terrain` (see the module documentation), and
/// the number of nodes in the columns of its first `dsm_vertices` vertices (the DSM's own,
/// whose terrain nodes the quality pass keeps).
pub(crate) fn layered_background(
    terrain: &Terrain,
    s: &MeshSettings,
    faults: &FaultSet,
    interfaces: usize,
    height: InterfaceFn,
    dsm_vertices: usize,
) -> Result<(State, usize), FaultError> {
    checked_thickest(terrain, s)?;
    let n = terrain.points.len();
    let bounds: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|v| {
            let [x, y] = terrain.points[v];
            let h = terrain.heights[v];
            let block = faults.block_key([x, y, h]);
            boundaries(h, s.base, interfaces, |k| height(k, block, [x, y]))
        })
        .collect();
    let units = interfaces + 1;
    let mut most = vec![0usize; units];
    for z in &bounds {
        for u in 0..units {
            most[u] = most[u].max(sublayers(z[u] - z[u + 1], s.max_cell_height));
        }
    }
    let levels = 1 + most.iter().sum::<usize>();
    if levels < 2
        || (n * levels) as u64 >= u32::MAX as u64 / 4
        || terrain.triangles.len() * (levels - 1) * 3 > 400_000_000
    {
        return Err(FaultError::Setting {
            name: "max_cell_height".into(),
            value: s.max_cell_height,
            why: "makes too many cells for this terrain; raise it",
        });
    }
    // Every column's level elevations, top to bottom, non-increasing.
    let columns: Vec<Vec<f64>> = bounds
        .par_iter()
        .map(|z| {
            let mut zs = Vec::with_capacity(levels);
            zs.push(z[0]);
            for u in 0..units {
                let (top, bottom) = (z[u], z[u + 1]);
                let m = sublayers(top - bottom, s.max_cell_height);
                for i in 1..=most[u] {
                    let e = if i < m {
                        (top + (bottom - top) * (i as f64 / m as f64)).clamp(bottom, top)
                    } else {
                        bottom
                    };
                    let above = *zs.last().unwrap();
                    zs.push(e.min(above));
                }
            }
            zs
        })
        .collect();
    let mut side = vec![false; n];
    for &[a, b] in &terrain.outline {
        side[a as usize] = true;
        side[b as usize] = true;
    }
    // One node per distinct elevation of a column, columns in vertex order.
    let mut ids = vec![0u32; n * levels];
    let mut points = Vec::with_capacity(n * levels);
    let mut flags = Vec::with_capacity(n * levels);
    let mut background_nodes = 0;
    for (v, zs) in columns.iter().enumerate() {
        if v == dsm_vertices {
            background_nodes = points.len();
        }
        let [x, y] = terrain.points[v];
        let sideflag = if side[v] { SIDE } else { 0 };
        for (k, &z) in zs.iter().enumerate() {
            if k > 0 && z == zs[k - 1] {
                ids[v * levels + k] = ids[v * levels + k - 1];
                continue;
            }
            ids[v * levels + k] = points.len() as u32;
            points.push([x, y, z]);
            flags.push(if k == 0 { TOP } else { 0 } | sideflag);
        }
        // The column's last node is on the base (its elevation is the base's exactly).
        flags[ids[v * levels + levels - 1] as usize] |= BASE;
    }
    if dsm_vertices >= n {
        background_nodes = points.len();
    }
    let tets: Vec<[u32; 4]> = terrain
        .triangles
        .par_iter()
        .flat_map_iter(|tri| {
            let (points, ids) = (&points, &ids);
            (0..levels - 1).flat_map(move |k| {
                let top = tri.map(|v| ids[v as usize * levels + k]);
                let bottom = tri.map(|v| ids[v as usize * levels + k + 1]);
                let cells = if top == bottom {
                    Vec::new()
                } else {
                    split_prism(top, bottom, points).to_vec()
                };
                cells.into_iter().filter(|t| {
                    t[0] != t[1]
                        && t[0] != t[2]
                        && t[0] != t[3]
                        && t[1] != t[2]
                        && t[1] != t[3]
                        && t[2] != t[3]
                })
            })
        })
        .collect();
    if std::env::var_os("TERRAMESH_PASS_STATS").is_some() {
        // For profiling: per unit, its cells and those below 5 degrees (a cell's unit: its
        // lowest level's), its thickness over the columns.
        let mut unit_of_level = vec![0usize; levels];
        let mut k = 1;
        for (u, &nu) in most.iter().enumerate() {
            for _ in 0..nu {
                unit_of_level[k] = u;
                k += 1;
            }
        }
        let mut level_of = vec![0usize; points.len()];
        for v in 0..n {
            for k in 0..levels {
                let id = ids[v * levels + k] as usize;
                if ids[v * levels + k.saturating_sub(1)] as usize != id || k == 0 {
                    level_of[id] = k;
                }
            }
        }
        let mut count = vec![(0usize, 0usize); units];
        for t in &tets {
            let k = t.iter().map(|&v| level_of[v as usize]).max().unwrap();
            let u = unit_of_level[k];
            count[u].0 += 1;
            if crate::quality::min_dihedral(t.map(|v| points[v as usize])) < 5.0 {
                count[u].1 += 1;
            }
        }
        let thick: Vec<(f64, f64)> = (0..units)
            .map(|u| {
                let t = bounds.iter().map(|z| z[u] - z[u + 1]);
                (t.clone().fold(f64::MAX, f64::min), t.fold(0.0, f64::max))
            })
            .collect();
        eprintln!("layered background: {levels} levels, sub-layers {most:?}; per unit (cells, below 5): {count:?}; thickness (min, max): {thick:?}; median planar edge {:.1}", terrain.median_edge());
    }
    Ok((State::background(points, flags, tets), background_nodes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundaries_merge_runs_within_on_surface() {
        // A unit pinching out (interfaces 0 and 1 within 1e-7), one above the terrain
        // (clamped to it), one below the base (clamped to it), one not a number.
        let at = |k: usize| [100.0, 60.0, 60.0 - 1e-7, 120.0, -5.0, f64::NAN][k];
        let z = boundaries(90.0, 0.0, 6, at);
        assert_eq!(z, vec![90.0, 90.0, 60.0, 60.0, 60.0, 0.0, 0.0, 0.0]);
        // The terrain is never merged with the base.
        let z = boundaries(1e-7, 0.0, 1, |_| 0.5e-7);
        assert_eq!(z, vec![1e-7, 1e-7, 0.0]);
        assert_eq!(sublayers(0.0, 10.0), 0);
        assert_eq!(sublayers(1e-3, 10.0), 1);
        assert_eq!(sublayers(25.0, 10.0), 3);
    }
}
