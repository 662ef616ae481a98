//! The geological model on the DSM's planar mesh: fields from the boreholes (or horizon grids)
//! at every vertex, the rules, the volume mesh and its checks, and the misfit at every
//! observed contact.
//!
//! ```
//! use terramesh::geology::model::{assemble, Base, ModelInputs};
//! use terramesh_core::volume::Interpolated;
//! use terramesh_geology::Layering;
//! use terramesh_geostat::Method;
//! use terramesh_mesh::MeshBuilder;
//! use terramesh_core::geometry::Region;
//! let region = Region::from_ring(vec![[0.0, 0.0], [1000.0, 0.0], [1000.0, 800.0], [0.0, 800.0]]);
//! let (mesh, _) = MeshBuilder::new().max_area(5000.0).build(&region)?;
//! let terrain: Vec<f64> = (0..mesh.points.len()).map(|i| 100.0 + 0.01 * mesh.absolute(i)[0]).collect();
//! // The top of the second unit given directly (a horizon grid already sampled at the vertices).
//! let clay_top: Vec<f64> = terrain.iter().map(|z| z - 20.0).collect();
//! let inputs = ModelInputs {
//!     boreholes: None,
//!     grids: vec![(1, clay_top)],
//!     base: Base::Elevation(0.0),
//!     min_thickness: 0.5,
//!     layering: Layering::new(vec!["sand".into(), "clay".into()]),
//!     interpolate: Interpolated::Tops,
//!     method: Method::Ordinary,
//! };
//! let m = assemble(&mesh, &terrain, &inputs)?;
//! assert!((m.stats[0].mean_thickness - 20.0).abs() < 1e-9);
//! assert!((m.check.volume - m.check.unit_volumes.iter().sum::<f64>()).abs() < 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use terramesh_core::volume::{Interpolated, VolumeMesh};
use terramesh_geology::{
    apply_rules, cell_volumes, check_with_volumes, stack_thicknesses, unit_stats, CheckSummary,
    Layering, Planar, RawSurfaces, RulesReport, Stack, UnitStats,
};
use terramesh_geostat::Method;
use terramesh_io::boreholes::Boreholes;
use terramesh_mesh::{Mesh, SurfaceLocator};

use super::fields::{interpolate_field, Field, Observation};
use crate::error::{Context, Error, Result};

/// The model's base.
#[derive(Debug, Clone, PartialEq)]
pub enum Base {
    /// A flat base at this elevation, metres.
    Elevation(f64),
    /// One elevation per planar vertex (a base raster sampled at the vertices).
    PerVertex(Vec<f64>),
    /// Flat, [`AUTO_BASE_MARGIN`] of the model's relief below the lowest point of every
    /// interface and observed contact.
    Auto,
}

/// The margin of [`Base::Auto`] below the lowest point, as a fraction of the relief between
/// it and the highest terrain point (at least 1 m).
pub const AUTO_BASE_MARGIN: f64 = 0.1;

/// Everything the model is made from besides the planar mesh and the terrain.
#[derive(Debug, Clone)]
pub struct ModelInputs<'a> {
    /// The boreholes, if any.
    pub boreholes: Option<&'a Boreholes>,
    /// Unit tops given by horizon grids, sampled at the planar vertices: `(unit, values)`,
    /// `unit` >= 1 (the first unit's top is the terrain). They take the place of the
    /// boreholes for that unit; the boreholes' contacts are then only compared with it. NaN is
    /// the grid's nodata: the unit is absent there (zero thickness, its top the next top below,
    /// or the base).
    pub grids: Vec<(usize, Vec<f64>)>,
    /// The base.
    pub base: Base,
    /// Thinner than this, a unit pinches out, metres.
    pub min_thickness: f64,
    /// Units, sub-layers, element, side tags.
    pub layering: Layering,
    /// What is interpolated between holes.
    pub interpolate: Interpolated,
    /// The kriging method of every field.
    pub method: Method,
}

/// One observed contact against the model.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Misfit {
    /// The hole.
    pub hole: String,
    /// The unit whose top it is.
    pub unit: String,
    /// Where, metres.
    pub x: f64,
    /// Where, metres.
    pub y: f64,
    /// The observed elevation, metres.
    pub observed: f64,
    /// The model's elevation there, metres.
    pub model: f64,
    /// `model - observed`, metres.
    pub misfit: f64,
}

