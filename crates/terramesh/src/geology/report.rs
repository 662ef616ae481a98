//! The geological model in the report: two vertical sections (along the region's long axis
//! and across it, units coloured, the boreholes near each line drawn with their logged
//! units), a thickness map per unit, the unit volume table and the misfit at the holes.
//! Pictures go to `out/pictures/model-*.png` (and `.svg`).

use std::path::Path;

use terramesh_mesh::Mesh;
use terramesh_report::pictures::{
    draw_bodies_view3d, draw_section, draw_surface, render_both_as, unit_colour, ColourMap,
    Section as Cut, SectionFault, SectionHole, SurfaceMap, SvgMode, VECTOR_TRIANGLE_LIMIT,
};
use terramesh_report::report::{Block, Section};

use super::section::{along_line, long_and_cross_axes, profile};
use super::stage::ModelBuilt;
use crate::error::{Context, Result};

/// Stations along each section line.
pub const SECTION_STATIONS: usize = 600;

/// The report section of the model, with its pictures drawn into `out/pictures/`.
pub fn model_section(out: &Path, m: &ModelBuilt, mesh: &Mesh) -> Result<Section> {
    let dir = out.join("pictures");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    // The column's units (a faulted model's mesh names its fault zones' materials after them).
    let all = &m.model.mesh.units;
    let units = &all[..m.model.stack.units().min(all.len())];
    let surfaces = &m.model.stack.surfaces;
    let mode = if mesh.triangles.len() > VECTOR_TRIANGLE_LIMIT {
        SvgMode::Raster
    } else {
        SvgMode::Vector
    };
    let mut blocks = Vec::new();
    let [long, cross] = long_and_cross_axes(mesh);
    for (name, (a, b), title) in [
        (
            "model-section-long",
            long,
            "Section along the region's long axis",
        ),
        ("model-section-cross", cross, "Section across the region"),
    ] {
        let (d, z) = profile(mesh, surfaces, a, b, SECTION_STATIONS);
        let len = d.last().copied().unwrap_or(0.0);
        // Holes within 5 % of the section's length from the line.
        let holes: Vec<SectionHole> = m
            .boreholes
            .iter()
            .flat_map(|bh| bh.holes.iter())
            .filter_map(|h| {
                let (t, off) = along_line(a, b, [h.collar[0], h.collar[1]])?;
                (off <= 0.05 * len).then(|| SectionHole {
                    name: h.name.clone(),
                    distance: t,
                    intervals: logged(h),
                })
            })
            .collect();
        let faults: Vec<SectionFault> = m
            .faults
            .iter()
            .map(|f| SectionFault {
                name: f.name.clone(),
                segments: f.cut(a, b),
            })
            .filter(|f| !f.segments.is_empty())
            .collect();
        let objects: Vec<SectionFault> = m
            .objects
            .iter()
            .map(|o| SectionFault {
                name: o.name.clone(),
                segments: o.cut(a, b),
            })
            .filter(|o| !o.segments.is_empty())
            .collect();
        let cut = Cut {
            title,
            distance: &d,
            surfaces: &z,
            units,
            holes: &holes,
            faults: &faults,
            objects: &objects,
        };
        let crossed = if faults.is_empty() {
            String::new()
        } else {
            let names: Vec<&str> = faults.iter().map(|f| f.name.as_str()).collect();
            format!(
                ", and the faults it crosses ({}) in dark red",
                names.join(", ")
            )
        };
        let crossed = if objects.is_empty() {
            crossed
        } else {
            let names: Vec<&str> = objects.iter().map(|o| o.name.as_str()).collect();
            format!(
                "{crossed}, and the outlines of the engineering objects it crosses ({}) in dark \
                 blue",
                names.join(", ")
            )
        };
        let files = render_both_as(&dir.join(name), (1100, 550), SvgMode::Vector, |r| {
            draw_section(r, &cut)
        })?;
        blocks.push(png(
            &files[0],
            format!(
                "{title}: from ({:.0}, {:.0}) to ({:.0}, {:.0}), {:.0} m, with the {} holes within \
                 {:.0} m of the line and their logged units{crossed}",
                a[0],
                a[1],
                b[0],
                b[1],
                len,
                holes.len(),
                0.05 * len
            ),
        )?);
    }
    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    blocks.push(stacked_view(&dir, &xy, mesh, surfaces, units)?);
    if !m.faults.is_empty() || !m.objects.is_empty() {
        blocks.push(sheets_view(&dir, m)?);
    }
    for (k, unit) in units.iter().enumerate() {
        let thickness: Vec<f64> = (0..xy.len())
            .map(|v| surfaces[k][v] - surfaces[k + 1][v])
            .collect();
        let title = format!("Thickness of {unit} (m)");
        let map = SurfaceMap {
            xy: &xy,
            values: &thickness,
            shade_z: None,
            triangles: &mesh.triangles,
            title: &title,
            unit: "thickness (m)",
            colours: ColourMap::Viridis,
            symmetric: false,
            outlines: &[],
        };
        let files = render_both_as(
            &dir.join(format!("model-thickness-{unit}")),
            (900, 700),
            mode,
            |r| draw_surface(r, &map),
        )?;
        blocks.push(png(
            &files[0],
            format!("Thickness of {unit} (isopach), metres"),
        )?);
    }
    let s = &m.summary;
    blocks.push(Block::Table {
        caption: format!(
            "Units, top to bottom ({} cells on {} points; the volumes add up to the volume between \
             the terrain and the base to {:.1e} relative)",
            s.cells, s.points, s.checks.relative_difference
        ),
        header: [
            "unit",
            "MaterialIDs",
            "volume (m³)",
            "cells",
            "thickness min / mean / max (m)",
            "pinched-out area (m²)",
            "interpolated",
        ]
        .map(String::from)
        .to_vec(),
        rows: s
            .units
            .iter()
            .map(|u| {
                vec![
                    u.name.clone(),
                    u.material_id.to_string(),
                    format!("{:.6e}", u.volume),
                    u.cells.to_string(),
                    format!(
                        "{:.2} / {:.2} / {:.2}",
                        u.min_thickness, u.mean_thickness, u.max_thickness
                    ),
                    format!("{:.1}", u.pinched_out_area),
                    u.interpolated.clone(),
                ]
            })
            .collect(),
    });
    if let Some(f) = &s.faulted {
        blocks.extend(fault_tables(f));
    }
    if let Some(o) = &s.objects {
        blocks.extend(object_tables(o));
    }
    if !s.boreholes.is_empty() {
        let worst = s
            .boreholes
            .iter()
            .max_by(|a, b| a.misfit.abs().total_cmp(&b.misfit.abs()))
            .map(|w| format!("{} m ({} in {})", w.misfit, w.unit, w.hole))
            .unwrap_or_default();
        blocks.push(Block::Text(format!(
            "{} observed contacts (every collar against the terrain, every logged top against its \
             interface); the largest misfit (model − observed) is {worst}. model.json lists each.",
            s.boreholes.len()
        )));
    }
    Ok(Section {
        heading: "Geological model".into(),
        blocks,
    })
}

