//! The scene of the 3D viewer in `report.html` (`terramesh_report::viewer`): the DSM surface
//! coloured by elevation, kriging standard deviation or UK minus IDW; the sealed solid's sides
//! and base; the samples as points; with `[geology]`, the units (capped where the
//! cross-section cuts them) and the boreholes (traces and collars) as further layers.
//!
//! A DSM of more than [`VIEWER_VERTICES`] vertices is shown decimated: the adaptive mesher
//! (`terramesh_mesh::adaptive_mesh`) meshes the region again against the DSM itself (a
//! triangle locator interpolating the full mesh), at the smallest tolerance, doubling from
//! 1/2000 of the relief, that stays within the budget; the fields are interpolated from the
//! full mesh at the new vertices, and the viewer says so.

use terramesh_core::geometry::Region;
use terramesh_core::solid::extrude;
use terramesh_mesh::{adaptive_mesh, AdaptiveSettings, Fallible, MeshError};
use terramesh_report::pictures::ColourMap;
use terramesh_report::viewer::{compact, Field, Geometry, Layer, Scene};

use super::stages::{Interpolated, Meshed, Samples};
use crate::error::{Context, Result};
use crate::geology::stage::ModelBuilt;

/// Most DSM vertices the viewer shows; larger surfaces are decimated to fit.
pub const VIEWER_VERTICES: usize = 200_000;
/// Most samples the viewer shows as points; more are thinned evenly.
pub const VIEWER_SAMPLES: usize = 200_000;

/// Most vertices of the geological units' shells together (each unit's top and bottom copy
/// the planar vertices): a model whose planar mesh needs more is shown on a decimated one.
pub const VIEWER_MODEL_VERTICES: usize = 400_000;

/// The viewer's scene of a build, with the solid extruded to `base`, and the geological
/// model's units (one toggle each) and borehole contacts when the project has `[geology]`
/// (then the solid, which the units fill, starts hidden).
pub fn scene(
    s: &Samples,
    m: &Meshed,
    it: &Interpolated,
    base: f64,
    geo: Option<&ModelBuilt>,
) -> Result<Scene> {
    let mesh = &m.mesh;
    let abs: Vec<[f64; 3]> = (0..mesh.points.len())
        .map(|i| {
            let q = mesh.absolute(i);
            [q[0], q[1], it.dsm[i]]
        })
        .collect();
    let diff: Vec<f64> = it.uk.iter().zip(&it.idw).map(|(a, b)| a - b).collect();
    // The DSM, and the kriging's fields when the samples were kriged.
    let mut fields: Vec<&[f64]> = vec![&it.dsm];
    if it.kriged() {
        fields.extend([&it.uk_std[..], &diff[..]]);
    }
    let own = fields.len();
    // The unit tops below the first and the base ride along as fields of the planar mesh.
    let surfaces = geo.map_or(&[][..], |g| &g.model.stack.surfaces[..]);
    fields.extend(surfaces.iter().skip(1).map(|v| &v[..]));
    let budget = match surfaces.len() {
        0 => VIEWER_VERTICES,
        n => VIEWER_VERTICES.min(VIEWER_MODEL_VERTICES / (2 * n - 1)),
    };
    let mut notes = Vec::new();
    let (positions, triangles, mut values) = if abs.len() > budget {
        let d = decimate(&s.region.projected, &abs, &mesh.triangles, &fields, budget)?;
        notes.push(format!(
            "The DSM has {} vertices; this view shows a decimated mesh of {} vertices and {} \
             triangles (the adaptive mesher within {:.3} m of the DSM{}). The exports and the \
             pictures use the full mesh.",
            abs.len(),
            d.positions.len(),
            d.triangles.len(),
            d.tolerance,
            if geo.is_some() {
                "; the units' surfaces interpolated linearly from the model's at its vertices"
            } else {
                ""
            }
        ));
        (d.positions, d.triangles, d.values)
    } else {
        let values = fields.iter().map(|f| f.to_vec()).collect();
        (abs, mesh.triangles.clone(), values)
    };
    let model_layers = match geo {
        Some(g) => {
            let mut stack = vec![positions.iter().map(|p| p[2]).collect::<Vec<f64>>()];
            stack.extend(values.drain(own..));
            let (layers, note) =
                crate::geology::web::viewer_layers(g, &positions, &triangles, &stack);
            notes.push(note);
            layers
        }
        None => Vec::new(),
    };
    let mut values = values.into_iter();
    let elevation = values.next().unwrap_or_default();
    let field = |key: &str, label: String, colours, values| Field {
        key: key.into(),
        label,
        unit: "m".into(),
        colours,
        values,
    };
    let solid = extrude(&positions, &triangles, base).context("export.base_elevation")?;
    let (solid_v, solid_t) = compact(&solid.vertices, &solid.triangles[solid.top_triangles..]);
    let surface = Layer {
        name: "DSM surface".into(),
        fields: {
            let mut f = vec![field(
                "elevation",
                format!("elevation ({})", it.dsm_method),
                ColourMap::Terrain,
                elevation,
            )];
            if let (Some(std), Some(diff)) = (values.next(), values.next()) {
                f.push(field(
                    "kriging_std",
                    "kriging standard deviation".into(),
                    ColourMap::Viridis,
                    std,
                ));
                f.push(field(
                    "uk_minus_idw",
                    "UK minus IDW".into(),
                    ColourMap::Diverging,
                    diff,
                ));
            }
            f
        },
        positions,
        geometry: Geometry::Triangles(triangles),
        colour: [200, 200, 200],
        visible: true,
        pickable: true,
        clipped: true,
        closed: false,
        vertex_colours: None,
    };
    let solid = Layer {
        name: format!("solid sides and base ({base:.1} m)"),
        positions: solid_v,
        geometry: Geometry::Triangles(solid_t),
        fields: Vec::new(),
        colour: [125, 135, 165],
        visible: geo.is_none(),
        pickable: false,
        clipped: true,
        closed: false,
        vertex_colours: None,
    };
    let stride = s.xyz.len().div_ceil(VIEWER_SAMPLES).max(1);
    let pts: Vec<[f64; 3]> = s.xyz.iter().step_by(stride).copied().collect();
    if stride > 1 {
        notes.push(format!(
            "Every {stride}th of the {} samples is shown.",
            s.xyz.len()
        ));
    }
    let samples = Layer {
        name: format!("samples ({})", pts.len()),
        fields: vec![field(
            "elevation",
            "elevation".into(),
            ColourMap::Terrain,
            pts.iter().map(|p| p[2]).collect(),
        )],
        positions: pts,
        geometry: Geometry::Points,
        colour: [40, 40, 40],
        visible: false,
        pickable: false,
        clipped: true,
        closed: false,
        vertex_colours: None,
    };
    Ok(Scene {
        crs: s.crs_name(),
        heights: if s.zone.is_some() {
            "above the EGM96 geoid (EPSG:5773)".into()
        } else {
            "as the project's inputs give it (their vertical datum, not converted)".into()
        },
        note: (!notes.is_empty()).then(|| notes.join(" ")),
        layers: [vec![surface, solid, samples], model_layers].concat(),
    })
}

