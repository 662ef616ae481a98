//! Inverse distance weighting: `ẑ = Σ w_i z_i / Σ w_i`, `w_i = d_i^{-p}`, exact at data.

use rayon::prelude::*;

use crate::data::Data;
use crate::error::{bad, GeostatError, Result};
use crate::search::Tree;

/// Default IDW power (the command line's `--power`).
pub const DEFAULT_IDW_POWER: f64 = 2.0;

/// Which data enter each estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Search {
    /// All data (exact; `O(n)` per target).
    All,
    /// The `k` nearest.
    Nearest(usize),
    /// All within the radius (exclusive); a target with none is an error.
    Radius(f64),
}

/// An IDW interpolator over fixed data.
pub struct Idw {
    xy: Vec<[f64; 2]>,
    z: Vec<f64>,
    tree: Tree,
    power: f64,
    search: Search,
    centre: [f64; 2],
}

impl Idw {
    /// Builds the search structure.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{Data, Duplicates, Idw, IdwSearch};
    /// let data = Data::new(vec![[0.0, 0.0], [2.0, 0.0]], vec![1.0, 3.0], Duplicates::Reject)?;
    /// let idw = Idw::new(&data, 2.0, IdwSearch::All)?;
    /// let mut z = vec![0.0; 2];
    /// idw.predict(&[[1.0, 0.0], [2.0, 0.0]], &mut z)?;
    /// assert_eq!(z, [2.0, 3.0]);
    /// # Ok(()) }
    /// ```
    pub fn new(data: &Data, power: f64, search: Search) -> Result<Idw> {
        if !(power.is_finite() && power > 0.0) {
            return Err(bad("power", power, "must be finite and > 0"));
        }
        match search {
            Search::Nearest(0) => return Err(bad("neighbors", 0.0, "must be at least 1")),
            Search::Radius(r) if !(r.is_finite() && r > 0.0) => {
                return Err(bad("radius", r, "must be finite and > 0"))
            }
            _ => {}
        }
        if data.is_empty() {
            return Err(GeostatError::TooFewData {
                n: 0,
                needed: 1,
                what: "IDW".into(),
            });
        }
        // Centre coordinates for precision with UTM-sized numbers.
        let n = data.len() as f64;
        let centre = data
            .xy()
            .iter()
            .fold([0.0, 0.0], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n]);
        let xy: Vec<[f64; 2]> = data
            .xy()
            .iter()
            .map(|p| [p[0] - centre[0], p[1] - centre[1]])
            .collect();
        let tree = Tree::new(&xy)?;
        Ok(Idw {
            xy,
            z: data.z().to_vec(),
            tree,
            power,
            search,
            centre,
        })
    }

    /// Estimates at `targets`, in parallel.
    ///
    /// # Panics
    /// If `est` is not as long as `targets`.
    pub fn predict(&self, targets: &[[f64; 2]], est: &mut [f64]) -> Result<()> {
        self.predict_excluding(targets, None, est)
    }

    /// Like [`Idw::predict`], target `i` never using data point `exclude[i]`.
    pub fn predict_excluding(
        &self,
        targets: &[[f64; 2]],
        exclude: Option<&[usize]>,
        est: &mut [f64],
    ) -> Result<()> {
        assert_eq!(est.len(), targets.len());
        let order = crate::linalg::morton_order(targets);
        let chunk = 4096;
        let mut res = vec![0.0; targets.len()];
        res.par_chunks_mut(chunk)
            .enumerate()
            .try_for_each_init(Vec::new, |near, (c, out)| {
                for (i, o) in out.iter_mut().enumerate() {
                    let t = order[c * chunk + i] as usize;
                    let q = [
                        targets[t][0] - self.centre[0],
                        targets[t][1] - self.centre[1],
                    ];
                    let ex = exclude.map_or(usize::MAX, |x| x[t]);
                    *o = self.one(q, ex, near).ok_or(GeostatError::NoNeighbours {
                        index: t,
                        x: targets[t][0],
                        y: targets[t][1],
                        radius: match self.search {
                            Search::Radius(r) => r,
                            _ => f64::INFINITY,
                        },
                    })?;
                }
                Ok::<(), GeostatError>(())
            })?;
        for (i, &t) in order.iter().enumerate() {
            est[t as usize] = res[i];
        }
        Ok(())
    }

    fn one(&self, q: [f64; 2], exclude: usize, near: &mut Vec<(f64, usize)>) -> Option<f64> {
        match self.search {
            Search::All => {
                let d2 = |p: &[f64; 2]| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
                let others = || {
                    self.xy
                        .iter()
                        .enumerate()
                        .filter(move |&(i, _)| i != exclude)
                        .map(|(i, p)| (d2(p), i))
                };
                if let Some((_, i)) = others().find(|a| a.0 == 0.0) {
                    return Some(self.z[i]);
                }
                self.weigh(others)
            }
            Search::Nearest(k) => {
                let want = k + usize::from(exclude != usize::MAX);
                self.tree.nearest(q, want, near);
                near.retain(|a| a.1 != exclude);
                near.truncate(k);
                self.combine(near)
            }
            Search::Radius(r) => {
                self.tree.within(q, r, near);
                near.retain(|a| a.1 != exclude);
                near.sort_unstable_by(|a, b| a.partial_cmp(b).expect("finite"));
                self.combine(near)
            }
        }
    }

    #[inline]
    fn weight(&self, d2: f64) -> f64 {
        if self.power == 2.0 {
            1.0 / d2
        } else {
            d2.powf(-0.5 * self.power)
        }
    }

    fn combine(&self, near: &[(f64, usize)]) -> Option<f64> {
        if let Some(&(d2, i)) = near.first() {
            if d2 == 0.0 {
                return Some(self.z[i]);
            }
        }
        self.weigh(|| near.iter().copied())
    }

    /// The weighted mean of the data `(d², index)` that `near` lists (none at distance
    /// zero). The weights `d^-power` underflow to zero or overflow to infinity for a large
    /// power (`1e6`: any distance but 1 is out of range), so a sum that is not a positive
    /// finite number is taken again with every weight divided by the nearest one's,
    /// `(d_min/d)^power`, which is at most 1 and is 1 at the nearest: the same mean, in
    /// range for any finite power. The plain form stays first, so that the usual powers keep
    /// their bits.
    fn weigh<I: Iterator<Item = (f64, usize)>>(&self, near: impl Fn() -> I) -> Option<f64> {
        let (mut sw, mut swz) = (0.0, 0.0);
        for (d2, i) in near() {
            let w = self.weight(d2);
            sw += w;
            swz += w * self.z[i];
        }
        let mean = swz / sw;
        if sw > 0.0 && sw.is_finite() && mean.is_finite() {
            return Some(mean);
        }
        let d2min = near().map(|a| a.0).fold(f64::INFINITY, f64::min);
        if !(d2min > 0.0 && d2min.is_finite()) {
            return None;
        }
        let (mut sw, mut swz) = (0.0, 0.0);
        for (d2, i) in near() {
            let w = (d2min / d2).powf(0.5 * self.power);
            sw += w;
            swz += w * self.z[i];
        }
        (sw > 0.0).then(|| swz / sw)
    }

    /// Number of data.
    pub fn len(&self) -> usize {
        self.z.len()
    }

    /// Whether there are no data (never true: construction rejects that).
    pub fn is_empty(&self) -> bool {
        self.z.is_empty()
    }
}