/// The assembled model.
#[derive(Debug, Clone)]
pub struct GeologicalModel {
    /// The volume mesh, tagged faces and sealed bodies.
    pub mesh: VolumeMesh,
    /// The repaired surfaces at the planar vertices (terrain, tops, base).
    pub stack: Stack,
    /// What the rules changed.
    pub rules: RulesReport,
    /// The interpolated fields, in the order interpolated (tops of units 1.. or
    /// thicknesses of units 0..n-1).
    pub fields: Vec<Field>,
    /// Per-unit figures.
    pub stats: Vec<UnitStats>,
    /// The independent checks' summary.
    pub check: CheckSummary,
    /// Every observed contact against the model: the collars against the terrain (the top
    /// of the first unit), then the logged tops of the other units.
    pub misfits: Vec<Misfit>,
    /// The horizon grids of the inputs as given (`(unit, values)`, before the rules): the
    /// realisations of [`super::ensemble`] use them unchanged.
    pub grids: Vec<(usize, Vec<f64>)>,
}

/// Builds the model on `mesh` (the DSM's planar mesh) under `terrain` (its elevations).
pub fn assemble(mesh: &Mesh, terrain: &[f64], inputs: &ModelInputs) -> Result<GeologicalModel> {
    assemble_beside(mesh, terrain, inputs, |_, _, _| ()).map(|(m, ())| m)
}

/// [`assemble`], running `beside` (the writing of the model's files) on the volume mesh, the
/// repaired surfaces and the cells' volumes at the same time as the model's independent
/// checks instead of after them: the two cores of a small machine then share the checks and
/// the writing. When a check fails its error is returned, whatever `beside` did, so `beside`
/// must write where a failed build is thrown away (the build's staging folder, which replaces
/// the output folder only when the whole build succeeds).
pub(crate) fn assemble_beside<R: Send>(
    mesh: &Mesh,
    terrain: &[f64],
    inputs: &ModelInputs,
    beside: impl FnOnce(&VolumeMesh, &Stack, &[f64]) -> R + Send,
) -> Result<(GeologicalModel, R)> {
    let units = &inputs.layering.units;
    if units.is_empty() {
        return Err(Error::NoUnits);
    }
    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    let planar = Planar::new(&xy, &mesh.triangles).context("the planar mesh")?;
    let holes = inputs.boreholes;
    let base = base_values(inputs, terrain, holes, xy.len())?;
    let mut fields = Vec::new();
    for (unit, obs) in field_observations(inputs)? {
        fields.push(interpolate_field(&units[unit], &obs, &xy, inputs.method)?);
    }
    let values: Vec<&[f64]> = fields.iter().map(|f| &f.values[..]).collect();
    let (stack, rules) = stack_of(&planar, terrain, &base, inputs, &values)?;
    let (volume, summary, stats, r) = seal_beside(&planar, &stack, &inputs.layering, beside)?;
    let misfits = holes.map(|b| misfits(b, mesh, &stack)).unwrap_or_default();
    let model = GeologicalModel {
        mesh: volume,
        stack,
        rules,
        fields,
        stats,
        check: summary,
        misfits,
        grids: inputs.grids.clone(),
    };
    Ok((model, r))
}

/// Builds the model from fields estimated already at the planar vertices: `values` in the
/// order of the fields [`assemble`] would interpolate (the tops of units 1.. that no horizon
/// grid of `inputs` gives, or with [`Interpolated::Thickness`] the thicknesses of units
/// 0..n-1; `inputs.boreholes` then only gives the misfits), followed by the same rules,
/// volume mesh and checks. A tile of a tiled build (`terramesh-tiles`) takes this: the plan
/// estimated its fields, the tile assembles its model as a one-piece build does.
///
/// ```
/// use terramesh::geology::model::{assemble_estimated, Base, ModelInputs};
/// use terramesh_core::volume::Interpolated;
/// use terramesh_geology::Layering;
/// use terramesh_geostat::Method;
/// use terramesh_mesh::Mesh;
/// let mesh = Mesh {
///     origin: [0.0, 0.0],
///     points: vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]],
///     triangles: vec![[0, 1, 2], [0, 2, 3]],
///     constraint_edges: vec![],
/// };
/// let inputs = ModelInputs {
///     boreholes: None,
///     grids: vec![],
///     base: Base::Elevation(0.0),
///     min_thickness: 0.0,
///     layering: Layering::new(vec!["sand".into(), "clay".into()]),
///     interpolate: Interpolated::Thickness,
///     method: Method::Ordinary,
/// };
/// // 4 m of sand over clay down to the base at 0, under a flat terrain at 10 m.
/// let model = assemble_estimated(&mesh, &[10.0; 4], &inputs, &[&[4.0; 4]])?;
/// assert!((model.check.unit_volumes[0] - 400.0).abs() < 1e-9);
/// assert!((model.check.unit_volumes[1] - 600.0).abs() < 1e-9);
/// # Ok::<(), terramesh::Error>(())
/// ```
pub fn assemble_estimated(
    mesh: &Mesh,
    terrain: &[f64],
    inputs: &ModelInputs,
    values: &[&[f64]],
) -> Result<GeologicalModel> {
    if inputs.layering.units.is_empty() {
        return Err(Error::NoUnits);
    }
    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    let planar = Planar::new(&xy, &mesh.triangles).context("the planar mesh")?;
    let holes = inputs.boreholes;
    let base = base_values(inputs, terrain, holes, xy.len())?;
    let (stack, rules) = stack_of(&planar, terrain, &base, inputs, values)?;
    let (volume, check, stats) = seal(&planar, &stack, &inputs.layering)?;
    let misfits = holes.map(|b| misfits(b, mesh, &stack)).unwrap_or_default();
    Ok(GeologicalModel {
        mesh: volume,
        stack,
        rules,
        fields: Vec::new(),
        stats,
        check,
        misfits,
        grids: inputs.grids.clone(),
    })
}