/// A decimated surface: positions (with z), triangles, the fields at its vertices.
pub(super) struct Decimated {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub values: Vec<Vec<f64>>,
    /// The adaptive mesher's tolerance against the full surface, metres.
    pub tolerance: f64,
}

/// Meshes `region` again, adaptively against the surface `abs`/`tris`, with at most `budget`
/// vertices; interpolates `fields` (one value per vertex of `abs`) at the new vertices.
pub(super) fn decimate(
    region: &Region,
    abs: &[[f64; 3]],
    tris: &[[u32; 3]],
    fields: &[&[f64]],
    budget: usize,
) -> Result<Decimated> {
    let locator = Locator::new(abs, tris);
    let z: Vec<f64> = abs.iter().map(|p| p[2]).collect();
    let (lo, hi) = z
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let height =
        Fallible(|x: f64, y: f64| locator.interpolate(x, y, &z).ok_or("outside the DSM mesh"));
    let mut tolerance = ((hi - lo) / 2000.0).max(1e-3);
    let mesh = loop {
        let mut settings = AdaptiveSettings::new(tolerance);
        settings.max_vertices = budget;
        settings.improve_3d = false;
        match adaptive_mesh(region, &settings, &height) {
            Ok((mesh, _, _)) => break mesh,
            Err(MeshError::Incomplete { .. }) if tolerance < hi - lo => tolerance *= 2.0,
            Err(e) => return Err(e).context("decimating the DSM for the 3D viewer"),
        }
    };
    let n = mesh.points.len();
    let mut positions = Vec::with_capacity(n);
    let mut values = vec![Vec::with_capacity(n); fields.len()];
    for i in 0..n {
        let q = mesh.absolute(i);
        let (t, w) = locator
            .locate(q[0], q[1])
            .with_context(|| format!("decimated vertex ({}, {}) is outside the DSM", q[0], q[1]))?;
        let at =
            |f: &[f64]| w[0] * f[t[0] as usize] + w[1] * f[t[1] as usize] + w[2] * f[t[2] as usize];
        positions.push([q[0], q[1], at(&z)]);
        for (k, f) in fields.iter().enumerate() {
            values[k].push(at(f));
        }
    }
    Ok(Decimated {
        positions,
        triangles: mesh.triangles,
        values,
        tolerance,
    })
}

