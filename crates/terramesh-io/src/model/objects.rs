//! What a model with engineering objects (issue 32: tunnels, excavations, structures) adds to
//! its [`VolumeMesh`] ([`ObjectData`]): the object and the lining flag of every cell, from
//! which the writers derive the int32 cell arrays `object` and `excavation_stage` of
//! `model.vtu`, the `MaterialIDs` of a structure's and a lining's cells (after the units),
//! the objects' volume groups (`tunnel-<name>`, `excavation-<name>`, `structure-<name>`,
//! `lining-<name>`), their boundaries (faces between a cell of the group and a cell not of
//! it, and the group's faces on the model's outer boundary) and the files
//! `object-<name>.vtu` ([`object_mesh`]) and `object-<name>.ts` ([`write_object_tsurf`]).
//!
//! Faces are matched by their points' coordinates, so that split fault nodes (two copies at
//! one place) still make one face of two cells.

use std::io::{self, Write};

use rayon::prelude::*;
use terramesh_core::volume::{Body, CellKind, FaceTag, VolumeMesh};

use super::boundary::BoundaryMesh;
use super::faces::{cell_faces, compact_nodes};
use super::faults::{side_nodes, side_triangles, FaceSide, FaultData, FaultGroup};
use super::{ogs_face_index, MeshError, ModelInfo};
use crate::export::tsurf::write_tsurf_with;
use crate::export::TsurfInfo;

/// What an engineering object is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObjectKind {
    /// A tunnel (`[[geology.tunnels]]`).
    Tunnel,
    /// An excavation (`[[geology.excavations]]`).
    Excavation,
    /// A structure (`[[geology.structures]]`): its cells get a material of their own.
    Structure,
}

impl ObjectKind {
    /// `tunnel`, `excavation` or `structure`: the prefix of the object's group names.
    pub fn word(self) -> &'static str {
        match self {
            ObjectKind::Tunnel => "tunnel",
            ObjectKind::Excavation => "excavation",
            ObjectKind::Structure => "structure",
        }
    }
}

/// One engineering object as the writers name it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModelObject {
    /// Its name (files `object-<name>.vtu`, `.ts`; groups `<kind>-<name>`).
    pub name: String,
    /// What it is.
    pub kind: ObjectKind,
    /// Its excavation stage (1 = first; 0: never excavated, a structure).
    pub stage: u32,
    /// A structure's material (its `MaterialIDs` name).
    pub material: Option<String>,
    /// Whether it is a tunnel with a lining (then the material and group `lining-<name>`).
    pub lining: bool,
}

impl ModelObject {
    /// The group of its cells (lining excluded): `<kind>-<name>`.
    pub fn group_name(&self) -> String {
        format!("{}-{}", self.kind.word(), self.name)
    }
}

/// The materials after the units, in this order: each distinct structure material (in the
/// order of the structures), then `lining-<name>` per tunnel with a lining. `MaterialIDs`
/// `units + k` is material `k`.
///
/// ```
/// use terramesh_io::model::{extra_materials, ModelObject, ObjectKind};
/// let o = |name: &str, kind, material: Option<&str>, lining| ModelObject {
///     name: name.into(), kind, stage: 0, material: material.map(String::from), lining };
/// let objects = [o("t", ObjectKind::Tunnel, None, true), o("dam", ObjectKind::Structure, Some("concrete"), false),
///     o("wall", ObjectKind::Structure, Some("concrete"), false)];
/// assert_eq!(extra_materials(&objects), ["concrete", "lining-t"]);
/// ```
pub fn extra_materials(objects: &[ModelObject]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for o in objects {
        if let (ObjectKind::Structure, Some(m)) = (o.kind, &o.material) {
            if !out.contains(m) {
                out.push(m.clone());
            }
        }
    }
    for o in objects.iter().filter(|o| o.lining) {
        out.push(format!("lining-{}", o.name));
    }
    out
}

/// The engineering objects of a model and the labels of its cells (see the module
/// documentation).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ObjectData {
    /// The objects in project order: object `k` is number `k + 1` in `object`.
    pub objects: Vec<ModelObject>,
    /// Per cell: 0 for none, else its object's number.
    pub object: Vec<u32>,
    /// Per cell: whether it is in its tunnel's lining.
    pub lining: Vec<bool>,
}