/// The tables of a faulted model: its faults (kind, throw given, area, mean dip and dip
/// direction as meshed, the throw along it) and its fault blocks (volume, cells, units, where
/// the interfaces come from), from `model.json`'s `faulted`.
pub fn fault_tables(f: &super::faulted::FaultedSummary) -> [Block; 2] {
    // A column of the fault zones, only when a fault has one.
    let zoned = f.faults.iter().any(|x| x.zone.is_some());
    let mut faults = Block::Table {
        caption: format!(
            "Faults as meshed ({} faults; the smallest dihedral angle of any cell {:.1} degrees, \
             the largest distance of a fault face from its fault {:.1e} m)",
            f.faults.len(),
            f.min_dihedral_degrees,
            f.fault_distance
        ),
        header: [
            "fault",
            "kind",
            "throw given (m)",
            "faces",
            "area (m²)",
            "mean dip (°)",
            "mean dip direction (°)",
            "throw along it, mean over the interfaces (m)",
        ]
        .map(String::from)
        .to_vec(),
        rows: f
            .faults
            .iter()
            .map(|x| {
                let n = x.throw_along.len().max(1) as f64;
                let mean = x.throw_along.iter().map(|t| t.mean).sum::<f64>() / n;
                vec![
                    x.name.clone(),
                    format!("{:?}", x.kind).to_lowercase(),
                    x.throw.map_or("-".into(), |t| format!("{t}")),
                    x.faces.to_string(),
                    format!("{:.1}", x.area),
                    format!("{:.1}", x.mean_dip),
                    format!("{:.1}", x.mean_dip_direction),
                    format!("{mean:.2}"),
                ]
            })
            .collect(),
    };
    if let (true, Block::Table { header, rows, .. }) = (zoned, &mut faults) {
        header.push("zone: material, thickness (m), volume meshed / exact (m³)".into());
        for (row, x) in rows.iter_mut().zip(&f.faults) {
            row.push(x.zone.as_ref().map_or("-".into(), |z| {
                format!(
                    "{} (MaterialIDs {}), {}, {:.1} / {:.1}",
                    z.material, z.material_id, z.thickness, z.covered_volume, z.expected_volume
                )
            }));
        }
    }
    let blocks = Block::Table {
        caption: format!(
            "Fault blocks ({}): each named by its side of every fault that counts there",
            f.blocks.len()
        ),
        header: [
            "block",
            "name",
            "volume (m³)",
            "cells",
            "units",
            "interfaces from contacts / throw",
        ]
        .map(String::from)
        .to_vec(),
        rows: f
            .blocks
            .iter()
            .map(|b| {
                let from = |w: &str| b.interfaces.iter().filter(|i| i.from == w).count();
                vec![
                    b.block.to_string(),
                    b.name.clone(),
                    format!("{:.6e}", b.volume),
                    b.cells.to_string(),
                    if b.zones.is_empty() {
                        b.units.join(", ")
                    } else {
                        format!(
                            "{}; fault zones: {}",
                            b.units.join(", "),
                            b.zones.join(", ")
                        )
                    },
                    format!("{} / {}", from("contacts"), from("throw")),
                ]
            })
            .collect(),
    };
    [faults, blocks]
}