/// Finds the triangle of a planar mesh under a point: a grid of buckets over the bounding box,
/// each listing the triangles whose bounding boxes meet it.
struct Locator<'a> {
    abs: &'a [[f64; 3]],
    tris: &'a [[u32; 3]],
    lo: [f64; 2],
    cell: f64,
    nx: usize,
    ny: usize,
    /// Bucket `b` holds `items[start[b]..start[b + 1]]`.
    start: Vec<usize>,
    items: Vec<u32>,
}

impl<'a> Locator<'a> {
    fn new(abs: &'a [[f64; 3]], tris: &'a [[u32; 3]]) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in abs {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(1e-12);
        let cell = (area / tris.len().max(1) as f64).sqrt().max(1e-9);
        let nx = (((hi[0] - lo[0]) / cell) as usize + 1).min(1 << 14);
        let ny = (((hi[1] - lo[1]) / cell) as usize + 1).min(1 << 14);
        let mut me = Locator {
            abs,
            tris,
            lo,
            cell,
            nx,
            ny,
            start: vec![0; nx * ny + 1],
            items: Vec::new(),
        };
        // Two passes: count, then fill (compressed rows).
        for pass in 0..2 {
            let mut fill = me.start.clone();
            for (k, t) in tris.iter().enumerate() {
                let (i0, j0, i1, j1) = me.span(t);
                for j in j0..=j1 {
                    for i in i0..=i1 {
                        let b = j * nx + i;
                        if pass == 0 {
                            me.start[b + 1] += 1;
                        } else {
                            me.items[fill[b]] = k as u32;
                            fill[b] += 1;
                        }
                    }
                }
            }
            if pass == 0 {
                for b in 0..nx * ny {
                    me.start[b + 1] += me.start[b];
                }
                me.items = vec![0; me.start[nx * ny]];
            }
        }
        me
    }

    fn bucket(&self, x: f64, y: f64) -> (usize, usize) {
        let i = ((x - self.lo[0]) / self.cell).floor().max(0.0) as usize;
        let j = ((y - self.lo[1]) / self.cell).floor().max(0.0) as usize;
        (i.min(self.nx - 1), j.min(self.ny - 1))
    }

    fn span(&self, t: &[u32; 3]) -> (usize, usize, usize, usize) {
        let p = t.map(|i| self.abs[i as usize]);
        let (x0, x1) = (
            p[0][0].min(p[1][0]).min(p[2][0]),
            p[0][0].max(p[1][0]).max(p[2][0]),
        );
        let (y0, y1) = (
            p[0][1].min(p[1][1]).min(p[2][1]),
            p[0][1].max(p[1][1]).max(p[2][1]),
        );
        let (i0, j0) = self.bucket(x0, y0);
        let (i1, j1) = self.bucket(x1, y1);
        (i0, j0, i1, j1)
    }

    /// The triangle under `(x, y)` and the barycentric weights of its corners; for a point
    /// outside the mesh (a rounding error, or where the new mesh's boundary cuts a corner
    /// differently), the nearest triangle of the nearest non-empty ring of buckets, weights
    /// clamped.
    fn locate(&self, x: f64, y: f64) -> Option<([u32; 3], [f64; 3])> {
        let (i, j) = self.bucket(x, y);
        let mut best: Option<(f64, usize, [f64; 3])> = None;
        for ring in 0..self.nx.max(self.ny) {
            let (i0, i1) = (i.saturating_sub(ring), (i + ring).min(self.nx - 1));
            let (j0, j1) = (j.saturating_sub(ring), (j + ring).min(self.ny - 1));
            for jj in j0..=j1 {
                for ii in i0..=i1 {
                    let b = jj * self.nx + ii;
                    for &k in &self.items[self.start[b]..self.start[b + 1]] {
                        let w = self.weights(k as usize, x, y);
                        let worst = w[0].min(w[1]).min(w[2]);
                        if worst >= -1e-9 {
                            return Some((self.tris[k as usize], w));
                        }
                        let better = match &best {
                            None => true,
                            Some(b) => worst > b.0,
                        };
                        if better {
                            best = Some((worst, k as usize, w));
                        }
                    }
                }
            }
            if best.is_some() {
                break;
            }
        }
        best.map(|(_, k, w)| {
            let c = w.map(|v| v.max(0.0));
            let s = c[0] + c[1] + c[2];
            (self.tris[k], c.map(|v| v / s))
        })
    }

