//! The volume mesh driver: the columns of nodes, the cells of every planar triangle and
//! sub-layer, the tagged faces and the sealed bodies.

use rayon::prelude::*;
use terramesh_core::volume::{Cell, Element, FaceTag, TaggedFace, VolumeMesh};

use crate::cells::{emit, prismatic, side_face, split_quad};
use crate::columns::Columns;
use crate::sides::{classify, SideTags};
use crate::{bodies, GeologyError, Planar, Stack};

/// The layering of the model: unit names, sub-layers per unit, the element and the side tags.
///
/// ```
/// use terramesh_core::volume::Element;
/// use terramesh_geology::{Layering, SideTags};
/// let l = Layering::new(vec!["sand".into(), "clay".into()])
///     .layers(vec![4, 2])
///     .element(Element::Tetra)
///     .sides(SideTags::Outline { corner_degrees: 10.0 });
/// assert_eq!(l.layers, [4, 2]);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Layering {
    /// Unit names, top to bottom.
    pub units: Vec<String>,
    /// Sub-layers per unit, each at least 1 (default 1): the unit is split evenly.
    pub layers: Vec<usize>,
    /// Prisms (degenerating to pyramids and tetrahedra) or tetrahedra only (default prisms).
    pub element: Element,
    /// How the side faces are tagged (default by compass direction).
    pub sides: SideTags,
}

impl Layering {
    /// One sub-layer per unit, prisms, compass sides.
    ///
    /// ```
    /// let l = terramesh_geology::Layering::new(vec!["a".into()]);
    /// assert_eq!(l.layers, [1]);
    /// ```
    pub fn new(units: Vec<String>) -> Self {
        Layering {
            layers: vec![1; units.len()],
            units,
            element: Element::default(),
            sides: SideTags::default(),
        }
    }

    /// Sets the sub-layers per unit.
    ///
    /// ```
    /// let l = terramesh_geology::Layering::new(vec!["a".into()]).layers(vec![3]);
    /// assert_eq!(l.layers, [3]);
    /// ```
    pub fn layers(mut self, layers: Vec<usize>) -> Self {
        self.layers = layers;
        self
    }

    /// Sets the element.
    ///
    /// ```
    /// use terramesh_core::volume::Element;
    /// let l = terramesh_geology::Layering::new(vec!["a".into()]).element(Element::Tetra);
    /// assert_eq!(l.element, Element::Tetra);
    /// ```
    pub fn element(mut self, element: Element) -> Self {
        self.element = element;
        self
    }

    /// Sets the side tags.
    ///
    /// ```
    /// use terramesh_geology::{Layering, SideTags};
    /// let l = Layering::new(vec!["a".into()]).sides(SideTags::Compass);
    /// assert_eq!(l.sides, SideTags::Compass);
    /// ```
    pub fn sides(mut self, sides: SideTags) -> Self {
        self.sides = sides;
        self
    }
}

fn validate(planar: &Planar, stack: &Stack, layering: &Layering) -> Result<(), GeologyError> {
    let units = layering.units.len();
    let length = |what: String, got, expected, why| GeologyError::Length {
        what,
        expected,
        got,
        why,
    };
    if units == 0 {
        return Err(length("the units".into(), 0, 1, "at least one unit"));
    }
    if stack.units() != units {
        return Err(length(
            "the stack's surfaces".into(),
            stack.surfaces.len(),
            units + 1,
            "the terrain, the top of every unit below the first, and the base",
        ));
    }
    if layering.layers.len() != units {
        return Err(length(
            "layers".into(),
            layering.layers.len(),
            units,
            "one count of sub-layers per unit",
        ));
    }
    if let Some(u) = layering.layers.iter().position(|&l| l == 0) {
        return Err(GeologyError::Setting {
            name: format!("layers of unit {}", layering.units[u]),
            value: 0.0,
            why: "must be at least 1",
        });
    }
    let n = planar.points.len();
    for (k, s) in stack.surfaces.iter().enumerate() {
        if s.len() != n {
            return Err(length(
                format!("surface {k} of the stack"),
                s.len(),
                n,
                "one value per planar vertex",
            ));
        }
        for (v, &z) in s.iter().enumerate() {
            let above = if k == 0 {
                f64::INFINITY
            } else {
                stack.surfaces[k - 1][v]
            };
            if !(z.is_finite() && z <= above) {
                let [x, y] = planar.points[v];
                return Err(GeologyError::NonFinite {
                    surface: format!(
                        "surface {k} of the stack (not finite or above the one above it; \
                         repair the surfaces with apply_rules)"
                    ),
                    vertex: v,
                    x,
                    y,
                    value: z,
                });
            }
        }
    }
    Ok(())
}

