//! The merged geological model read in passes over the tiles ([`TiledModel`]), in the
//! numbering of `model.vtu` (a seam column once, the cells tile by tile): what the merge
//! writes `model.msh` and `model.f3grid` from (`terramesh_io::model::ModelPasses`, one tile in
//! memory at a time), and each boundary mesh and body gathered on its own.
//!
//! A first pass ([`TiledModel::prepare`]) numbers every tile's cells and finds the faces and
//! body triangles that two tiles have: the side faces on a seam, interior in the merged model
//! (both tiles cut a seam's faces the same way, so they have the same nodes). Only those are
//! hashed (by their sorted global nodes): a few per metre of seam. A side face or body
//! triangle over a seam edge of its tile that no other tile has fails the merge with its
//! place: the seam would be open.

use std::collections::{HashMap, HashSet};
use std::io;
use std::path::Path;

use terramesh_core::volume::{Body, Cell, FaceTag, TaggedFace, VolumeMesh};
use terramesh_io::model::{boundary_mesh, BoundaryMesh, CellVisit, FaceVisit, ModelPasses};

use super::files::{read_f64s, read_u32s};
use super::geology::{tag_of_name, GeologyPlan, TileFigures, MODEL_BODIES, MODEL_FACES};
use super::geology::{MODEL_JSON, MODEL_POINTS};
use super::manifest::{tile_dir, Manifest, Tile};
use super::model_columns::{cell_of, columns, key, node_map, read_cells, Column};
use crate::error::{BoundaryProblem, Context, Result, TilesError as Error};

type Key = (u64, u64);

/// What a pass over the faces calls: the face, its points, its cell, the cell's material and
/// points.
type FaceAndCell<'a> =
    dyn FnMut(&TaggedFace, &[[f64; 3]], &Cell, i32, &[[f64; 3]]) -> Result<()> + 'a;

/// The merged model as passes over the tiles (see the module documentation).
pub(super) struct TiledModel<'a> {
    plan: &'a Path,
    m: &'a Manifest,
    seams: &'a HashMap<Key, Column>,
    units: Vec<String>,
    tags: Vec<FaceTag>,
    /// Per tile: its tags' indices in `tags`.
    tag_map: Vec<Vec<u16>>,
    /// Per tile: its first cell in the merged numbering.
    first_cell: Vec<u32>,
    /// Per tile: its faces on a seam (indices in its `model-faces.u32`), dropped.
    dead_faces: Vec<HashSet<u32>>,
    /// Per tile: its body triangles on a seam (indices in its `model-bodies.u32`), dropped.
    dead_triangles: Vec<HashSet<u32>>,
    points: usize,
    cells: usize,
    faces: usize,
    /// Per unit: its body's triangles.
    pub(super) body_triangles: Vec<usize>,
    /// The lowest x and y of the points.
    pub(super) low: [f64; 2],
    /// Side faces dropped (each counted once per tile).
    pub(super) seam_faces_dropped: usize,
    /// Body triangles dropped (each counted once per tile).
    pub(super) seam_triangles_dropped: usize,
}

/// One tile as a pass reads it: its nodes (`x, y, z`), cells (8 `u32` each, empty when not
/// asked for) and their global numbers.
struct Loaded {
    points: Vec<f64>,
    cells: Vec<u32>,
    map: Vec<(u32, bool)>,
}

impl Loaded {
    fn point(&self, n: u32) -> [f64; 3] {
        let i = 3 * n as usize;
        [self.points[i], self.points[i + 1], self.points[i + 2]]
    }
}

fn sorted<const N: usize>(mut a: [u32; N]) -> [u32; N] {
    a.sort_unstable();
    a
}

/// The tags of the merged model in the one-piece order: top, bottom, the sides (north, east,
/// south, west), then the interfaces in unit order; only those some tile has.
fn merged_tags(names: &[Vec<String>], units: &[String]) -> Vec<FaceTag> {
    let mut all = vec![FaceTag::Top, FaceTag::Bottom];
    all.extend(["north", "east", "south", "west"].map(|s| FaceTag::Side(s.into())));
    all.extend(units.iter().skip(1).map(|u| FaceTag::Interface(u.clone())));
    let used: Vec<FaceTag> = names.iter().flatten().map(|n| tag_of_name(n)).collect();
    let mut out: Vec<FaceTag> = all.into_iter().filter(|t| used.contains(t)).collect();
    // Any other (none today): after, in the order met.
    for t in used {
        if !out.contains(&t) {
            out.push(t);
        }
    }
    out
}

