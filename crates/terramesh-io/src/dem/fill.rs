//! Filling voids (nodata posts) from their neighbours.

/// Fills the NaN posts of a `rows x cols` grid in passes: each pass sets every void that has
/// at least one valid 8-neighbour to the mean of those neighbours (values from before the
/// pass), so large voids fill from their rim inwards. Returns the number of filled posts.
/// A grid with no valid post is left as it is.
pub(crate) fn fill_voids(data: &mut [f64], rows: usize, cols: usize) -> usize {
    let mut voids: Vec<usize> = (0..data.len()).filter(|&i| data[i].is_nan()).collect();
    let total = voids.len();
    let mut updates = Vec::new();
    while !voids.is_empty() {
        updates.clear();
        let mut rest = Vec::new();
        for &i in &voids {
            let (r, c) = ((i / cols) as i64, (i % cols) as i64);
            let (mut s, mut n) = (0.0, 0u32);
            for dr in -1..=1 {
                for dc in -1..=1 {
                    let (rr, cc) = (r + dr, c + dc);
                    if (dr, dc) == (0, 0) || rr < 0 || cc < 0 {
                        continue;
                    }
                    if rr as usize >= rows || cc as usize >= cols {
                        continue;
                    }
                    let v = data[rr as usize * cols + cc as usize];
                    if !v.is_nan() {
                        s += v;
                        n += 1;
                    }
                }
            }
            if n > 0 {
                updates.push((i, s / n as f64));
            } else {
                rest.push(i);
            }
        }
        if updates.is_empty() {
            break;
        }
        for &(i, v) in &updates {
            data[i] = v;
        }
        voids = rest;
    }
    total - voids.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_from_the_rim_inwards() {
        let n = f64::NAN;
        let mut d = vec![
            1.0, 1.0, 1.0, 1.0, //
            1.0, n, n, 1.0, //
            1.0, n, n, 1.0, //
            1.0, 1.0, 1.0, 5.0,
        ];
        assert_eq!(fill_voids(&mut d, 4, 4), 4);
        assert!(d.iter().all(|v| v.is_finite()));
        assert_eq!(d[5], 1.0);
        // the void next to the 5 sees it: (1*7 + 5)/8... only valid neighbours count
        assert_eq!(d[10], (4.0 + 5.0) / 5.0); // valid neighbours only: four 1s and the 5
    }

    #[test]
    fn all_void_grid_is_left_alone() {
        let mut d = vec![f64::NAN; 4];
        assert_eq!(fill_voids(&mut d, 2, 2), 0);
    }
}
