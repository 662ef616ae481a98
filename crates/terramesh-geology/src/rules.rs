//! Geological rules on the stacked surfaces of a model, per planar vertex, in this order:
//!
//! 1. **erosion**: nothing above the terrain; every interface is clipped to the terrain;
//! 2. **onlap**: going down, an interface may not rise above the (repaired) one above it; a
//!    unit that would rise above it has zero thickness there;
//! 3. **pinch-out**: going down, a unit thinner than `min_thickness` gets exactly zero
//!    thickness: its lower interface takes the upper's value;
//! 4. **base**: the base must not be above the terrain anywhere (an error naming the worst
//!    vertex and by how much); interfaces below the base are raised to it (the model is cut at
//!    its base), and then the lowest units still thinner than `min_thickness` above the base
//!    pinch out onto it (their top drops to the base; counted as pinch-outs).
//!
//! The terrain and the base never move. A column whose terrain is less than `min_thickness`
//! above the base keeps that thin top unit (the only unit with thickness there).
//!
//! A unit thinner than [`THICKNESS_FLOOR`] (1 µm) pinches out whatever `min_thickness` is,
//! `0` included: interfaces interpolated through contacts of zero thickness come out equal
//! only to rounding (1e-12 m apart), and a cell that thin has Jacobians of rounding noise,
//! negative at some integration points, which Gmsh and OpenGeoSys reject.

use crate::{GeologyError, Planar};

/// The thinnest unit a model keeps, in metres: thinner is zero thickness (a pinch-out), even
/// with `min_thickness = 0` (see the module's documentation).
pub const THICKNESS_FLOOR: f64 = 1e-6;

/// The surfaces before the rules, one value per planar vertex each.
///
/// ```
/// let raw = terramesh_geology::RawSurfaces {
///     terrain: vec![10.0],
///     tops: vec![vec![5.0], vec![2.0]], // three units
///     base: vec![0.0],
/// };
/// assert_eq!(raw.tops.len() + 1, 3);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RawSurfaces {
    /// The terrain (the DSM elevations): the top of the first unit.
    pub terrain: Vec<f64>,
    /// The raw interpolated top of every unit below the first, top to bottom.
    pub tops: Vec<Vec<f64>>,
    /// The model's base.
    pub base: Vec<f64>,
}

/// The repaired surfaces: `surfaces[0]` the terrain, `surfaces[k]` the top of unit `k` (and
/// the bottom of unit `k - 1`), the last the base; non-increasing downwards at every vertex.
///
/// ```
/// let s = terramesh_geology::Stack { surfaces: vec![vec![10.0], vec![4.0], vec![0.0]] };
/// assert_eq!(s.units(), 2);
/// assert_eq!(s.thickness(0, 0), 6.0);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Stack {
    /// Terrain, unit tops below the first, base.
    pub surfaces: Vec<Vec<f64>>,
}

impl Stack {
    /// The number of units.
    ///
    /// ```
    /// assert_eq!(terramesh_geology::Stack { surfaces: vec![vec![1.0], vec![0.0]] }.units(), 1);
    /// ```
    pub fn units(&self) -> usize {
        self.surfaces.len().saturating_sub(1)
    }

    /// The thickness of `unit` at vertex `v`.
    ///
    /// ```
    /// let s = terramesh_geology::Stack { surfaces: vec![vec![3.0], vec![1.0]] };
    /// assert_eq!(s.thickness(0, 0), 2.0);
    /// ```
    pub fn thickness(&self, unit: usize, v: usize) -> f64 {
        self.surfaces[unit][v] - self.surfaces[unit + 1][v]
    }
}

/// How many vertices each rule changed on one interface (the top of one unit below the
/// first).
///
/// ```
/// let r = terramesh_geology::InterfaceReport::default();
/// assert_eq!(r.erosion + r.onlap + r.pinch_out + r.base + r.negative_thickness, 0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct InterfaceReport {
    /// Clipped to the terrain.
    pub erosion: usize,
    /// Lowered to the interface above.
    pub onlap: usize,
    /// Moved onto the interface above (or onto the base) because the unit was thinner than
    /// `min_thickness`.
    pub pinch_out: usize,
    /// Raised to the base.
    pub base: usize,
    /// With [`stack_thicknesses`]: a negative thickness of the unit above set to zero.
    pub negative_thickness: usize,
}

/// What the rules changed: one entry per unit below the first (`interfaces[i]` is the top of
/// unit `i + 1`).
///
/// ```
/// let r = terramesh_geology::RulesReport { interfaces: vec![Default::default(); 2] };
/// assert_eq!(r.changed(), 0);
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RulesReport {
    /// Per interface, top to bottom.
    pub interfaces: Vec<InterfaceReport>,
}

