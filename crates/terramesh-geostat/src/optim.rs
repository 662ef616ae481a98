//! Nelder–Mead simplex minimisation (Nelder & Mead 1965, with the standard coefficients
//! reflection 1, expansion 2, contraction ½, shrink ½, as in Lagarias et al. 1998).
//!
//! Deterministic: the same start gives the same evaluations in the same order. Infinite
//! values (a parameter set that is not admissible) are simply worse than any finite one.

/// Minimises `f` from `x0` with initial steps `step` (one per coordinate); stops after
/// `max_evals` evaluations or when the simplex's values agree to `ftol` (absolute).
/// Returns the best point and its value.
pub(crate) fn nelder_mead(
    f: &mut dyn FnMut(&[f64]) -> f64,
    x0: &[f64],
    step: &[f64],
    ftol: f64,
    max_evals: usize,
) -> (Vec<f64>, f64) {
    let d = x0.len();
    let mut pts: Vec<Vec<f64>> = vec![x0.to_vec()];
    for i in 0..d {
        let mut p = x0.to_vec();
        p[i] += step[i];
        pts.push(p);
    }
    let mut vals: Vec<f64> = pts.iter().map(|p| f(p)).collect();
    let mut evals = d + 1;
    let nan_last = |v: f64| if v.is_nan() { f64::INFINITY } else { v };
    for v in vals.iter_mut() {
        *v = nan_last(*v);
    }
    while evals < max_evals {
        let mut order: Vec<usize> = (0..=d).collect();
        order.sort_by(|&a, &b| vals[a].total_cmp(&vals[b]));
        pts = order.iter().map(|&i| pts[i].clone()).collect();
        vals = order.iter().map(|&i| vals[i]).collect();
        if (vals[d] - vals[0]).abs() <= ftol && vals[d].is_finite() {
            break;
        }
        let centroid: Vec<f64> = (0..d)
            .map(|k| pts[..d].iter().map(|p| p[k]).sum::<f64>() / d as f64)
            .collect();
        let at = |t: f64| -> Vec<f64> {
            (0..d)
                .map(|k| centroid[k] + t * (pts[d][k] - centroid[k]))
                .collect()
        };
        let xr = at(-1.0);
        let fr = nan_last(f(&xr));
        evals += 1;
        if fr < vals[0] {
            let xe = at(-2.0);
            let fe = nan_last(f(&xe));
            evals += 1;
            if fe < fr {
                (pts[d], vals[d]) = (xe, fe);
            } else {
                (pts[d], vals[d]) = (xr, fr);
            }
        } else if fr < vals[d - 1] {
            (pts[d], vals[d]) = (xr, fr);
        } else {
            let (xc, fc) = if fr < vals[d] {
                let x = at(-0.5);
                let v = nan_last(f(&x));
                (x, v)
            } else {
                let x = at(0.5);
                let v = nan_last(f(&x));
                (x, v)
            };
            evals += 1;
            if fc < vals[d].min(fr) {
                (pts[d], vals[d]) = (xc, fc);
            } else {
                for i in 1..=d {
                    for k in 0..d {
                        pts[i][k] = pts[0][k] + 0.5 * (pts[i][k] - pts[0][k]);
                    }
                    vals[i] = nan_last(f(&pts[i]));
                }
                evals += d;
            }
        }
    }
    let best = (0..=d)
        .min_by(|&a, &b| vals[a].total_cmp(&vals[b]))
        .unwrap();
    (pts[best].clone(), vals[best])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_rosenbrock_and_respects_infinite_walls() {
        let mut rosen = |x: &[f64]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
        let (x, v) = nelder_mead(&mut rosen, &[-1.2, 1.0], &[0.5, 0.5], 1e-14, 2000);
        assert!(
            (x[0] - 1.0).abs() < 1e-3 && (x[1] - 1.0).abs() < 1e-3 && v < 1e-6,
            "{x:?}"
        );
        // A wall: x < 0.5 is not admissible; the minimum of (x-0)^2 on x >= 0.5 is at 0.5.
        let mut walled = |x: &[f64]| {
            if x[0] < 0.5 {
                f64::INFINITY
            } else {
                x[0] * x[0]
            }
        };
        let (x, _) = nelder_mead(&mut walled, &[2.0], &[0.5], 1e-12, 500);
        assert!((x[0] - 0.5).abs() < 1e-3, "{x:?}");
    }
}