/// A seam edge of a tile: two consecutive vertices of one of its seams, in either order.
fn seam_edges(t: &Tile) -> HashSet<[Key; 2]> {
    let mut out = HashSet::new();
    for s in &t.seams {
        for w in s.vertices.windows(2) {
            let (a, b) = (key(w[0][0], w[0][1]), key(w[1][0], w[1][1]));
            out.insert(if a <= b { [a, b] } else { [b, a] });
        }
    }
    out
}

/// What a face or body triangle on seam columns stands over: its two distinct columns, if two.
fn over_edge(l: &Loaded, nodes: &[u32]) -> Option<[Key; 2]> {
    let mut cols: Vec<Key> = nodes
        .iter()
        .map(|&n| {
            let p = l.point(n);
            key(p[0], p[1])
        })
        .collect();
    cols.sort_unstable();
    cols.dedup();
    (cols.len() == 2).then(|| [cols[0], cols[1]])
}

fn io_err(e: Error) -> io::Error {
    io::Error::other(e)
}

impl<'a> TiledModel<'a> {
    /// The first pass: numbers, tags, and the seam faces and triangles to drop.
    pub(super) fn prepare(
        plan: &'a Path,
        m: &'a Manifest,
        gp: &GeologyPlan,
        seams: &'a HashMap<Key, Column>,
    ) -> Result<TiledModel<'a>> {
        let mut names = Vec::with_capacity(m.tiles.len());
        for t in &m.tiles {
            let path = tile_dir(plan, &t.id).join(MODEL_JSON);
            let text = std::fs::read_to_string(&path).at(&path)?;
            let f: TileFigures = serde_json::from_str(&text).at(&path)?;
            names.push(f.tags);
        }
        let tags = merged_tags(&names, &gp.units);
        let tag_map: Vec<Vec<u16>> = names
            .iter()
            .map(|n| {
                n.iter()
                    .map(|n| {
                        let t = tag_of_name(n);
                        tags.iter().position(|x| *x == t).expect("a merged tag") as u16
                    })
                    .collect()
            })
            .collect();
        let nt = m.tiles.len();
        let mut tm = TiledModel {
            plan,
            m,
            seams,
            units: gp.units.clone(),
            tags,
            tag_map,
            first_cell: Vec::with_capacity(nt),
            dead_faces: vec![HashSet::new(); nt],
            dead_triangles: vec![HashSet::new(); nt],
            points: 0,
            cells: 0,
            faces: 0,
            body_triangles: vec![0; gp.units.len()],
            low: [f64::INFINITY; 2],
            seam_faces_dropped: 0,
            seam_triangles_dropped: 0,
        };
        // Faces and triangles on seam columns, by their sorted global nodes: (tile, index,
        // the seam edge they stand over).
        type Seen = (usize, u32, Option<[Key; 2]>);
        let mut side_at: HashMap<[u32; 4], Seen> = HashMap::new();
        let mut tri_at: HashMap<(usize, [u32; 3]), Seen> = HashMap::new();
        let mut edges = Vec::with_capacity(nt);
        let mut next = 0u32;
        for (k, t) in m.tiles.iter().enumerate() {
            let dir = tile_dir(plan, &t.id);
            edges.push(seam_edges(t));
            let l = tm.load(k, t, true, &mut next)?;
            let local_cells = l.cells.len() / 8;
            tm.first_cell.push(tm.cells as u32);
            tm.cells += local_cells;
            for (i, &(_, mine)) in l.map.iter().enumerate() {
                if mine {
                    tm.points += 1;
                    tm.low[0] = tm.low[0].min(l.points[3 * i]);
                    tm.low[1] = tm.low[1].min(l.points[3 * i + 1]);
                }
            }
            let mut seam = Vec::with_capacity(l.map.len());
            for (ck, _, count) in columns(&l.points) {
                seam.extend(std::iter::repeat_n(seams.contains_key(&ck), count));
            }
            let bad = |why: BoundaryProblem| Error::BoundaryMeshes {
                dir: dir.clone(),
                why,
                tile: t.id.clone(),
            };
            let path = dir.join(MODEL_FACES);
            if !path.is_file() {
                return Err(bad(BoundaryProblem::Missing(MODEL_FACES)));
            }
            let map = &tm.tag_map[k];
            for (j, rec) in read_u32s(&path, 6)?.chunks_exact(6).enumerate() {
                let tag = *map.get(rec[5] as usize).ok_or_else(|| {
                    bad(BoundaryProblem::FaceTag {
                        tag: rec[5],
                        tags: map.len(),
                    })
                })?;
                if rec[4] as usize >= local_cells
                    || rec[..4]
                        .iter()
                        .any(|&n| n != u32::MAX && n as usize >= l.map.len())
                {
                    return Err(bad(BoundaryProblem::FaceRange));
                }
                tm.faces += 1;
                let used: Vec<u32> = rec[..4]
                    .iter()
                    .copied()
                    .filter(|&n| n != u32::MAX)
                    .collect();
                if !(used.iter().all(|&n| seam[n as usize])
                    && matches!(tm.tags[tag as usize], FaceTag::Side(_)))
                {
                    continue;
                }
                let mut nodes = [u32::MAX; 4];
                for (g, &n) in nodes.iter_mut().zip(&used) {
                    *g = l.map[n as usize].0;
                }
                match side_at.get(&sorted(nodes)) {
                    Some(&(other, i, _)) if other != k => {
                        tm.dead_faces[other].insert(i);
                        tm.dead_faces[k].insert(j as u32);
                    }
                    _ => {
                        side_at.insert(sorted(nodes), (k, j as u32, over_edge(&l, &used)));
                    }
                }
            }
            let path = dir.join(MODEL_BODIES);
            if !path.is_file() {
                return Err(bad(BoundaryProblem::Missing(MODEL_BODIES)));
            }
            for (j, rec) in read_u32s(&path, 4)?.chunks_exact(4).enumerate() {
                let u = rec[0] as usize;
                if u >= tm.units.len() || rec[1..].iter().any(|&n| n as usize >= l.map.len()) {
                    return Err(bad(BoundaryProblem::TriangleRange));
                }
                tm.body_triangles[u] += 1;
                if !rec[1..].iter().all(|&n| seam[n as usize]) {
                    continue;
                }
                let tri = [rec[1], rec[2], rec[3]].map(|n| l.map[n as usize].0);
                // Keyed by unit too: two units' bodies share their interface triangles.
                let key = (u, sorted(tri));
                match tri_at.get(&key) {
                    Some(&(other, i, _)) if other != k => {
                        tm.dead_triangles[other].insert(i);
                        tm.dead_triangles[k].insert(j as u32);
                        tm.body_triangles[u] -= 2;
                    }
                    _ => {
                        tri_at.insert(key, (k, j as u32, over_edge(&l, &rec[1..])));
                    }
                }
            }
        }
        // What stands over a seam edge of its tile must have met its twin.
        let open = |(k, i, edge): &Seen, dead: &[HashSet<u32>], what: &str| -> Result<()> {
            match edge {
                Some(e) if edges[*k].contains(e) && !dead[*k].contains(i) => {
                    let p = |c: Key| (f64::from_bits(c.0), f64::from_bits(c.1));
                    Err(Error::NoTwin {
                        tile: m.tiles[*k].id.clone(),
                        what: what.to_string(),
                        index: *i,
                        a: p(e[0]),
                        b: p(e[1]),
                    })
                }
                _ => Ok(()),
            }
        };
        for s in side_at.values() {
            open(s, &tm.dead_faces, "side face")?;
        }
        for s in tri_at.values() {
            open(s, &tm.dead_triangles, "body triangle")?;
        }
        tm.seam_faces_dropped = tm.dead_faces.iter().map(HashSet::len).sum();
        tm.seam_triangles_dropped = tm.dead_triangles.iter().map(HashSet::len).sum();
        tm.faces -= tm.seam_faces_dropped;
        Ok(tm)
    }

    /// Tile `k`'s nodes (and cells when `cells`), numbered after `next`.
    fn load(&self, k: usize, t: &Tile, cells: bool, next: &mut u32) -> Result<Loaded> {
        let dir = tile_dir(self.plan, &t.id);
        let points = read_f64s(&dir.join(MODEL_POINTS), 3)?;
        let cells = if cells {
            read_cells(&dir, &t.id, points.len() / 3)?
        } else {
            Vec::new()
        };
        let map = node_map(k, &points, self.seams, next);
        Ok(Loaded { points, cells, map })
    }

    /// One pass: every tile loaded in order.
    fn pass(
        &self,
        cells: bool,
        f: &mut dyn FnMut(usize, &Tile, &Loaded) -> Result<()>,
    ) -> Result<()> {
        let mut next = 0u32;
        for (k, t) in self.m.tiles.iter().enumerate() {
            let l = self.load(k, t, cells, &mut next)?;
            f(k, t, &l)?;
        }
        Ok(())
    }

    /// Every kept face of the merged model in order, with its cell, material and the cell's
    /// points when `cells` (otherwise an empty tetrahedron, unit 0, no points: a pass that
    /// reads no cells).
    fn faces_with_cells(&self, cells: bool, f: &mut FaceAndCell) -> Result<()> {
        let none = Cell::tetra([0; 4]);
        self.pass(cells, &mut |k, t, l| {
            let path = tile_dir(self.plan, &t.id).join(MODEL_FACES);
            let (mut fp, mut cp) = ([[0.0; 3]; 4], [[0.0; 3]; 6]);
            for (j, rec) in read_u32s(&path, 6)?.chunks_exact(6).enumerate() {
                if self.dead_faces[k].contains(&(j as u32)) {
                    continue;
                }
                let mut nodes = [u32::MAX; 4];
                let mut used = 0;
                for (g, &n) in nodes.iter_mut().zip(&rec[..4]) {
                    if n != u32::MAX {
                        *g = l.map[n as usize].0;
                        fp[used] = l.point(n);
                        used += 1;
                    }
                }
                let face = TaggedFace {
                    nodes,
                    cell: self.first_cell[k] + rec[4],
                    tag: self.tag_map[k][rec[5] as usize],
                };
                if !cells {
                    f(&face, &fp[..used], &none, 0, &[])?;
                    continue;
                }
                let (mut c, mat) = cell_of(&l.cells[8 * rec[4] as usize..][..8]);
                let kn = c.kind.nodes();
                for (i, n) in c.nodes.iter_mut().take(kn).enumerate() {
                    cp[i] = l.point(*n);
                    *n = l.map[*n as usize].0;
                }
                f(&face, &fp[..used], &c, mat, &cp[..kn])?;
            }
            Ok(())
        })
    }

    /// The tags of the boundary meshes (top, bottom, sides) that have faces, in tag order.
    pub(super) fn boundary_tags(&self) -> Result<Vec<u16>> {
        let mut used = vec![false; self.tags.len()];
        self.each_face(&mut |f, _| {
            used[f.tag as usize] = true;
            Ok(())
        })?;
        Ok((0..self.tags.len())
            .filter(|&t| used[t] && !matches!(self.tags[t], FaceTag::Interface(_)))
            .map(|t| t as u16)
            .collect())
    }

    /// The merged model's tagged faces.
    pub(super) fn face_count_kept(&self) -> usize {
        self.faces
    }

    /// The merged model's tags.
    pub(super) fn tag_list(&self) -> &[FaceTag] {
        &self.tags
    }

    /// The boundary mesh of tag `tag` (`terramesh_io::model::boundary_mesh` of the merged
    /// model), gathered on its own: its faces, their cells and nodes, nothing else.
    pub(super) fn boundary(&self, tag: u16) -> Result<BoundaryMesh> {
        let mut coords: HashMap<u32, [f64; 3]> = HashMap::new();
        let mut faces: Vec<TaggedFace> = Vec::new();
        let mut cells: Vec<(Cell, i32, u32)> = Vec::new();
        self.faces_with_cells(true, &mut |f, _, c, mat, cp| {
            if f.tag == tag {
                for (&n, p) in c.used().iter().zip(cp) {
                    coords.insert(n, *p);
                }
                faces.push(*f);
                cells.push((*c, mat, f.cell));
            }
            Ok(())
        })?;
        let mut ids: Vec<u32> = coords.keys().copied().collect();
        ids.sort_unstable();
        let local = |n: u32| ids.binary_search(&n).expect("a gathered node") as u32;
        let mesh = VolumeMesh {
            points: ids.iter().map(|n| coords[n]).collect(),
            cells: cells
                .iter()
                .map(|(c, _, _)| {
                    let mut c = *c;
                    let kn = c.kind.nodes();
                    for n in c.nodes.iter_mut().take(kn) {
                        *n = local(*n);
                    }
                    c
                })
                .collect(),
            material: cells.iter().map(|c| c.1).collect(),
            units: self.units.clone(),
            faces: faces
                .iter()
                .enumerate()
                .map(|(i, f)| TaggedFace {
                    nodes: f.nodes.map(|n| if n == u32::MAX { n } else { local(n) }),
                    cell: i as u32,
                    tag: 0,
                })
                .collect(),
            tags: vec![self.tags[tag as usize].clone()],
            bodies: Vec::new(),
        };
        let mut b = boundary_mesh(&mesh, 0);
        for n in b.bulk_node_ids.iter_mut() {
            *n = u64::from(ids[*n as usize]);
        }
        for c in b.bulk_element_ids.iter_mut() {
            *c = u64::from(cells[*c as usize].2);
        }
        Ok(b)
    }

    /// The body of unit `u`, gathered on its own: a mesh of its nodes only (in the merged
    /// order) and its triangles.
    pub(super) fn body(&self, u: usize) -> Result<(VolumeMesh, Body)> {
        let mut coords: HashMap<u32, [f64; 3]> = HashMap::new();
        let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(self.body_triangles[u]);
        self.pass(false, &mut |k, t, l| {
            let path = tile_dir(self.plan, &t.id).join(MODEL_BODIES);
            for (j, rec) in read_u32s(&path, 4)?.chunks_exact(4).enumerate() {
                if rec[0] as usize != u || self.dead_triangles[k].contains(&(j as u32)) {
                    continue;
                }
                let tri = [rec[1], rec[2], rec[3]].map(|n| {
                    let g = l.map[n as usize].0;
                    coords.insert(g, l.point(n));
                    g
                });
                triangles.push(tri);
            }
            Ok(())
        })?;
        let mut ids: Vec<u32> = coords.keys().copied().collect();
        ids.sort_unstable();
        let local = |n: u32| ids.binary_search(&n).expect("a gathered node") as u32;
        let mesh = VolumeMesh {
            points: ids.iter().map(|n| coords[n]).collect(),
            units: self.units.clone(),
            ..Default::default()
        };
        let body = Body {
            unit: u,
            triangles: triangles.iter().map(|t| t.map(local)).collect(),
        };
        Ok((mesh, body))
    }
}

