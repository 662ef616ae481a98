//! Per-unit figures for `model.json` and the report.

use rayon::prelude::*;
use terramesh_core::volume::{cell_volume, VolumeMesh};

use crate::{Planar, Stack};

/// The figures of one unit.
///
/// ```
/// let s = terramesh_geology::UnitStats::default();
/// assert_eq!(s.cells, 0);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct UnitStats {
    /// The unit's name.
    pub name: String,
    /// The volume of its cells, m³.
    pub volume: f64,
    /// Its cells.
    pub cells: usize,
    /// The smallest thickness over the planar vertices, m.
    pub min_thickness: f64,
    /// The mean thickness over the planar vertices (each vertex counts once), m.
    pub mean_thickness: f64,
    /// The largest thickness over the planar vertices, m.
    pub max_thickness: f64,
    /// The planar area of the triangles where the unit has zero thickness at all three
    /// vertices (so no cell), m².
    pub pinched_area: f64,
}

/// The figures of every unit of `mesh`, built on `planar` from `stack`.
///
/// ```
/// use terramesh_geology::{unit_stats, volume_mesh, Layering, Planar, Stack};
/// let points = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
/// let planar = Planar::new(&points, &[[0, 1, 2], [1, 3, 2]])?;
/// // Unit b is absent over the second triangle.
/// let stack = Stack { surfaces: vec![vec![2.0; 4], vec![1.0, 0.0, 0.0, 0.0], vec![0.0; 4]] };
/// let mesh = volume_mesh(&planar, &stack, &Layering::new(vec!["a".into(), "b".into()]))?;
/// let stats = unit_stats(&planar, &stack, &mesh);
/// assert_eq!(stats[1].pinched_area, 0.5);
/// assert_eq!((stats[1].min_thickness, stats[1].max_thickness), (0.0, 1.0));
/// assert!((stats[0].volume + stats[1].volume - 1.0 * 2.0).abs() < 1e-12);
/// # Ok::<(), terramesh_geology::GeologyError>(())
/// ```
pub fn unit_stats(planar: &Planar, stack: &Stack, mesh: &VolumeMesh) -> Vec<UnitStats> {
    let units = stack.units();
    // Fixed chunks summed in order: the same volumes, to the last bit, on every run (a rayon
    // fold splits its work by what the threads steal, so its float sums vary).
    const CHUNK: usize = 8192;
    let partial: Vec<(Vec<f64>, Vec<usize>)> = mesh
        .cells
        .par_chunks(CHUNK)
        .zip(mesh.material.par_chunks(CHUNK))
        .map(|(cs, ms)| {
            let (mut v, mut n) = (vec![0.0; units], vec![0usize; units]);
            for (c, &m) in cs.iter().zip(ms) {
                if let Some(slot) = v.get_mut(m as usize) {
                    *slot += cell_volume(&mesh.points, c);
                    n[m as usize] += 1;
                }
            }
            (v, n)
        })
        .collect();
    let (mut volume, mut cells) = (vec![0.0; units], vec![0usize; units]);
    for (w, k) in partial {
        for u in 0..units {
            volume[u] += w[u];
            cells[u] += k[u];
        }
    }
    (0..units)
        .map(|u| {
            let t: Vec<f64> = (0..planar.points.len())
                .map(|v| stack.thickness(u, v))
                .collect();
            let pinched_area = (0..planar.triangles.len())
                .filter(|&i| planar.triangles[i].iter().all(|&v| t[v as usize] == 0.0))
                .map(|i| planar.area(i))
                .sum();
            let n = t.len().max(1) as f64;
            UnitStats {
                name: mesh.units.get(u).cloned().unwrap_or_default(),
                volume: volume[u],
                cells: cells[u],
                min_thickness: t.iter().copied().fold(f64::INFINITY, f64::min),
                mean_thickness: t.iter().sum::<f64>() / n,
                max_thickness: t.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                pinched_area,
            }
        })
        .collect()
}