/// What one chunk of planar triangles contributes; cell indices local to the chunk.
#[derive(Default)]
struct Chunk {
    cells: Vec<Cell>,
    material: Vec<i32>,
    faces: Vec<TaggedFace>,
}

/// Builds the volume mesh of the repaired surfaces on the planar mesh: nodes, cells (module
/// documentation of `terramesh_core::volume` for their node order), tagged faces and the
/// sealed bodies.
///
/// Tags, in this order, those that have faces: `top`, `bottom`, the sides ([`SideTags`]), and
/// `Interface(unit)` for every unit below the first whose top touches another unit's cells.
/// An interface face belongs to the cell below it and points up (out of that cell).
///
/// ```
/// use terramesh_core::volume::{CellKind, Element};
/// use terramesh_geology::{volume_mesh, Layering, Planar, Stack};
/// let points = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
/// let planar = Planar::new(&points, &[[0, 1, 2]])?;
/// // The lower unit pinches out at vertex 2: a pyramid under a wedge.
/// let stack = Stack { surfaces: vec![vec![10.0; 3], vec![5.0, 5.0, 0.0], vec![0.0; 3]] };
/// let mesh = volume_mesh(&planar, &stack, &Layering::new(vec!["a".into(), "b".into()]))?;
/// assert_eq!(mesh.cells.iter().map(|c| c.kind).collect::<Vec<_>>(), [CellKind::Wedge, CellKind::Pyramid]);
/// assert_eq!(mesh.points.len(), 8); // vertex 2 has two nodes, the others three
/// let tets = volume_mesh(&planar, &stack, &Layering::new(vec!["a".into(), "b".into()]).element(Element::Tetra))?;
/// assert_eq!(tets.cells.len(), 5);
/// # Ok::<(), terramesh_geology::GeologyError>(())
/// ```
///
/// # Errors
/// [`GeologyError::Length`] or [`GeologyError::Setting`] when the layering does not fit the
/// stack, [`GeologyError::NonFinite`] for a surface that is not finite or rises above the one
/// above it (repair it with [`crate::apply_rules`]), [`GeologyError::TooLarge`] beyond 32-bit
/// indices.
pub fn volume_mesh(
    planar: &Planar,
    stack: &Stack,
    layering: &Layering,
) -> Result<VolumeMesh, GeologyError> {
    validate(planar, stack, layering)?;
    let cols = Columns::build(planar, stack, &layering.layers)?;
    let boundary = planar.boundary_edges();
    let (side_of, side_names) = classify(planar, &boundary, layering.sides);
    // Per triangle and local edge: 1 + its side index, 0 inside.
    let mut edge_side = vec![[0u32; 3]; planar.triangles.len()];
    for (&(t, k), &s) in boundary.iter().zip(&side_of) {
        edge_side[t as usize][k as usize] = s as u32 + 1;
    }
    let units = layering.units.len();
    let tag_side = 2;
    let tag_interface = tag_side + side_names.len(); // + unit - 1
    let tetra = layering.element == Element::Tetra;
    const CHUNK: usize = 2048;
    let chunks: Vec<Chunk> = planar
        .triangles
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, tris)| {
            let mut out = Chunk::default();
            for (i, tri) in tris.iter().enumerate() {
                let t = c * CHUNK + i;
                column(&cols, tri, &edge_side[t], tetra, tag_interface, &mut out);
            }
            out
        })
        .collect();
    let total: usize = chunks.iter().map(|c| c.cells.len()).sum();
    if total >= u32::MAX as usize {
        return Err(GeologyError::TooLarge {
            what: "cells",
            count: total,
        });
    }
    let mut mesh = VolumeMesh {
        cells: Vec::with_capacity(total),
        material: Vec::with_capacity(total),
        units: layering.units.clone(),
        ..Default::default()
    };
    for mut chunk in chunks {
        let offset = mesh.cells.len() as u32;
        for f in &mut chunk.faces {
            f.cell += offset;
        }
        mesh.cells.append(&mut chunk.cells);
        mesh.material.append(&mut chunk.material);
        mesh.faces.append(&mut chunk.faces);
    }
    // The tags, compacted to those in use.
    let mut all = vec![FaceTag::Top, FaceTag::Bottom];
    all.extend(side_names.into_iter().map(FaceTag::Side));
    all.extend(
        layering.units[1..units]
            .iter()
            .map(|u| FaceTag::Interface(u.clone())),
    );
    let mut used = vec![false; all.len()];
    for f in &mesh.faces {
        used[f.tag as usize] = true;
    }
    let mut remap = vec![0u16; all.len()];
    for (i, tag) in all.into_iter().enumerate() {
        if used[i] {
            remap[i] = mesh.tags.len() as u16;
            mesh.tags.push(tag);
        }
    }
    for f in &mut mesh.faces {
        f.tag = remap[f.tag as usize];
    }
    mesh.bodies = bodies::bodies(planar, &cols, &boundary);
    mesh.points = cols.points;
    Ok(mesh)
}