impl RulesReport {
    /// The total number of changes.
    ///
    /// ```
    /// let mut r = terramesh_geology::RulesReport { interfaces: vec![Default::default()] };
    /// r.interfaces[0].onlap = 3;
    /// assert_eq!(r.changed(), 3);
    /// ```
    pub fn changed(&self) -> usize {
        self.interfaces
            .iter()
            .map(|r| r.erosion + r.onlap + r.pinch_out + r.base + r.negative_thickness)
            .sum()
    }
}

fn check_len(what: String, got: usize, n: usize) -> Result<(), GeologyError> {
    if got != n {
        return Err(GeologyError::Length {
            what,
            expected: n,
            got,
            why: "one value per planar vertex",
        });
    }
    Ok(())
}

fn check_finite(planar: &Planar, what: &dyn Fn() -> String, z: &[f64]) -> Result<(), GeologyError> {
    check_len(what(), z.len(), planar.points.len())?;
    if let Some(v) = z.iter().position(|z| !z.is_finite()) {
        let p = planar.points[v];
        return Err(GeologyError::NonFinite {
            surface: what(),
            vertex: v,
            x: p[0],
            y: p[1],
            value: z[v],
        });
    }
    Ok(())
}

/// Applies erosion, onlap, pinch-out and base (the module documentation gives the order and
/// the exact rules) to the raw surfaces.
///
/// ```
/// use terramesh_geology::{apply_rules, Planar, RawSurfaces};
/// let points = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
/// let planar = Planar::new(&points, &[[0, 1, 2]])?;
/// let raw = RawSurfaces {
///     terrain: vec![10.0, 10.0, 10.0],
///     // unit 1's top: above ground, fine, 0.2 m below ground; unit 2's top: above unit 1's.
///     tops: vec![vec![12.0, 6.0, 9.8], vec![3.0, 7.0, 2.0]],
///     base: vec![0.0; 3],
/// };
/// let (stack, report) = apply_rules(&planar, &raw, 0.5)?;
/// assert_eq!(stack.surfaces[1], [10.0, 6.0, 10.0]); // eroded, kept, pinched out
/// assert_eq!(stack.surfaces[2], [3.0, 6.0, 2.0]); // onlap at vertex 1
/// assert_eq!((report.interfaces[0].erosion, report.interfaces[0].pinch_out), (1, 1));
/// assert_eq!(report.interfaces[1].onlap, 1);
/// # Ok::<(), terramesh_geology::GeologyError>(())
/// ```
///
/// # Errors
/// [`GeologyError::Setting`] for a negative or non-finite `min_thickness`,
/// [`GeologyError::Length`] or [`GeologyError::NonFinite`] for a surface that does not give a
/// finite value per vertex, [`GeologyError::BaseAboveTerrain`] at the vertex where the base
/// rises highest above the terrain.
pub fn apply_rules(
    planar: &Planar,
    raw: &RawSurfaces,
    min_thickness: f64,
) -> Result<(Stack, RulesReport), GeologyError> {
    if !(min_thickness.is_finite() && min_thickness >= 0.0) {
        return Err(GeologyError::Setting {
            name: "min_thickness".into(),
            value: min_thickness,
            why: "must be a finite number of metres, zero or more",
        });
    }
    check_finite(planar, &|| "the terrain".into(), &raw.terrain)?;
    check_finite(planar, &|| "the base".into(), &raw.base)?;
    for (i, top) in raw.tops.iter().enumerate() {
        check_finite(
            planar,
            &|| format!("the top of unit {} (0 = the top unit)", i + 1),
            top,
        )?;
    }
    let worst = (0..raw.terrain.len())
        .map(|v| (v, raw.base[v] - raw.terrain[v]))
        .filter(|&(_, d)| d > 0.0)
        .max_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((v, _)) = worst {
        let p = planar.points[v];
        return Err(GeologyError::BaseAboveTerrain {
            vertex: v,
            x: p[0],
            y: p[1],
            base: raw.base[v],
            terrain: raw.terrain[v],
        });
    }
    let min_thickness = min_thickness.max(THICKNESS_FLOOR);
    let m = raw.tops.len();
    let n = raw.terrain.len();
    let mut surfaces = Vec::with_capacity(m + 2);
    surfaces.push(raw.terrain.clone());
    surfaces.extend(raw.tops.iter().cloned());
    surfaces.push(raw.base.clone());
    let mut report = vec![InterfaceReport::default(); m];
    let mut z = vec![0.0; m + 2];
    for v in 0..n {
        for (k, s) in surfaces.iter().enumerate() {
            z[k] = s[v];
        }
        let (terrain, base) = (z[0], z[m + 1]);
        // 1. Erosion.
        for k in 1..=m {
            if z[k] > terrain {
                z[k] = terrain;
                report[k - 1].erosion += 1;
            }
        }
        // 2. Onlap.
        for k in 1..=m {
            if z[k] > z[k - 1] {
                z[k] = z[k - 1];
                report[k - 1].onlap += 1;
            }
        }
        // 3. Pinch-out.
        for k in 1..=m {
            if z[k] != z[k - 1] && z[k - 1] - z[k] < min_thickness {
                z[k] = z[k - 1];
                report[k - 1].pinch_out += 1;
            }
        }
        // 4. Base: raise to it, then pinch the thin lowest units out onto it.
        for k in 1..=m {
            if z[k] < base {
                z[k] = base;
                report[k - 1].base += 1;
            }
        }
        for k in (1..=m).rev() {
            if z[k] == base {
                continue;
            }
            if z[k] - base >= min_thickness {
                break;
            }
            z[k] = base;
            report[k - 1].pinch_out += 1;
        }
        for (k, s) in surfaces.iter_mut().enumerate() {
            s[v] = z[k];
        }
    }
    Ok((Stack { surfaces }, RulesReport { interfaces: report }))
}

