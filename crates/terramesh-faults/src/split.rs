//! Split nodes: every node on a fault duplicated, one copy per side, so that a simulator can
//! put interface elements on the faults.

use rayon::prelude::*;
use robust::{orient3d, Coord3D};

use crate::mesh::{all_faces, face_key, outward_faces};
use crate::{FaultError, FaultedMesh};

/// A faulted mesh with its fault nodes split.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SplitMesh {
    /// Nodes: the original ones, then the copies.
    pub points: Vec<[f64; 3]>,
    /// The cells, in the original order, naming their side's copies.
    pub tets: Vec<[u32; 4]>,
    /// The original node of every node.
    pub original: Vec<u32>,
    /// Every fault face twice: `(fault, negative side's triangle, positive side's triangle)`,
    /// each counter-clockwise seen from outside its cell.
    pub fault_faces: Vec<(u32, [u32; 3], [u32; 3])>,
}

struct Dsu(Vec<u32>);
impl Dsu {
    fn find(&mut self, a: u32) -> u32 {
        let mut a = a;
        while self.0[a as usize] != a {
            self.0[a as usize] = self.0[self.0[a as usize] as usize];
            a = self.0[a as usize];
        }
        a
    }
    fn union(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.0[a.max(b) as usize] = a.min(b);
        }
    }
}

/// Splits the nodes on the faults: around every such node, the cells connected through faces
/// that are not fault faces share one copy (so a node on a fault's tip, where the two sides
/// join, is not split; a node where faults cross gets one copy per sector).
///
/// ```
/// # use terramesh_faults::*;
/// let t = Terrain::new(vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]],
///     vec![[0, 1, 2], [0, 2, 3]], vec![100.0; 4])?;
/// let set = FaultSet::new(&[FaultSpec::trace("F1", vec![[40.0, -10.0], [60.0, 110.0]], 80.0, 90.0)], &t, 0.0)?;
/// let mesh = faulted_mesh(&t, &set, 0, &|_, _, _| 0.0, &MeshSettings::new(0.0, 50.0))?;
/// let split = split_nodes(&mesh);
/// assert!(split.points.len() > mesh.points.len());
/// let summary = check_split(&mesh, &split)?;
/// assert_eq!(summary.opened, mesh.fault_faces.len());
/// # Ok::<(), terramesh_faults::FaultError>(())
/// ```
pub fn split_nodes(mesh: &FaultedMesh) -> SplitMesh {
    let mut fkeys: Vec<u128> = mesh
        .fault_faces
        .iter()
        .map(|f| face_key(&f.nodes))
        .collect();
    fkeys.par_sort_unstable();
    fkeys.dedup();
    let mut on = vec![false; mesh.points.len()];
    for f in &mesh.fault_faces {
        for &v in &f.nodes {
            on[v as usize] = true;
        }
    }
    // (node, cell) for every fault node's cells.
    let mut star: Vec<(u32, u32)> = mesh
        .tets
        .par_iter()
        .enumerate()
        .flat_map_iter(|(c, t)| {
            let on = &on;
            t.iter()
                .filter(move |&&v| on[v as usize])
                .map(move |&v| (v, c as u32))
        })
        .collect();
    star.par_sort_unstable();
    let mut groups: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < star.len() {
        let mut j = i;
        while j < star.len() && star[j].0 == star[i].0 {
            j += 1;
        }
        groups.push((i, j));
        i = j;
    }
    // For every entry of `star`, its component's rank around the node (0 keeps the node).
    let ranks: Vec<Vec<u32>> = groups
        .par_iter()
        .map(|&(lo, hi)| {
            let v = star[lo].0;
            let cells = &star[lo..hi];
            let mut faces: Vec<(u128, u32)> = Vec::new();
            for (k, &(_, c)) in cells.iter().enumerate() {
                for f in outward_faces(&mesh.tets[c as usize]) {
                    if f.contains(&v) {
                        faces.push((face_key(&f), k as u32));
                    }
                }
            }
            faces.sort_unstable();
            let mut dsu = Dsu((0..cells.len() as u32).collect());
            for w in faces.windows(2) {
                if w[0].0 == w[1].0 && fkeys.binary_search(&w[0].0).is_err() {
                    dsu.union(w[0].1, w[1].1);
                }
            }
            let mut roots: Vec<u32> = (0..cells.len() as u32).map(|k| dsu.find(k)).collect();
            let mut order: Vec<u32> = roots.clone();
            order.sort_unstable();
            order.dedup();
            for r in &mut roots {
                *r = order.binary_search(r).unwrap() as u32;
            }
            roots
        })
        .collect();
    let mut points = mesh.points.clone();
    let mut original: Vec<u32> = (0..mesh.points.len() as u32).collect();
    let mut tets = mesh.tets.clone();
    for (g, &(lo, _)) in groups.iter().enumerate() {
        let v = star[lo].0;
        let copies = ranks[g].iter().copied().max().unwrap_or(0);
        let first = points.len() as u32;
        for _ in 0..copies {
            points.push(mesh.points[v as usize]);
            original.push(v);
        }
        for (k, &r) in ranks[g].iter().enumerate() {
            if r > 0 {
                let c = star[lo + k].1 as usize;
                for n in &mut tets[c] {
                    if *n == v {
                        *n = first + r - 1;
                    }
                }
            }
        }
    }
    let map = |c: u32, nodes: [u32; 3]| {
        let t = tets[c as usize];
        nodes.map(|v| *t.iter().find(|&&w| original[w as usize] == v).unwrap())
    };
    let fault_faces = mesh
        .fault_faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.nodes;
            (
                f.fault,
                map(f.cells[0], f.nodes),
                map(f.cells[1], [a, c, b]),
            )
        })
        .collect();
    SplitMesh {
        points,
        tets,
        original,
        fault_faces,
    }
}