/// The cells and tagged faces of the column over one planar triangle.
fn column(
    cols: &Columns,
    tri: &[u32; 3],
    edge_side: &[u32; 3],
    tetra: bool,
    tag_interface: usize,
    out: &mut Chunk,
) {
    const NONE: u32 = u32::MAX;
    let at = |level: usize| tri.map(|v| cols.node(v, level));
    let mut previous_unit = None;
    let mut last: Option<(usize, usize, [u32; 3])> = None; // cells range, lower nodes
    for s in 0..cols.levels - 1 {
        let (up, lo) = (at(s), at(s + 1));
        let Some(cell) = prismatic(up, lo) else {
            continue;
        };
        let unit = cols.unit_of_layer[s];
        let first = out.cells.len();
        emit(&cols.points, cell, tetra, &mut out.cells);
        let emitted = first..out.cells.len();
        out.material.resize(out.cells.len(), unit as i32);
        let face = |nodes: [u32; 4], tag: usize, out: &mut Chunk| {
            let used = if nodes[3] == NONE { 3 } else { 4 };
            let owner = emitted
                .clone()
                .find(|&c| {
                    nodes[..used]
                        .iter()
                        .all(|n| out.cells[c].used().contains(n))
                })
                .expect("every face of a cell belongs to one of its tetrahedra");
            out.faces.push(TaggedFace {
                nodes,
                cell: owner as u32,
                tag: tag as u16,
            });
        };
        match previous_unit {
            None => face([up[0], up[1], up[2], NONE], 0, out),
            Some(p) if p != unit => {
                face([up[0], up[1], up[2], NONE], tag_interface + unit - 1, out)
            }
            _ => {}
        }
        for (k, &side) in edge_side.iter().enumerate() {
            if side == 0 {
                continue;
            }
            let (a, b) = (k, (k + 1) % 3);
            let Some(f) = side_face(up[a], up[b], lo[a], lo[b]) else {
                continue;
            };
            let tag = 1 + side as usize; // 2 + side index
            if tetra && f[3] != NONE {
                for t in split_quad(f) {
                    face([t[0], t[1], t[2], NONE], tag, out);
                }
            } else {
                face(f, tag, out);
            }
        }
        previous_unit = Some(unit);
        last = Some((emitted.start, emitted.end, lo));
    }
    if let Some((start, end, lo)) = last {
        let nodes = [lo[2], lo[1], lo[0]];
        let owner = (start..end)
            .find(|&c| nodes.iter().all(|n| out.cells[c].used().contains(n)))
            .expect("the bottom face belongs to one of the lowest cell's tetrahedra");
        out.faces.push(TaggedFace {
            nodes: [nodes[0], nodes[1], nodes[2], NONE],
            cell: owner as u32,
            tag: 1,
        });
    }
}