/// The "thickness" mode: stacks the given per-vertex thicknesses of every unit but the lowest
/// down from the terrain (a negative thickness becomes zero and is counted), the lowest unit
/// reaching down to the base; then applies [`apply_rules`] (so thin units pinch out and the
/// base cuts the stack).
///
/// ```
/// use terramesh_geology::{stack_thicknesses, Planar};
/// let points = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
/// let planar = Planar::new(&points, &[[0, 1, 2]])?;
/// let terrain = vec![10.0; 3];
/// let thickness = vec![vec![2.0, -1.0, 0.1]]; // unit 0; unit 1 reaches the base
/// let (stack, report) = stack_thicknesses(&planar, &terrain, &thickness, &[0.0; 3], 0.5)?;
/// assert_eq!(stack.surfaces[1], [8.0, 10.0, 10.0]);
/// assert_eq!(report.interfaces[0].negative_thickness, 1);
/// assert_eq!(report.interfaces[0].pinch_out, 1);
/// # Ok::<(), terramesh_geology::GeologyError>(())
/// ```
///
/// # Errors
/// Those of [`apply_rules`], and [`GeologyError::NonFinite`] or [`GeologyError::Length`] for a
/// thickness that is not a finite value per vertex.
pub fn stack_thicknesses(
    planar: &Planar,
    terrain: &[f64],
    thicknesses: &[Vec<f64>],
    base: &[f64],
    min_thickness: f64,
) -> Result<(Stack, RulesReport), GeologyError> {
    check_finite(planar, &|| "the terrain".into(), terrain)?;
    let mut tops = Vec::with_capacity(thicknesses.len());
    let mut negative = vec![0; thicknesses.len()];
    let mut above = terrain.to_vec();
    for (u, t) in thicknesses.iter().enumerate() {
        check_finite(
            planar,
            &|| format!("the thickness of unit {u} (0 = the top unit)"),
            t,
        )?;
        for (z, &t) in above.iter_mut().zip(t) {
            if t < 0.0 {
                negative[u] += 1;
            } else {
                *z -= t;
            }
        }
        tops.push(above.clone());
    }
    let raw = RawSurfaces {
        terrain: terrain.to_vec(),
        tops,
        base: base.to_vec(),
    };
    let (stack, mut report) = apply_rules(planar, &raw, min_thickness)?;
    for (r, n) in report.interfaces.iter_mut().zip(negative) {
        r.negative_thickness = n;
    }
    Ok((stack, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Interfaces equal but for rounding make no sliver cells, even with `min_thickness = 0`;
    /// a thin unit above the floor is kept.
    #[test]
    fn rounding_slivers_pinch_out_with_min_thickness_zero() {
        let points = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let planar = Planar::new(&points, &[[0, 1, 2]]).unwrap();
        let raw = RawSurfaces {
            terrain: vec![1000.0; 3],
            // unit 0 is 1e-12 m, 2e-7 m and 1e-5 m thick at the three vertices
            tops: vec![
                vec![1000.0 - 1e-12, 1000.0 - 2e-7, 1000.0 - 1e-5],
                vec![500.0; 3],
            ],
            base: vec![0.0; 3],
        };
        let (stack, report) = apply_rules(&planar, &raw, 0.0).unwrap();
        assert_eq!(stack.surfaces[1][0], 1000.0);
        assert_eq!(stack.surfaces[1][1], 1000.0);
        assert_eq!(stack.surfaces[1][2], 1000.0 - 1e-5);
        assert_eq!(report.interfaces[0].pinch_out, 2);
        // Just above the base, too.
        let raw = RawSurfaces {
            terrain: vec![1000.0; 3],
            tops: vec![vec![500.0; 3], vec![1e-9, 5e-7, 2e-6]],
            base: vec![0.0; 3],
        };
        let (stack, report) = apply_rules(&planar, &raw, 0.0).unwrap();
        assert_eq!(stack.surfaces[2], [0.0, 0.0, 2e-6]);
        assert_eq!(report.interfaces[1].pinch_out, 2);
        // A larger min_thickness still rules.
        let (stack, _) = apply_rules(&planar, &raw, 1e-5).unwrap();
        assert_eq!(stack.surfaces[2], [0.0; 3]);
    }
}