/// The fields a model interpolates, in order, as `(unit, observations)`: the tops of units
/// 1.. that no horizon grid gives, or the thicknesses of units 0..n-1.
pub(crate) fn field_observations(inputs: &ModelInputs) -> Result<Vec<(usize, Vec<Observation>)>> {
    let n = inputs.layering.units.len();
    let holes = inputs.boreholes;
    Ok(match inputs.interpolate {
        Interpolated::Tops => (1..n)
            .filter(|u| !inputs.grids.iter().any(|g| g.0 == *u))
            .map(|u| (u, holes.map(|b| tops_of(b, u)).unwrap_or_default()))
            .collect(),
        Interpolated::Thickness => {
            if !inputs.grids.is_empty() {
                return Err(Error::GridsGiveTops);
            }
            let Some(b) = holes else {
                return Err(Error::ThicknessNeedsBoreholes);
            };
            (0..n - 1)
                .map(|u| {
                    let obs = b
                        .thicknesses(u)
                        .map(|(h, t, p)| Observation {
                            hole: h.name.clone(),
                            x: p[0],
                            y: p[1],
                            value: t,
                        })
                        .collect();
                    (u, obs)
                })
                .collect()
        }
    })
}

/// The repaired surfaces from the interpolated `values` of the fields of
/// [`field_observations`] (in its order), the horizon grids of `inputs`, the terrain and the
/// base: the geological rules of `terramesh_geology`.
pub(crate) fn stack_of(
    planar: &Planar,
    terrain: &[f64],
    base: &[f64],
    inputs: &ModelInputs,
    values: &[&[f64]],
) -> Result<(Stack, RulesReport)> {
    let n = planar.points.len();
    let mut values = values.iter();
    match inputs.interpolate {
        Interpolated::Tops => {
            let mut tops = Vec::new();
            for unit in 1..inputs.layering.units.len() {
                match inputs.grids.iter().find(|g| g.0 == unit) {
                    Some(g) => tops.push(g.1.clone()),
                    None => tops.push(values.next().map(|v| v.to_vec()).unwrap_or_default()),
                }
            }
            // A grid's nodata: the unit is absent there, its top is the next top below.
            for k in (0..tops.len()).rev() {
                for v in 0..n {
                    if tops[k][v].is_nan() {
                        tops[k][v] = if k + 1 < tops.len() {
                            tops[k + 1][v]
                        } else {
                            base[v]
                        };
                    }
                }
            }
            let raw = RawSurfaces {
                terrain: terrain.to_vec(),
                tops,
                base: base.to_vec(),
            };
            apply_rules(planar, &raw, inputs.min_thickness).context("the geological rules")
        }
        Interpolated::Thickness => {
            let thick: Vec<Vec<f64>> = values.map(|v| v.to_vec()).collect();
            stack_thicknesses(planar, terrain, &thick, base, inputs.min_thickness)
                .context("the geological rules")
        }
    }
}

/// The volume mesh of `stack`, its independent checks (sealed, conformal, positive cells,
/// the units' volume equal to the volume between the terrain and the base) and the per-unit
/// figures.
pub(crate) fn seal(
    planar: &Planar,
    stack: &Stack,
    layering: &Layering,
) -> Result<(VolumeMesh, CheckSummary, Vec<UnitStats>)> {
    seal_beside(planar, stack, layering, |_, _, _| ()).map(|(v, c, s, ())| (v, c, s))
}

/// Bytes of one cell of the volume mesh, all told: the cell's node indices and kind, its
/// material and volume, and its share of the nodes (a vertex per level, half as many as the
/// cells) and of the tagged faces. An upper estimate from the types' sizes, not measured.
const BYTES_PER_CELL: f64 = 96.0;

