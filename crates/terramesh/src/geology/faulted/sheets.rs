//! The engineering objects' boundaries as triangles, for the report (the viewer's layers, the
//! sections' outlines and the still picture): the faces of an object's cells (its lining
//! included) that no other cell of the same object shares, found from the cell labels
//! (`terramesh_faults::ObjectCells::object`), each oriented away from its cell. Faces are
//! matched by their corners' coordinates, so a mesh whose nodes are split at the faults
//! still pairs the faces on both sides of a fault inside an object.

use super::FaultSheet;

/// One sheet per named object (`names`: its number in `object`, 1 = first, and its name),
/// in the order of `names`: the outward boundary of the cells labelled with that number.
pub(crate) fn object_sheets(
    points: &[[f64; 3]],
    tets: &[[u32; 4]],
    object: &[u32],
    names: &[(u32, String)],
) -> Vec<FaultSheet> {
    use rayon::prelude::*;
    // Faces are matched by their corners' coordinates: every point stands for the first point
    // with its coordinates' bits (its canonical id), so that a face's sorted canonical ids are
    // equal exactly where its sorted corners' coordinates are.
    let bits = |i: u32| points[i as usize].map(f64::to_bits);
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.par_sort_unstable_by_key(|&i| (bits(i), i));
    let mut canon = vec![0u32; points.len()];
    for w in 0..order.len() {
        canon[order[w] as usize] = if w > 0 && bits(order[w]) == bits(order[w - 1]) {
            canon[order[w - 1] as usize]
        } else {
            order[w]
        };
    }
    // Every face of an object's cell (cell and the node opposite it): its object and its
    // sorted canonical corners; sorted by both, a face that only one cell of its object has
    // is on the object's boundary.
    let mut faces: Vec<(u32, [u32; 3], u32, u8)> = tets
        .par_iter()
        .enumerate()
        .flat_map_iter(|(c, t)| {
            let o = object.get(c).copied().unwrap_or(0);
            let canon = &canon;
            (0..4u8).filter(move |_| o != 0).map(move |opp| {
                let mut key = [1, 2, 3].map(|k| canon[t[(opp as usize + k) % 4] as usize]);
                key.sort_unstable();
                (o, key, c as u32, opp)
            })
        })
        .collect();
    faces.par_sort_unstable();
    // The boundary faces, oriented away from their cell, with the key they are given in
    // (their sorted corners' coordinates: distinct within an object's boundary).
    type Key = [[u64; 3]; 3];
    let mut found: Vec<(u32, Key, [[f64; 3]; 3])> = faces
        .par_chunk_by(|a, b| a.0 == b.0 && a.1 == b.1)
        .filter_map(|run| match run {
            [(o, _, c, opp)] => {
                let (opp, q) = (*opp as usize, tets[*c as usize].map(|v| points[v as usize]));
                let mut f: [[f64; 3]; 3] = [0, 1, 2].map(|k| q[(opp + 1 + k) % 4]);
                let (a, b, c3, d) = (f[0], f[1], f[2], q[opp]);
                let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let w = [c3[0] - a[0], c3[1] - a[1], c3[2] - a[2]];
                let n = [
                    u[1] * w[2] - u[2] * w[1],
                    u[2] * w[0] - u[0] * w[2],
                    u[0] * w[1] - u[1] * w[0],
                ];
                let s = n[0] * (d[0] - a[0]) + n[1] * (d[1] - a[1]) + n[2] * (d[2] - a[2]);
                if s > 0.0 {
                    f.swap(1, 2);
                }
                let mut key: Key = f.map(|p| p.map(f64::to_bits));
                key.sort_unstable();
                Some((*o, key, f))
            }
            _ => None,
        })
        .collect();
    found.par_sort_unstable_by(|a, b| (a.0, a.1).cmp(&(b.0, b.1)));
    // per object, its boundary faces in increasing key
    let mut boundary: std::collections::HashMap<u32, Vec<[[f64; 3]; 3]>> =
        std::collections::HashMap::new();
    for (o, _, f) in found {
        boundary.entry(o).or_default().push(f);
    }
    names
        .iter()
        .map(|(o, name)| FaultSheet {
            name: name.clone(),
            triangles: boundary.get(o).cloned().unwrap_or_default(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube of six tetrahedra (Kuhn), all labelled object 1 but one labelled 2: the
    /// boundary of object 1 is closed (every edge in two faces), encloses the cube less one
    /// tetrahedron, and is oriented outward (positive enclosed volume).
    #[test]
    fn an_objects_boundary_is_closed_and_outward() {
        let p: Vec<[f64; 3]> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let tets = vec![
            [0, 1, 3, 7],
            [0, 1, 5, 7],
            [0, 2, 3, 7],
            [0, 2, 6, 7],
            [0, 4, 5, 7],
            [0, 4, 6, 7],
        ];
        let s = object_sheets(
            &p,
            &tets,
            &[1, 1, 1, 1, 1, 2],
            &[(1, "a".into()), (2, "b".into()), (3, "none".into())],
        );
        assert_eq!(s.len(), 3);
        assert!(s[2].triangles.is_empty());
        assert_eq!(s[1].triangles.len(), 4);
        let vol = |t: &[[[f64; 3]; 3]]| {
            t.iter()
                .map(|[a, b, c]| {
                    (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                        + a[2] * (b[0] * c[1] - b[1] * c[0]))
                        / 6.0
                })
                .sum::<f64>()
        };
        assert!((vol(&s[0].triangles) - 5.0 / 6.0).abs() < 1e-12);
        assert!((vol(&s[1].triangles) - 1.0 / 6.0).abs() < 1e-12);
        // 10 faces of the cube's surface (12 less the 2 of the tetrahedron labelled 2) and the
        // 2 faces it shares with object 1
        assert_eq!(s[0].triangles.len(), 12);
    }
}