/// One volume group of the objects: its name and which cells it holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjectGroup {
    /// `tunnel-<name>`, `excavation-<name>`, `structure-<name>` or `lining-<name>`.
    pub name: String,
    /// The object's index (0-based).
    pub object: usize,
    /// Whether it is the object's lining.
    pub lining: bool,
}

impl ObjectData {
    /// The volume groups: per object its cells (`<kind>-<name>`), then its lining's
    /// (`lining-<name>`) where it has one.
    pub fn groups(&self) -> Vec<ObjectGroup> {
        let mut out = Vec::new();
        for (k, o) in self.objects.iter().enumerate() {
            out.push(ObjectGroup {
                name: o.group_name(),
                object: k,
                lining: false,
            });
            if o.lining {
                out.push(ObjectGroup {
                    name: format!("lining-{}", o.name),
                    object: k,
                    lining: true,
                });
            }
        }
        out
    }

    /// The group of every cell (an index into [`ObjectData::groups`]), `u32::MAX` for none.
    pub fn cell_groups(&self) -> Vec<u32> {
        let groups = self.groups();
        let first: Vec<u32> = (0..self.objects.len())
            .map(|k| groups.iter().position(|g| g.object == k).unwrap_or(0) as u32)
            .collect();
        self.object
            .iter()
            .zip(&self.lining)
            .map(|(&o, &l)| {
                if o == 0 {
                    u32::MAX
                } else {
                    first[o as usize - 1] + u32::from(l)
                }
            })
            .collect()
    }

    /// Per cell: its excavation stage (0: never excavated: no object, a structure, a lining).
    pub fn excavation_stage(&self) -> Vec<i32> {
        self.object
            .iter()
            .zip(&self.lining)
            .map(|(&o, &l)| {
                if o == 0 || l {
                    0
                } else {
                    self.objects[o as usize - 1].stage as i32
                }
            })
            .collect()
    }

    /// Per cell: its `MaterialIDs`: `material` (its unit) but for a structure's cells and a
    /// lining's, which take `units + k` for their material `k` of [`extra_materials`].
    pub fn material_ids(&self, material: &[i32], units: usize) -> Vec<i32> {
        let extra = extra_materials(&self.objects);
        let id = |name: &str| (units + extra.iter().position(|m| m == name).unwrap_or(0)) as i32;
        let of_object: Vec<Option<i32>> = self
            .objects
            .iter()
            .map(|o| match (o.kind, &o.material) {
                (ObjectKind::Structure, Some(m)) => Some(id(m)),
                _ => None,
            })
            .collect();
        let of_lining: Vec<i32> = self
            .objects
            .iter()
            .map(|o| id(&format!("lining-{}", o.name)))
            .collect();
        material
            .iter()
            .zip(self.object.iter().zip(&self.lining))
            .map(|(&m, (&o, &l))| match (o, l) {
                (0, _) => m,
                (o, true) => of_lining[o as usize - 1],
                (o, false) => of_object[o as usize - 1].unwrap_or(m),
            })
            .collect()
    }
}