impl ModelPasses for TiledModel<'_> {
    fn units(&self) -> &[String] {
        &self.units
    }
    fn tags(&self) -> &[FaceTag] {
        &self.tags
    }
    fn point_count(&self) -> usize {
        self.points
    }
    fn cell_count(&self) -> usize {
        self.cells
    }
    fn face_count(&self) -> usize {
        self.faces
    }
    fn each_point(&self, f: &mut dyn FnMut(&[f64; 3]) -> io::Result<()>) -> io::Result<()> {
        self.pass(false, &mut |_, _, l| {
            for (i, &(_, mine)) in l.map.iter().enumerate() {
                if mine {
                    f(&l.point(i as u32)).map_err(Error::from)?;
                }
            }
            Ok(())
        })
        .map_err(io_err)
    }
    fn each_cell(&self, f: &mut CellVisit) -> io::Result<()> {
        self.pass(true, &mut |_, _, l| {
            let mut pts = [[0.0; 3]; 6];
            for rec in l.cells.chunks_exact(8) {
                let (mut c, mat) = cell_of(rec);
                let kn = c.kind.nodes();
                for (i, n) in c.nodes.iter_mut().take(kn).enumerate() {
                    pts[i] = l.point(*n);
                    *n = l.map[*n as usize].0;
                }
                f(&c, mat, &pts[..kn]).map_err(Error::from)?;
            }
            Ok(())
        })
        .map_err(io_err)
    }
    fn each_face(&self, f: &mut FaceVisit) -> io::Result<()> {
        self.faces_with_cells(false, &mut |face, fp, _, _, _| Ok(f(face, fp)?))
            .map_err(io_err)
    }
}
