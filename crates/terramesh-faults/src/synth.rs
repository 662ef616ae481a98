//! A synthetic site with a known truth: a planar terrain over a jittered triangle grid,
//! planar strata, planar faults offsetting them by a constant throw (the positive side, the
//! hanging wall, moved down), so that the true unit at any point has a closed form computed
//! here independently of the kernel's fault surfaces.

use crate::{BlockKey, FaultError, FaultSpec, Terrain};

/// One planar fault of a synthetic site.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthFault {
    /// Its name.
    pub name: String,
    /// Two points of its trace (the trace runs through them, beyond the region).
    pub trace: [[f64; 2]; 2],
    /// Degrees below horizontal.
    pub dip: f64,
    /// Degrees clockwise from grid north.
    pub dip_direction: f64,
    /// The hanging wall (positive side) moves down by this, metres.
    pub throw: f64,
    /// The fault it ends at (by index) and the side of it where it exists.
    pub ends_at: Option<(usize, i8)>,
    /// Its down-dip extent.
    pub depth: Option<f64>,
}

impl SynthFault {
    /// A fault through two plan points.
    pub fn new(
        name: &str,
        a: [f64; 2],
        b: [f64; 2],
        dip: f64,
        dip_direction: f64,
        throw: f64,
    ) -> Self {
        SynthFault {
            name: name.into(),
            trace: [a, b],
            dip,
            dip_direction,
            throw,
            ends_at: None,
            depth: None,
        }
    }
}

/// A synthetic site.
#[derive(Debug, Clone)]
pub struct Site {
    /// The terrain.
    pub terrain: Terrain,
    /// The terrain plane: `z = plane[0] + plane[1] x + plane[2] y`.
    pub plane: [f64; 3],
    /// The base.
    pub base: f64,
    /// The faults.
    pub faults: Vec<SynthFault>,
    /// The interfaces in the block that no fault moved: `z = tops[k] + dip[0] x + dip[1] y`.
    pub tops: Vec<f64>,
    /// The strata's gradient.
    pub dip: [f64; 2],
}

/// splitmix64: a small seeded generator for the jitter.
fn mix(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

impl Site {
    /// A square site `size` metres wide over an `n` by `n` grid of squares (two triangles
    /// each), interior vertices jittered by up to `jitter` of a square (seeded).
    ///
    /// ```
    /// use terramesh_faults::{Site, SynthFault};
    /// let site = Site::new(100.0, 4, 0.2, 7, [100.0, 0.0, 0.0], 0.0, vec![60.0], [0.0, 0.0],
    ///     vec![SynthFault::new("F", [50.0, -1.0], [50.0, 101.0], 90.0, 90.0, 10.0)])?;
    /// assert_eq!(site.true_unit([10.0, 50.0, 70.0]), 0);
    /// assert_eq!(site.true_unit([60.0, 50.0, 55.0]), 0); // the east side moved down by 10 m
    /// assert_eq!(site.true_unit([10.0, 50.0, 55.0]), 1);
    /// # Ok::<(), terramesh_faults::FaultError>(())
    /// ```
    ///
    /// # Errors
    /// From [`Terrain::new`].
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        size: f64,
        n: usize,
        jitter: f64,
        seed: u64,
        plane: [f64; 3],
        base: f64,
        tops: Vec<f64>,
        dip: [f64; 2],
        faults: Vec<SynthFault>,
    ) -> Result<Site, FaultError> {
        let mut state = seed;
        let h = size / n as f64;
        let mut points = Vec::with_capacity((n + 1) * (n + 1));
        for j in 0..=n {
            for i in 0..=n {
                let (mut x, mut y) = (i as f64 * h, j as f64 * h);
                if i > 0 && i < n {
                    x += (mix(&mut state) - 0.5) * 2.0 * jitter * h;
                }
                if j > 0 && j < n {
                    y += (mix(&mut state) - 0.5) * 2.0 * jitter * h;
                }
                points.push([x, y]);
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut triangles = Vec::with_capacity(2 * n * n);
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if (i + j) % 2 == 0 {
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                } else {
                    triangles.push([a, b, d]);
                    triangles.push([b, c, d]);
                }
            }
        }
        let heights = points
            .iter()
            .map(|p| plane[0] + plane[1] * p[0] + plane[2] * p[1])
            .collect();
        Ok(Site {
            terrain: Terrain::new(points, triangles, heights)?,
            plane,
            base,
            faults,
            tops,
            dip,
        })
    }

    /// The faults as the kernel takes them.
    pub fn specs(&self) -> Vec<FaultSpec> {
        self.faults
            .iter()
            .map(|f| {
                let mut s = FaultSpec::trace(&f.name, f.trace.to_vec(), f.dip, f.dip_direction);
                if let Some((g, _)) = f.ends_at {
                    s.ends_at = vec![self.faults[g].name.clone()];
                }
                s.depth = f.depth;
                s
            })
            .collect()
    }

    /// The signed distance of `q` from fault `f`'s plane, positive towards its dip direction.
    pub fn true_side(&self, f: usize, q: [f64; 3]) -> f64 {
        let fault = &self.faults[f];
        let [a, b] = fault.trace;
        let z = |p: [f64; 2]| self.plane[0] + self.plane[1] * p[0] + self.plane[2] * p[1];
        let d = fault.dip_direction.to_radians();
        let u = [d.sin(), d.cos()];
        let cot = if fault.dip == 90.0 {
            0.0
        } else {
            1.0 / fault.dip.to_radians().tan()
        };
        let e = [b[0] - a[0], b[1] - a[1], z(b) - z(a)];
        let w = [cot * u[0], cot * u[1], -1.0];
        let mut n = [
            e[1] * w[2] - e[2] * w[1],
            e[2] * w[0] - e[0] * w[2],
            e[0] * w[1] - e[1] * w[0],
        ];
        if n[0] * u[0] + n[1] * u[1] < 0.0 {
            n = [-n[0], -n[1], -n[2]];
        }
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        (n[0] * (q[0] - a[0]) + n[1] * (q[1] - a[1]) + n[2] * (q[2] - z(a))) / l
    }

    /// Whether fault `f` offsets the strata at `q` (on its side of the fault it ends at).
    fn counts(&self, f: usize, q: [f64; 3]) -> bool {
        match self.faults[f].ends_at {
            Some((g, s)) => (self.true_side(g, q) > 0.0) == (s > 0),
            None => true,
        }
    }

    /// The true unit at `q`: the number of interfaces above it.
    pub fn true_unit(&self, q: [f64; 3]) -> usize {
        let mut z = q[2];
        for f in 0..self.faults.len() {
            if self.counts(f, q) && self.true_side(f, q) > 0.0 {
                z += self.faults[f].throw;
            }
        }
        self.tops
            .iter()
            .filter(|&&t| t + self.dip[0] * q[0] + self.dip[1] * q[1] > z)
            .count()
    }

    /// The height of interface `k` in the block `key` (the kernel's interfaces).
    pub fn height(&self, k: usize, key: BlockKey, p: [f64; 2]) -> f64 {
        let mut z = self.tops[k] + self.dip[0] * p[0] + self.dip[1] * p[1];
        for (f, fault) in self.faults.iter().enumerate() {
            if key.side(f) == Some(1) {
                z -= fault.throw;
            }
        }
        z
    }
}
