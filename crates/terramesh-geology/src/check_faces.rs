//! The faces of the cells as the check sees them ([`crate::check`]): each cell's outward
//! faces in its own node order, and a key per face that is the same from both sides.

use terramesh_core::volume::{Cell, CellKind};

use crate::cells::split_quad;

/// The outward faces of a cell (triangles end with `u32::MAX`).
pub(crate) fn faces(c: &Cell) -> impl Iterator<Item = [u32; 4]> {
    const T: u32 = u32::MAX;
    let n = c.nodes;
    let list: ([[u32; 4]; 5], usize) = match c.kind {
        CellKind::Tetra => (
            [
                [n[0], n[2], n[1], T],
                [n[0], n[1], n[3], T],
                [n[1], n[2], n[3], T],
                [n[0], n[3], n[2], T],
                [T; 4],
            ],
            4,
        ),
        CellKind::Pyramid => (
            [
                [n[0], n[3], n[2], n[1]],
                [n[0], n[1], n[4], T],
                [n[1], n[2], n[4], T],
                [n[2], n[3], n[4], T],
                [n[3], n[0], n[4], T],
            ],
            5,
        ),
        CellKind::Wedge => (
            [
                [n[0], n[2], n[1], T],
                [n[3], n[4], n[5], T],
                [n[0], n[1], n[4], n[3]],
                [n[1], n[2], n[5], n[4]],
                [n[2], n[0], n[3], n[5]],
            ],
            5,
        ),
    };
    list.0.into_iter().take(list.1)
}

/// A face's key (the same for both orientations) and its orientation: the face turned to
/// start at its least node (the first of equal least ones), the rest of the key in increasing
/// order.
#[inline]
pub(crate) fn canonical(f: [u32; 4]) -> ([u32; 4], bool) {
    // the rotations written out, not taken modulo the face's size (a division per node)
    if f[3] == u32::MAX {
        let [a, b, c, _] = f;
        let (m, x, y) = if a <= b && a <= c {
            (a, b, c)
        } else if b <= c {
            (b, c, a)
        } else {
            (c, a, b)
        };
        ([m, x.min(y), x.max(y), u32::MAX], x < y)
    } else {
        let mut m = 0;
        for i in 1..4 {
            if f[i] < f[m] {
                m = i;
            }
        }
        let at = |k: usize| f[(m + k) & 3];
        let (x, z) = (at(1), at(3));
        ([at(0), x.min(z), at(2), x.max(z)], x < z)
    }
}

/// The face back from its key and orientation.
pub(crate) fn oriented(key: [u32; 4], forward: bool) -> [u32; 4] {
    match (key[3] == u32::MAX, forward) {
        (true, true) => key,
        (true, false) => [key[0], key[2], key[1], u32::MAX],
        (false, true) => key,
        (false, false) => [key[0], key[3], key[2], key[1]],
    }
}

pub(crate) fn used(f: &[u32; 4]) -> &[u32] {
    if f[3] == u32::MAX {
        &f[..3]
    } else {
        f
    }
}

/// The triangles of a face (a quadrilateral cut by the diagonal rule).
pub(crate) fn triangles(f: &[u32; 4]) -> impl Iterator<Item = [u32; 3]> {
    let (n, t) = if f[3] == u32::MAX {
        (1, [[f[0], f[1], f[2]], [0; 3]])
    } else {
        (2, split_quad(*f))
    };
    t.into_iter().take(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The key as first written: rotations taken modulo the face's size.
    fn canonical_by_modulo(f: [u32; 4]) -> ([u32; 4], bool) {
        let used = if f[3] == u32::MAX { 3 } else { 4 };
        let m = (0..used).min_by_key(|&i| f[i]).unwrap();
        let at = |k: usize| f[(m + k) % used];
        if used == 3 {
            let (x, y) = (at(1), at(2));
            ([at(0), x.min(y), x.max(y), u32::MAX], x < y)
        } else {
            let (x, z) = (at(1), at(3));
            ([at(0), x.min(z), at(2), x.max(z)], x < z)
        }
    }

    #[test]
    fn face_keys_are_those_of_the_rotation_by_modulo_repeated_nodes_included() {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s % 5) as u32 // few values: many ties
        };
        for _ in 0..20_000 {
            let tri = [next(), next(), next(), u32::MAX];
            let quad = [next(), next(), next(), next()];
            assert_eq!(canonical(tri), canonical_by_modulo(tri), "{tri:?}");
            assert_eq!(canonical(quad), canonical_by_modulo(quad), "{quad:?}");
            for f in [tri, quad] {
                let (key, o) = canonical(f);
                assert_eq!(canonical(oriented(key, o)), (key, o));
            }
        }
    }
}