/// The volume mesh's size follows from the mesh and `[geology] layers` (up to 1,000 per unit):
/// its cells (triangles x sub-layers, three tetrahedra per prism with `element = "tetra"`)
/// estimated before anything is allocated, and refused beyond the memory ceiling naming the
/// key (issue 34: every number that reaches an allocation).
fn estimate_volume(planar: &Planar, layering: &Layering) -> Result<()> {
    let sub_layers: f64 = layering.layers.iter().map(|&l| l as f64).sum();
    let per_prism = if layering.element == terramesh_core::volume::Element::Tetra {
        3.0
    } else {
        1.0
    };
    terramesh_core::limits::Estimate::new(
        "cells of the volume mesh",
        planar.triangles.len() as f64 * sub_layers * per_prism,
        BYTES_PER_CELL,
    )
    .remedy(terramesh_core::limits::Remedy::lower("geology.layers"))
    .check()?;
    Ok(())
}

/// [`seal`], running `beside` at the same time as the checks (see [`assemble_beside`]).
fn seal_beside<R: Send>(
    planar: &Planar,
    stack: &Stack,
    layering: &Layering,
    beside: impl FnOnce(&VolumeMesh, &Stack, &[f64]) -> R + Send,
) -> Result<(VolumeMesh, CheckSummary, Vec<UnitStats>, R)> {
    estimate_volume(planar, layering)?;
    let volume =
        terramesh_geology::volume_mesh(planar, stack, layering).context("the volume mesh")?;
    // computed once, for the checks here and the writers' own
    let volumes = cell_volumes(&volume);
    let (checked, r) = rayon::join(
        || -> Result<(CheckSummary, Vec<UnitStats>)> {
            let summary = check_with_volumes(&volume, &volumes).context("checking the model")?;
            summary
                .compare_with(planar, stack)
                .context("checking the model's volume")?;
            Ok((summary, unit_stats(planar, stack, &volume)))
        },
        || beside(&volume, stack, &volumes),
    );
    let (summary, stats) = checked?;
    Ok((volume, summary, stats, r))
}

/// The observed tops of `unit` (every kind of contact: logged, at the collar, absent, repaired).
fn tops_of(b: &Boreholes, unit: usize) -> Vec<Observation> {
    b.contacts()
        .filter(|(_, c)| c.unit == unit)
        .map(|(h, c)| Observation {
            hole: h.name.clone(),
            x: c.position[0],
            y: c.position[1],
            value: c.position[2],
        })
        .collect()
}

pub(crate) fn base_values(
    inputs: &ModelInputs,
    terrain: &[f64],
    holes: Option<&Boreholes>,
    n: usize,
) -> Result<Vec<f64>> {
    Ok(match &inputs.base {
        Base::Elevation(z) => vec![*z; n],
        Base::PerVertex(v) if v.len() == n => v.clone(),
        Base::PerVertex(v) => {
            return Err(Error::BaseValues {
                values: v.len(),
                vertices: n,
            })
        }
        Base::Auto => {
            let hi = terrain.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let mut lo = terrain.iter().copied().fold(f64::INFINITY, f64::min);
            for (_, g) in &inputs.grids {
                lo = g.iter().copied().fold(lo, f64::min);
            }
            if let Some(b) = holes {
                for (_, c) in b.contacts() {
                    lo = lo.min(c.position[2]);
                }
            }
            let margin = (AUTO_BASE_MARGIN * (hi - lo)).max(1.0);
            vec![lo - margin; n]
        }
    })
}

/// Every observed contact of `b` against the surfaces `stack` on the planar `mesh` (linear
/// on its triangles): the collars against the terrain, then the logged tops of the other
/// units, hole by hole (`model.json`'s `boreholes`); a contact outside the mesh is left out.
pub fn misfits(b: &Boreholes, mesh: &Mesh, stack: &Stack) -> Vec<Misfit> {
    let locators: Vec<SurfaceLocator> = stack
        .surfaces
        .iter()
        .map(|s| SurfaceLocator::new(mesh, s))
        .collect();
    // The first unit's top is the terrain: it is compared with the collars. Its contacts in
    // the logs are not (a log that starts below the ground, at the top of a deeper formation,
    // makes the first unit of the column a cover unit no file names).
    let collars = b.holes.iter().filter_map(|h| {
        let model = locators[0].height(h.collar[0], h.collar[1])?;
        Some(Misfit {
            hole: h.name.clone(),
            unit: b.units[0].clone(),
            x: h.collar[0],
            y: h.collar[1],
            observed: h.collar[2],
            model,
            misfit: model - h.collar[2],
        })
    });
    let contacts = b
        .contacts()
        .filter(|(_, c)| c.unit > 0)
        .filter_map(|(h, c)| {
            let loc = locators.get(c.unit)?;
            let model = loc.height(c.position[0], c.position[1])?;
            Some(Misfit {
                hole: h.name.clone(),
                unit: b.units[c.unit].clone(),
                x: c.position[0],
                y: c.position[1],
                observed: c.position[2],
                model,
                misfit: model - c.position[2],
            })
        });
    collars.chain(contacts).collect()
}