/// The tables of a model's engineering objects, from `model.json`'s `objects`: per object its
/// kind, stage, cells, meshed against exact volume, the units it crosses (its volume in each
/// and a tunnel's axis length) and its fault blocks; per excavation stage the excavated volume,
/// its cells and the objects dug in it.
pub fn object_tables(o: &super::objects::ObjectsSummary) -> [Block; 2] {
    let objects = Block::Table {
        caption: format!(
            "Engineering objects as meshed ({} objects; the volume error is |meshed − exact| / \
             exact; the units each crosses with its volume in each, and a tunnel's axis length)",
            o.objects.len()
        ),
        header: [
            "object",
            "kind",
            "stage",
            "material",
            "cells",
            "meshed volume (m³)",
            "exact volume (m³)",
            "volume error (%)",
            "units crossed: volume (m³) [axis length (m)]",
            "fault blocks",
        ]
        .map(String::from)
        .to_vec(),
        rows: o
            .objects
            .iter()
            .map(|x| {
                let units: Vec<String> = x
                    .units
                    .iter()
                    .map(|u| match u.length {
                        Some(l) => format!("{}: {:.1} [{l:.1}]", u.unit, u.volume),
                        None => format!("{}: {:.1}", u.unit, u.volume),
                    })
                    .collect();
                vec![
                    x.name.clone(),
                    x.kind.to_string(),
                    if x.stage == 0 {
                        "-".into()
                    } else {
                        x.stage.to_string()
                    },
                    x.material.clone().unwrap_or_else(|| "-".into()),
                    x.cells.to_string(),
                    format!("{:.1}", x.meshed_volume),
                    format!("{:.1}", x.exact_volume),
                    format!("{:.3}", 100.0 * x.volume_error),
                    units.join("; "),
                    x.blocks.join(", "),
                ]
            })
            .collect(),
    };
    let stages = Block::Table {
        caption: format!(
            "Excavation stages ({}): the cells each removes (FLAC3D's zone group stage-<n>, \
             model.vtu's excavation_stage), a tunnel's lining never",
            o.stages.len()
        ),
        header: ["stage", "excavated volume (m³)", "cells", "objects"]
            .map(String::from)
            .to_vec(),
        rows: o
            .stages
            .iter()
            .map(|st| {
                let names: Vec<&str> = o
                    .objects
                    .iter()
                    .filter(|x| x.stage == st.stage)
                    .map(|x| x.name.as_str())
                    .collect();
                vec![
                    st.stage.to_string(),
                    format!("{:.1}", st.excavated_volume),
                    st.cells.to_string(),
                    names.join(", "),
                ]
            })
            .collect(),
    };
    [objects, stages]
}

/// Most triangles of the still picture of the faults and objects (all sheets together).
pub const STILL_SHEET_TRIANGLES: usize = 60_000;

