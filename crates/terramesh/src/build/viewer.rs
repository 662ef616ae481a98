//! The scene of the 3D viewer in `report.html` (`terramesh_report::viewer`): the DSM surface
//! coloured by elevation, kriging standard deviation or UK minus IDW; the sealed solid's sides
//! and base; the samples as points; with `[geology]`, the units (capped where the
//! cross-section cuts them) and the boreholes (traces and collars) as further layers.
//!
//! A DSM of more than [`VIEWER_TRIANGLES`] triangles is shown as a level-of-detail copy
//! (`terramesh_mesh::simplify`): a subset of its vertices, its boundary kept, chosen greedily
//! where the copy is furthest from the DSM, at most [`VIEWER_TRIANGLES`] triangles; the fields
//! are read at those vertices (no interpolation), and the viewer says how many triangles it
//! shows and the largest vertical difference from the DSM at the DSM's vertices.

use terramesh_core::solid::extrude;
use terramesh_mesh::{simplify_to, Mesh};
use terramesh_report::pictures::ColourMap;
use terramesh_report::viewer::{compact, Field, Geometry, Layer, Scene};

use super::stages::{Interpolated, Meshed, Samples};
use crate::error::{Context, Result};
use crate::geology::stage::ModelBuilt;

/// Most DSM vertices the viewer shows (at most `VIEWER_TRIANGLES` triangles have about half
/// as many vertices).
pub const VIEWER_VERTICES: usize = 200_000;
/// Most DSM triangles the viewer shows; larger surfaces are shown as a level-of-detail copy.
pub const VIEWER_TRIANGLES: usize = 200_000;
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
    // Vertices (which a model's shells copy twice per unit) and triangles.
    let vertices = match surfaces.len() {
        0 => VIEWER_VERTICES,
        n => VIEWER_VERTICES.min(VIEWER_MODEL_VERTICES / (2 * n - 1)),
    };
    let budget = VIEWER_TRIANGLES.min(2 * vertices);
    let mut notes = Vec::new();
    let (positions, triangles, mut values) = if mesh.triangles.len() > budget
        || mesh.points.len() > vertices
    {
        let d = level_of_detail(mesh, &it.dsm, &fields, budget, vertices)?;
        notes.push(format!(
            "The DSM has {} vertices and {} triangles; this view shows a decimated, level-of-detail \
             copy of {} of its vertices and {} triangles (at most {budget}), within {:.3} m of the \
             DSM in elevation at every DSM vertex{}. The exports and the pictures use the \
             full mesh.",
            mesh.points.len(),
            mesh.triangles.len(),
            d.positions.len(),
            d.triangles.len(),
            d.max_error,
            if geo.is_some() {
                "; the units' surfaces as the model gives them at its vertices"
            } else {
                ""
            }
        ));
        (d.positions, d.triangles, d.values)
    } else {
        let values = fields.iter().map(|f| f.to_vec()).collect();
        let abs = (0..mesh.points.len())
            .map(|i| {
                let q = mesh.absolute(i);
                [q[0], q[1], it.dsm[i]]
            })
            .collect();
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

/// A level-of-detail copy of the DSM: positions (with z), triangles, the fields at its
/// vertices.
pub(super) struct Decimated {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub values: Vec<Vec<f64>>,
    /// The largest vertical difference from the DSM at the DSM's vertices, metres.
    pub max_error: f64,
}

/// A copy of `mesh` (elevations `z`) with at most `max_triangles` triangles and `max_vertices`
/// vertices
/// (`terramesh_mesh::simplify`), with `fields` (one value per vertex of `mesh`) read at its
/// vertices, which are vertices of `mesh`.
pub(super) fn level_of_detail(
    mesh: &Mesh,
    z: &[f64],
    fields: &[&[f64]],
    max_triangles: usize,
    max_vertices: usize,
) -> Result<Decimated> {
    let lod = simplify_to(mesh, z, max_triangles, max_vertices)
        .map_err(terramesh_mesh::MeshError::from)
        .context("the level-of-detail copy of the DSM for the 3D view")?;
    let positions = lod
        .vertices
        .iter()
        .map(|&v| {
            let q = mesh.absolute(v as usize);
            [q[0], q[1], z[v as usize]]
        })
        .collect();
    let values = fields
        .iter()
        .map(|f| lod.vertices.iter().map(|&v| f[v as usize]).collect())
        .collect();
    Ok(Decimated {
        positions,
        triangles: lod.triangles,
        values,
        max_error: lod.max_error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use terramesh_core::geometry::Region;
    use terramesh_mesh::MeshBuilder;

    /// A fine mesh of a 1 km square under a smooth hill.
    fn hill() -> (Mesh, Vec<f64>) {
        let r = Region::from_ring(vec![
            [500_000.0, 5_400_000.0],
            [501_000.0, 5_400_000.0],
            [501_000.0, 5_401_000.0],
            [500_000.0, 5_401_000.0],
        ]);
        let (mesh, _) = MeshBuilder::new().max_area(100.0).build(&r).unwrap();
        let z = (0..mesh.points.len())
            .map(|i| {
                let q = mesh.absolute(i);
                300.0
                    + 40.0
                        * (-((q[0] - 500_400.0).powi(2) + (q[1] - 5_400_600.0).powi(2)) / 9e4).exp()
            })
            .collect();
        (mesh, z)
    }

    #[test]
    fn the_copy_keeps_the_budget_and_reads_the_fields_at_dsm_vertices() {
        let (mesh, z) = hill();
        assert!(mesh.triangles.len() > 8000, "{}", mesh.triangles.len());
        let east: Vec<f64> = (0..mesh.points.len())
            .map(|i| mesh.absolute(i)[0] - 500_000.0)
            .collect();
        let d = level_of_detail(&mesh, &z, &[&east], 2000, 1000).unwrap();
        assert!(
            d.triangles.len() <= 2000 && d.triangles.len() > 1000,
            "{}",
            d.triangles.len()
        );
        // Every vertex of the copy is a DSM vertex, its field value the DSM's own.
        for (p, e) in d.positions.iter().zip(&d.values[0]) {
            assert_eq!(p[0] - 500_000.0, *e);
            let k = (0..mesh.points.len())
                .find(|&i| mesh.absolute(i) == [p[0], p[1]])
                .expect("a DSM vertex");
            assert_eq!(z[k], p[2]);
        }
        assert!(d.max_error > 0.0 && d.max_error < 2.0, "{}", d.max_error);
    }
}