/// Checks what the writers rely on in [`ObjectData`] (after [`super::check_mesh`] and
/// [`super::check_faults`]): one label per cell, object numbers within the objects, linings
/// only in tunnels with one, names usable in file and group names and distinct (the groups
/// from each other, from the units' and blocks' names and the face groups).
///
/// ```
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::{check_objects, MeshError, ModelObject, ObjectData, ObjectKind};
/// let m = VolumeMesh { points: vec![[0.0; 3]; 4], cells: vec![Cell::tetra([0, 1, 2, 3])],
///     material: vec![0], units: vec!["sand".into()], ..Default::default() };
/// let mut d = ObjectData { objects: vec![ModelObject { name: "pit".into(), kind: ObjectKind::Excavation,
///     stage: 1, material: None, lining: false }], object: vec![1], lining: vec![false] };
/// assert!(check_objects(&m, None, &d).is_ok());
/// d.object[0] = 2;
/// assert!(matches!(check_objects(&m, None, &d), Err(MeshError::ObjectLabel { cell: 0, .. })));
/// ```
pub fn check_objects(
    m: &VolumeMesh,
    faults: Option<&FaultData>,
    d: &ObjectData,
) -> Result<(), MeshError> {
    if d.object.len() != m.cells.len() || d.lining.len() != m.cells.len() {
        return Err(MeshError::ObjectCount {
            cells: m.cells.len(),
            labels: d.object.len().min(d.lining.len()),
        });
    }
    for (cell, (&o, &l)) in d.object.iter().zip(&d.lining).enumerate() {
        let bad =
            o as usize > d.objects.len() || (l && (o == 0 || !d.objects[o as usize - 1].lining));
        if bad {
            return Err(MeshError::ObjectLabel {
                cell,
                object: o,
                lining: l,
                objects: d.objects.len(),
            });
        }
    }
    let groups = d.groups();
    let mut names: Vec<String> = m.units.clone();
    names.extend(extra_materials(&d.objects));
    for o in &d.objects {
        if terramesh_core::names::check_name(&o.name).is_err() {
            return Err(MeshError::Name {
                name: o.name.clone(),
            });
        }
    }
    let dup = |names: &[String], what: &str| -> Result<(), MeshError> {
        match terramesh_core::names::same_file_name(names) {
            Some((i, j)) => Err(MeshError::Duplicate {
                what: what.to_string(),
                first: names[i].clone(),
                second: names[j].clone(),
            }),
            None => Ok(()),
        }
    };
    dup(&names, "materials")?;
    // the zone groups: materials (slot 1), blocks, the objects' groups, the stages
    if let Some(f) = faults {
        names.extend(f.blocks.iter().cloned());
    }
    names.extend(groups.iter().filter(|g| !g.lining).map(|g| g.name.clone()));
    names.extend(stages(d).iter().map(|s| format!("stage-{s}")));
    dup(&names, "zone groups")?;
    let mut faces: Vec<String> = m.tags.iter().map(FaceTag::name).collect();
    if let Some(f) = faults {
        faces.extend((0..f.faults.len()).map(|i| f.group_name(i)));
    }
    faces.extend(groups.iter().map(|g| format!("{}-boundary", g.name)));
    dup(&faces, "face groups")?;
    let objects: Vec<String> = d.objects.iter().map(|o| o.name.clone()).collect();
    dup(&objects, "objects")
}

/// The excavation stages that have cells, increasing.
pub(super) fn stages(d: &ObjectData) -> Vec<u32> {
    let mut s: Vec<u32> = d
        .excavation_stage()
        .into_iter()
        .filter(|&s| s > 0)
        .map(|s| s as u32)
        .collect();
    s.sort_unstable();
    s.dedup();
    s
}