    fn weights(&self, k: usize, x: f64, y: f64) -> [f64; 3] {
        let [a, b, c] = self.tris[k].map(|i| self.abs[i as usize]);
        let det = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1]);
        if det.abs() < 1e-300 {
            return [-1.0; 3];
        }
        let l0 = ((b[1] - c[1]) * (x - c[0]) + (c[0] - b[0]) * (y - c[1])) / det;
        let l1 = ((c[1] - a[1]) * (x - c[0]) + (a[0] - c[0]) * (y - c[1])) / det;
        [l0, l1, 1.0 - l0 - l1]
    }

    fn interpolate(&self, x: f64, y: f64, f: &[f64]) -> Option<f64> {
        // None only for a mesh without triangles.
        let (t, w) = self.locate(x, y)?;
        Some(w[0] * f[t[0] as usize] + w[1] * f[t[1] as usize] + w[2] * f[t[2] as usize])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use terramesh_mesh::MeshBuilder;

    /// A fine mesh of a 1 km square under a smooth hill.
    fn hill() -> (Region, Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let r = Region::from_ring(vec![
            [500_000.0, 5_400_000.0],
            [501_000.0, 5_400_000.0],
            [501_000.0, 5_401_000.0],
            [500_000.0, 5_401_000.0],
        ]);
        let (mesh, _) = MeshBuilder::new().max_area(100.0).build(&r).unwrap();
        let h = |x: f64, y: f64| {
            300.0 + 40.0 * (-((x - 500_400.0).powi(2) + (y - 5_400_600.0).powi(2)) / 9e4).exp()
        };
        let abs = (0..mesh.points.len())
            .map(|i| {
                let q = mesh.absolute(i);
                [q[0], q[1], h(q[0], q[1])]
            })
            .collect();
        (r, abs, mesh.triangles)
    }

    #[test]
    fn decimation_stays_within_the_budget_and_interpolates_the_fields() {
        let (r, abs, tris) = hill();
        assert!(abs.len() > 4000, "{}", abs.len());
        let east: Vec<f64> = abs.iter().map(|p| p[0] - 500_000.0).collect();
        let d = decimate(&r, &abs, &tris, &[&east], 1000).unwrap();
        assert!(
            d.positions.len() <= 1000 && d.positions.len() > 100,
            "{}",
            d.positions.len()
        );
        // A field linear in x is reproduced exactly by barycentric interpolation.
        for (p, e) in d.positions.iter().zip(&d.values[0]) {
            assert!((p[0] - 500_000.0 - e).abs() < 1e-6, "{p:?} {e}");
        }
        // The decimated surface is within the tolerance of the full one at its own vertices
        // (they lie on it) and the tolerance grew from its start only as the budget needed.
        let full = Locator::new(&abs, &tris);
        let z: Vec<f64> = abs.iter().map(|p| p[2]).collect();
        for p in &d.positions {
            assert!((full.interpolate(p[0], p[1], &z).unwrap() - p[2]).abs() < 1e-9);
        }
        assert!(d.tolerance > 40.0 / 2000.0, "{}", d.tolerance);
    }

    #[test]
    fn the_locator_finds_every_triangle_centre() {
        let (_, abs, tris) = hill();
        let loc = Locator::new(&abs, &tris);
        for t in tris.iter().step_by(7) {
            let c = [0, 1].map(|k| t.iter().map(|&i| abs[i as usize][k]).sum::<f64>() / 3.0);
            let (found, w) = loc.locate(c[0], c[1]).unwrap();
            assert_eq!(found, *t);
            assert!(w.iter().all(|v| (v - 1.0 / 3.0).abs() < 1e-6), "{w:?}");
        }
    }

    #[test]
    fn a_point_outside_the_mesh_gets_its_nearest_triangle() {
        let (_, abs, tris) = hill();
        let loc = Locator::new(&abs, &tris);
        let z: Vec<f64> = abs.iter().map(|p| p[2]).collect();
        // 5 m west of the south-west corner, many buckets away from any triangle.
        let corner = loc.interpolate(500_000.0, 5_400_000.0, &z).unwrap();
        let outside = loc.interpolate(499_995.0, 5_399_995.0, &z).unwrap();
        assert!((outside - corner).abs() < 1e-6, "{outside} vs {corner}");
    }
}