/// The still 3D view of a faulted model's faults and its engineering objects
/// (`pictures/model-faults-view3d.png`): each fault's faces (both sides) and each object's
/// boundary in the viewer's colours, seen as the stacked bodies are, at true scale, thinned to
/// [`STILL_SHEET_TRIANGLES`] in all as the viewer thins them.
fn sheets_view(dir: &Path, m: &ModelBuilt) -> Result<Block> {
    use super::web::{fault_colour, object_colour, sheet_mesh};
    let sizes: Vec<usize> = m
        .faults
        .iter()
        .map(|f| 2 * f.triangles.len())
        .chain(m.objects.iter().map(|o| o.triangles.len()))
        .collect();
    let shares = super::web::shares(&sizes, STILL_SHEET_TRIANGLES, STILL_SHEET_TRIANGLES);
    let (mut v, mut t, mut c) = (Vec::new(), Vec::new(), Vec::new());
    let mut thinned = false;
    let sheets = m
        .faults
        .iter()
        .enumerate()
        .map(|(k, f)| (f, fault_colour(k), true))
        .chain(
            m.objects
                .iter()
                .enumerate()
                .map(|(k, o)| (o, object_colour(k), false)),
        );
    for ((sheet, colour, both_sides), &each) in sheets.zip(&shares) {
        let s = sheet_mesh(&sheet.triangles, if both_sides { each / 2 } else { each });
        thinned |= s.cell > 0.0;
        let off = v.len() as u32;
        v.extend_from_slice(&s.vertices);
        let rgb = terramesh_report::pictures::RGBColor(colour[0], colour[1], colour[2]);
        for tr in &s.triangles {
            t.push(tr.map(|i| i + off));
            c.push(rgb);
            if both_sides {
                // a fault is an open sheet: seen from either side
                t.push([tr[0], tr[2], tr[1]].map(|i| i + off));
                c.push(rgb);
            }
        }
    }
    let mode = if t.len() > VECTOR_TRIANGLE_LIMIT {
        SvgMode::Raster
    } else {
        SvgMode::Vector
    };
    let title = "Faults and engineering objects";
    let files = render_both_as(&dir.join("model-faults-view3d"), (1000, 700), mode, |r| {
        draw_bodies_view3d(r, &v, &t, &c, 1.0, title)
    })?;
    let mut parts = Vec::new();
    if !m.faults.is_empty() {
        let names: Vec<&str> = m.faults.iter().map(|f| f.name.as_str()).collect();
        parts.push(format!("the faults ({}) in reds", names.join(", ")));
    }
    if !m.objects.is_empty() {
        let names: Vec<&str> = m.objects.iter().map(|o| o.name.as_str()).collect();
        parts.push(format!(
            "the engineering objects' boundaries ({}) in blues",
            names.join(", ")
        ));
    }
    png(
        &files[0],
        format!(
            "{title} as meshed, seen as the stacked bodies are, true scale: {}{}",
            parts.join(" and "),
            if thinned {
                format!(" (thinned by vertex clustering to at most {STILL_SHEET_TRIANGLES} triangles in all)")
            } else {
                String::new()
            }
        ),
    )
}

/// The still 3D view of the stacked unit bodies (`pictures/model-view3d.png`): each unit's
/// shell (`super::web::unit_shells`) in its colour, seen from the south-west, with a vertical
/// exaggeration that makes the model's height about a third of its width.
fn stacked_view(
    dir: &Path,
    xy: &[[f64; 2]],
    mesh: &Mesh,
    surfaces: &[Vec<f64>],
    units: &[String],
) -> Result<Block> {
    let shells = super::web::unit_shells(xy, &mesh.triangles, surfaces);
    let (mut v, mut t, mut c) = (Vec::new(), Vec::new(), Vec::new());
    for sh in &shells {
        let off = v.len() as u32;
        v.extend_from_slice(&sh.vertices);
        t.extend(sh.triangles.iter().map(|tr| tr.map(|i| i + off)));
        c.extend(std::iter::repeat_n(
            unit_colour(sh.unit),
            sh.triangles.len(),
        ));
    }
    let span = |k: usize| {
        let (lo, hi) = v.iter().fold(
            (f64::INFINITY, f64::NEG_INFINITY),
            |(a, b), p: &[f64; 3]| (a.min(p[k]), b.max(p[k])),
        );
        (hi - lo).max(1e-9)
    };
    let exaggeration = ((0.3 * span(0).max(span(1)) / span(2)) * 2.0)
        .round()
        .max(2.0)
        / 2.0;
    let mode = if t.len() > VECTOR_TRIANGLE_LIMIT {
        SvgMode::Raster
    } else {
        SvgMode::Vector
    };
    let title = "The stacked unit bodies";
    let files = render_both_as(&dir.join("model-view3d"), (1000, 700), mode, |r| {
        draw_bodies_view3d(r, &v, &t, &c, exaggeration, title)
    })?;
    let names: Vec<&str> = shells.iter().map(|s| units[s.unit].as_str()).collect();
    png(
        &files[0],
        format!(
            "{title}, top to bottom: {} (the colours of the sections), each closed by its sides, \
             vertical exaggeration {exaggeration:.1}x",
            names.join(", ")
        ),
    )
}

/// The logged intervals of a hole, `(top, bottom, unit)`: from each known top down to the
/// next known top below it.
fn logged(h: &terramesh_io::boreholes::Hole) -> Vec<(f64, f64, usize)> {
    let tops: Vec<(f64, usize)> = h
        .tops
        .iter()
        .flatten()
        .map(|c| (c.position[2], c.unit))
        .collect();
    tops.windows(2)
        .filter(|w| w[0].0 > w[1].0)
        .map(|w| (w[0].0, w[1].0, w[0].1))
        .collect()
}

fn png(path: &Path, caption: String) -> Result<Block> {
    Ok(Block::Png {
        caption,
        bytes: std::fs::read(path).with_context(|| path.display().to_string())?,
    })
}