/// The boundary faces of every group of [`ObjectData::groups`], each as the side of its
/// group's cell (counter-clockwise seen from outside the group): the faces between a cell of
/// the group and a cell not of it, and the group's faces on the model's outer boundary (a
/// portal), in increasing cell and face.
///
/// # Panics
/// On what [`check_objects`] rejects.
pub fn object_boundaries(m: &VolumeMesh, d: &ObjectData) -> Vec<Vec<FaceSide>> {
    let cell_group = d.cell_groups();
    // the objects' bounding box: a neighbour has at least three points in it
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for (c, &g) in cell_group.iter().enumerate() {
        if g != u32::MAX {
            for &n in m.cells[c].used() {
                let p = m.points[n as usize];
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
    }
    if lo[0] > hi[0] {
        return vec![Vec::new(); d.groups().len()];
    }
    let inside = |p: [f64; 3]| (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k]);
    let canon = &canonical_points(m);
    // every face of the cells near the objects (a neighbour has three points in their box),
    // by its points, sorted
    let mut sides: Vec<([u32; 4], u32, u8)> = (0..m.cells.len())
        .into_par_iter()
        .filter(|&c| {
            let near = m.cells[c]
                .used()
                .iter()
                .filter(|&&n| inside(m.points[n as usize]))
                .count();
            near >= 3
        })
        .flat_map_iter(|c| {
            (0..cell_faces(m.cells[c].kind).len())
                .map(move |f| (face_key(m, canon, c, f), c as u32, f as u8))
        })
        .collect();
    sides.par_sort_unstable();
    boundaries_of(d, &sides)
}

/// Every face of `m`'s cells by its points' canonical ids (split fault nodes share one),
/// sorted: what [`material_bodies`] and [`boundaries_of`] read.
pub(super) fn all_sides(m: &VolumeMesh) -> Vec<([u32; 4], u32, u8)> {
    sides_by(m, &canonical_points(m))
}

/// Whether `faces` ([`super::MeshFaces`], every face of `m`'s tetrahedra by its node ids,
/// sorted) are what [`all_sides`] would sort: every cell a tetrahedron, a face per cell and
/// side, and every point its own canonical id (no two points at the same coordinates), so
/// that node ids and canonical ids sort alike. Else [`all_sides`] is what the writers read.
pub(super) fn faces_are_sides(m: &VolumeMesh, faces: &[([u32; 3], u32, u8)]) -> bool {
    faces.len() == 4 * m.cells.len()
        && m.cells.par_iter().all(|c| c.kind == CellKind::Tetra)
        && canonical_points(m)
            .par_iter()
            .enumerate()
            .all(|(i, &c)| c as usize == i)
}

fn sides_by(m: &VolumeMesh, canon: &[u32]) -> Vec<([u32; 4], u32, u8)> {
    let mut sides: Vec<([u32; 4], u32, u8)> = (0..m.cells.len())
        .into_par_iter()
        .flat_map_iter(|c| {
            (0..cell_faces(m.cells[c].kind).len())
                .map(move |f| (face_key(m, canon, c, f), c as u32, f as u8))
        })
        .collect();
    sides.par_sort_unstable();
    sides
}

/// [`object_boundaries`] from `sides`, the sorted faces of the cells near the objects (at
/// least those with three points in the objects' bounding box) or of all cells
/// ([`all_sides`]): the same boundaries either way, since every cell that shares a face with
/// an object's cell has that face's three points in the box.
pub(super) fn boundaries_of<K: PartialEq + Sync>(
    d: &ObjectData,
    sides: &[(K, u32, u8)],
) -> Vec<Vec<FaceSide>> {
    let cell_group = d.cell_groups();
    let mut out = vec![Vec::new(); d.groups().len()];
    for group in sides.chunk_by(|a, b| a.0 == b.0) {
        for &(_, c, f) in group {
            let g = cell_group[c as usize];
            if g == u32::MAX {
                continue;
            }
            if !group
                .iter()
                .any(|&(_, d, _)| d != c && cell_group[d as usize] == g)
            {
                out[g as usize].push(FaceSide { cell: c, face: f });
            }
        }
    }
    for faces in &mut out {
        faces.sort_unstable_by_key(|s| (s.cell, s.face));
    }
    out
}

/// The boundary of object `object` (its cells, lining excluded) as an OpenGeoSys boundary mesh
/// (`object-<name>.vtu`): its faces counter-clockwise seen from outside the object, as
/// `ExtractBoundary` writes them (`bulk_node_ids`, `bulk_element_ids`: the object's cell,
/// `bulk_face_ids`, `MaterialIDs`: `materials[cell]`); `boundary` is its group's faces of
/// [`object_boundaries`].
pub fn object_mesh(m: &VolumeMesh, materials: &[i32], boundary: &[FaceSide]) -> BoundaryMesh {
    let (nodes, local) = compact_nodes(
        m.points.len(),
        boundary.iter().flat_map(|s| side_nodes(m, *s)),
    );
    let mut out = BoundaryMesh {
        points: nodes.iter().map(|&n| m.points[n as usize]).collect(),
        bulk_node_ids: nodes.iter().map(|&n| n as u64).collect(),
        ..Default::default()
    };
    for s in boundary {
        let c = &m.cells[s.cell as usize];
        out.faces.push(
            side_nodes(m, *s)
                .iter()
                .map(|&n| local[n as usize])
                .collect(),
        );
        out.bulk_element_ids.push(u64::from(s.cell));
        out.bulk_face_ids
            .push(ogs_face_index(c.kind, s.face as usize));
        out.material_ids.push(materials[s.cell as usize]);
    }
    out
}

/// Writes an object's boundary faces (those of [`object_mesh`]) as GOCAD TSurf
/// (`object-<name>.ts`): triangles facing out of the object (quadrilaterals split in two) over
/// their own vertices in increasing index of [`VolumeMesh::points`]; the object name is
/// `name`.
pub fn write_object_tsurf<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    boundary: &[FaceSide],
    name: &str,
    info: &ModelInfo,
) -> io::Result<()> {
    let (nodes, tris) = side_triangles(m, boundary.iter().copied());
    write_tsurf_with(
        w,
        nodes.len(),
        |s, i| {
            for c in m.points[nodes[i] as usize] {
                s.byte(b' ')?;
                s.f64(if c == 0.0 { 0.0 } else { c })?;
            }
            Ok(())
        },
        &tris,
        &TsurfInfo {
            name,
            crs_name: &info.crs,
        },
    )
}