/// What [`check_split`] counted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SplitSummary {
    /// Fault faces that now appear twice, one per side.
    pub opened: usize,
    /// Fault faces that stay one interior face: at a fault's tip inside the volume (where it
    /// ends at depth or where its surface ends) a face whose three nodes all lie on the tip,
    /// where the two sides join around it, keeps one copy of each node on both sides. None
    /// is expected on faults without a tip (the tests check that).
    pub tip: usize,
}

/// Checks a split mesh against its mesh: the same cells on copies of the same nodes, each of
/// positive volume; every fault face now twice, as two boundary faces (one per side, on
/// different nodes), except faces that stay shut (on a fault's tip), counted;
/// every other face as before (the new boundary is the opened fault faces only).
///
/// # Errors
/// [`FaultError::Check`] naming the first failure.
pub fn check_split(mesh: &FaultedMesh, split: &SplitMesh) -> Result<SplitSummary, FaultError> {
    let fail = |p: [f64; 3], what: String| FaultError::Check {
        what,
        x: p[0],
        y: p[1],
        z: p[2],
    };
    if split.tets.len() != mesh.tets.len() || split.original.len() != split.points.len() {
        return Err(fail([0.0; 3], "the split mesh has other cells".into()));
    }
    for (c, (t, s)) in mesh.tets.iter().zip(&split.tets).enumerate() {
        for k in 0..4 {
            let o = split.original[s[k] as usize];
            if o != t[k] || split.points[s[k] as usize] != mesh.points[o as usize] {
                return Err(fail(
                    mesh.points[t[k] as usize],
                    format!("cell {c} of the split mesh is not a copy"),
                ));
            }
        }
        let q = s.map(|v| {
            let p = split.points[v as usize];
            Coord3D {
                x: p[0],
                y: p[1],
                z: p[2],
            }
        });
        if orient3d(q[0], q[1], q[2], q[3]) >= 0.0 {
            return Err(fail(
                split.points[s[0] as usize],
                format!("cell {c} has no positive volume"),
            ));
        }
    }
    let boundary = |faces: Vec<(u128, u32, u8)>| {
        let mut out = Vec::new();
        let mut i = 0;
        while i < faces.len() {
            let mut j = i + 1;
            while j < faces.len() && faces[j].0 == faces[i].0 {
                j += 1;
            }
            if j - i == 1 {
                out.push(faces[i].0);
            }
            i = j;
        }
        out
    };
    let before = boundary(all_faces(&mesh.tets));
    let after = boundary(all_faces(&split.tets));
    let mut opened: Vec<u128> = Vec::new();
    let mut tip: Vec<u128> = Vec::new();
    for &(f, a, b) in &split.fault_faces {
        let key = face_key(&a.map(|v| split.original[v as usize]));
        let (ka, kb) = (face_key(&a), face_key(&b));
        if ka == kb {
            tip.push(key);
            continue;
        }
        if after.binary_search(&ka).is_err() || after.binary_search(&kb).is_err() {
            return Err(fail(
                split.points[a[0] as usize],
                format!(
                    "a face of fault {f} does not appear twice, once per side, in the split mesh"
                ),
            ));
        }
        opened.push(key);
    }
    opened.sort_unstable();
    opened.dedup();
    tip.sort_unstable();
    tip.dedup();
    if after.len() != before.len() + 2 * opened.len() {
        return Err(fail(
            [0.0; 3],
            format!(
                "the split mesh has {} boundary faces, not {} + 2 x {} opened fault faces",
                after.len(),
                before.len(),
                opened.len()
            ),
        ));
    }
    Ok(SplitSummary {
        opened: opened.len(),
        tip: tip.len(),
    })
}