/// What the Gmsh and FLAC3D writers add for the objects: the group of every cell, the groups'
/// names (lining groups are the lining materials' groups already), the stages, and the
/// boundaries as face groups (after the faults').
pub(super) struct ObjectExtra {
    /// Per cell: its group, `u32::MAX` for none.
    pub(super) cell_group: Vec<u32>,
    /// The groups' names and whether each is a lining.
    pub(super) groups: Vec<(String, bool)>,
    /// Per cell: its excavation stage.
    pub(super) stage: Vec<i32>,
    /// The stages with cells, increasing.
    pub(super) stages: Vec<u32>,
}

impl ObjectExtra {
    pub(super) fn new(d: &ObjectData) -> ObjectExtra {
        ObjectExtra {
            cell_group: d.cell_groups(),
            groups: d.groups().into_iter().map(|g| (g.name, g.lining)).collect(),
            stage: d.excavation_stage(),
            stages: stages(d),
        }
    }
}

/// The boundaries of the groups as face groups `<group>-boundary` for `model.msh` and
/// `model.f3grid`, in FLAC3D slots 2, 3, ... (one per boundary: boundaries share faces with
/// each other and with the model's faces, and a face is in one group per slot).
pub(super) fn boundary_groups(
    m: &VolumeMesh,
    d: &ObjectData,
    boundaries: &[Vec<FaceSide>],
) -> Vec<FaultGroup> {
    d.groups()
        .iter()
        .zip(boundaries)
        .enumerate()
        .map(|(g, (group, faces))| {
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            let faces = faces
                .iter()
                .map(|s| {
                    let mut a = [u32::MAX; 4];
                    for (k, &v) in side_nodes(m, *s).iter().enumerate() {
                        a[k] = v;
                        let p = m.points[v as usize];
                        for d in 0..3 {
                            lo[d] = lo[d].min(p[d]);
                            hi[d] = hi[d].max(p[d]);
                        }
                    }
                    a
                })
                .collect();
            FaultGroup {
                name: format!("{}-boundary", group.name),
                faces,
                lo,
                hi,
                slot: 2 + g as u32,
            }
        })
        .collect()
}

/// The sealed body of every material of `m` (its units and the objects' materials after
/// them): the faces of a material's cells whose other side (matched by the points'
/// coordinates, so split fault nodes make one face) is of another material or none, each
/// counter-clockwise seen from outside its cell (quadrilaterals split in two); bodies without
/// faces left out. What `unit-<name>.ts` and `.stl` hold for a model with objects, whose
/// structures and linings take their cells out of the units.
/// `sides` are all faces of `m`'s cells, sorted ([`all_sides`]).
pub(super) fn material_bodies<K: PartialEq>(m: &VolumeMesh, sides: &[(K, u32, u8)]) -> Vec<Body> {
    let mut bodies: Vec<Body> = (0..m.units.len())
        .map(|unit| Body {
            unit,
            triangles: vec![],
        })
        .collect();
    for group in sides.chunk_by(|a, b| a.0 == b.0) {
        for &(_, c, f) in group {
            let mat = m.material[c as usize];
            if group
                .iter()
                .all(|&(_, d, _)| d == c || m.material[d as usize] != mat)
            {
                let cell = &m.cells[c as usize];
                let n: Vec<u32> = cell_faces(cell.kind)[f as usize]
                    .iter()
                    .map(|&i| cell.used()[i])
                    .collect();
                for k in 1..n.len() - 1 {
                    bodies[mat as usize].triangles.push([n[0], n[k], n[k + 1]]);
                }
            }
        }
    }
    bodies.retain(|b| !b.triangles.is_empty());
    bodies
}

/// Per point: the smallest index of a point at the same coordinates (split fault nodes share
/// one).
fn canonical_points(m: &VolumeMesh) -> Vec<u32> {
    let mut order: Vec<u32> = (0..m.points.len() as u32).collect();
    let bits = |i: u32| m.points[i as usize].map(|v| (v + 0.0).to_bits());
    order.par_sort_unstable_by_key(|&i| (bits(i), i));
    let mut canon = vec![0u32; m.points.len()];
    for w in 0..order.len() {
        canon[order[w] as usize] = if w > 0 && bits(order[w]) == bits(order[w - 1]) {
            canon[order[w - 1] as usize]
        } else {
            order[w]
        };
    }
    canon
}

/// Face `f` of cell `c` by its points' canonical ids, sorted (`u32::MAX` after a triangle's).
fn face_key(m: &VolumeMesh, canon: &[u32], c: usize, f: usize) -> [u32; 4] {
    let cell = &m.cells[c];
    let mut k = [u32::MAX; 4];
    for (j, &i) in cell_faces(cell.kind)[f].iter().enumerate() {
        k[j] = canon[cell.used()[i] as usize];
    }
    k.sort_unstable();
    k
}

#[cfg(test)]
mod tests {
    use super::*;
    use terramesh_core::volume::Cell;

    /// Three unit cubes in a row along x (six tetrahedra each, Kuhn), a point of the last
    /// one copied (as split fault nodes are) into one of its cells; the objects in cells of
    /// the first cube. The boundaries from every face sorted once ([`all_sides`], as
    /// `write_object_model` finds them) are those of [`object_boundaries`] (the faces near
    /// the objects only), and nonempty.
    #[test]
    fn boundaries_from_all_faces_are_those_from_the_faces_near_the_objects() {
        let mut points: Vec<[f64; 3]> = Vec::new();
        for x in 0..4 {
            for i in 0..4 {
                points.push([x as f64, (i & 1) as f64, ((i >> 1) & 1) as f64]);
            }
        }
        // corner (dx, dy, dz) of cube x
        let id = |x: u32, d: u32| (x + (d & 1)) * 4 + ((d >> 1) & 1) + ((d >> 2) & 1) * 2;
        let kuhn = [
            [0, 1, 3, 7],
            [0, 1, 5, 7],
            [0, 2, 3, 7],
            [0, 2, 6, 7],
            [0, 4, 5, 7],
            [0, 4, 6, 7],
        ];
        let mut cells = Vec::new();
        for x in 0..3 {
            for t in kuhn {
                cells.push(Cell::tetra(t.map(|d| id(x, d))));
            }
        }
        // a split copy of the last cube's far corner, used by its last cell
        points.push(points[id(2, 7) as usize]);
        let copy = points.len() as u32 - 1;
        let last = cells.len() - 1;
        cells[last] = Cell::tetra(kuhn[5].map(|d| if d == 7 { copy } else { id(2, d) }));
        let n = cells.len();
        let m = VolumeMesh {
            points,
            cells,
            material: vec![0; n],
            units: vec!["sand".into()],
            ..Default::default()
        };
        let mut object = vec![0; n];
        let mut lining = vec![false; n];
        object[..4].copy_from_slice(&[1, 1, 1, 2]);
        lining[2] = true;
        let d = ObjectData {
            objects: vec![
                ModelObject {
                    name: "t".into(),
                    kind: ObjectKind::Tunnel,
                    stage: 1,
                    material: None,
                    lining: true,
                },
                ModelObject {
                    name: "pit".into(),
                    kind: ObjectKind::Excavation,
                    stage: 2,
                    material: None,
                    lining: false,
                },
            ],
            object,
            lining,
        };
        let near = object_boundaries(&m, &d);
        let all = boundaries_of(&d, &all_sides(&m));
        assert_eq!(near.len(), 3);
        assert!(near.iter().all(|b| !b.is_empty()), "{near:?}");
        assert_eq!(near, all);
    }
}
