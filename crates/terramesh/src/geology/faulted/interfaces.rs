//! Per-block interface surfaces: every interface fitted in every block from that block's
//! contacts, or taken from a neighbouring block shifted by the faults' throws.

use serde::Serialize;
use std::collections::{BTreeMap, HashMap};
use terramesh_faults::{BlockKey, FaultSet};
use terramesh_geostat::{
    experimental, fit_auto, Data, Drift, DualKriging, Duplicates, LagSettings, ModelKind, Named,
    Weighting,
};
use terramesh_io::boreholes::Boreholes;
use terramesh_io::faults::FaultPick;

use super::contacts::{block_contacts, block_name, Contact};
use crate::error::{Error, Result};
use crate::geology::fields::MIN_KRIGED;
use crate::plan::{FaultKind, GeologyPlan};

/// Fewer contacts of an interface than this in a block, and the block's plane takes the
/// gradient of all the interface's contacts (its own contacts fix the level).
pub const PLANE_CONTACTS: usize = 3;

/// A unit thinner than this (metres), or than `min_thickness`, pinches out in a faulted model:
/// two interfaces closer than a millimetre would cut cells into slivers of no volume.
pub const PINCH: f64 = 1e-3;

/// The thickness of a unit whose interfaces are `t` apart, pinching out at `min`: none up to
/// `min`, `t` from `min + PINCH` on, and between them rising linearly from 0 to `min + PINCH`,
/// so that the interface under the unit is continuous where the unit starts. (A jump there
/// from 0 to `min`, the rule before, sent the kernel's search for an edge's crossing of the
/// interface to the jump, where two edges of one face could get the same new node and a cell
/// no volume.)
fn pinched(t: f64, min: f64) -> f64 {
    if t <= min {
        0.0
    } else if t < min + PINCH {
        (t - min) * (min + PINCH) / PINCH
    } else {
        t
    }
}

/// Points `[x, y]` with a value.
type Samples = Vec<([f64; 2], f64)>;

/// A fitted interface in one block: universal kriging with a linear drift of the block's
/// contacts where they are enough ([`kriged`]), else a plane; plus the residuals of its
/// contacts spread by inverse distance (squared), so that the surface passes through every
/// contact.
#[derive(Clone)]
struct Fit {
    plane: [f64; 3],
    kriged: Option<DualKriging>,
    residuals: Vec<([f64; 2], f64)>,
}

/// Fewer distinct contact locations of an interface than this in a block, and it is a plane
/// plus residuals instead of kriged: a variogram is fitted from [`MIN_KRIGED`] locations, and
/// universal kriging with a linear drift (3 terms) needs more than twice its terms, as the
/// unfaulted model's fields (`geology::fields`).
pub const KRIGED_CONTACTS: usize = 7;

/// The block's contacts `p` kriged as the unfaulted model's interfaces are
/// (`geology::fields`: the variogram fitted automatically, universal kriging with a linear
/// drift over all the contacts), or `None` when they are too few (fewer than
/// [`KRIGED_CONTACTS`] distinct locations), all equal, or no variogram fits.
fn kriged(p: &[([f64; 2], f64)]) -> Option<DualKriging> {
    let data = Data::new(
        p.iter().map(|(q, _)| *q).collect(),
        p.iter().map(|(_, z)| *z).collect(),
        Duplicates::Mean,
    )
    .ok()?;
    let drift = Drift::Linear;
    if data.len() < KRIGED_CONTACTS.max(MIN_KRIGED) || data.len() <= 2 * drift.terms() {
        return None;
    }
    let (lo, hi) = data
        .z()
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if hi - lo <= 1e-12 * hi.abs().max(1.0) {
        return None;
    }
    let lags = experimental(&data, &LagSettings::default()).ok()?;
    let (fit, _) = fit_auto(&data, &lags, Weighting::Cressie, ModelKind::ALL).ok()?;
    DualKriging::new(data.xy(), data.z(), fit.variogram)
}

impl Fit {
    /// How it is interpolated, for `model.json`.
    fn method(&self) -> &'static str {
        if self.kriged.is_some() {
            "kriging"
        } else {
            "plane"
        }
    }

    /// The surface before the residuals.
    fn base(&self, p: [f64; 2]) -> f64 {
        let plane = self.plane[0] + self.plane[1] * p[0] + self.plane[2] * p[1];
        match &self.kriged {
            Some(k) => {
                let e = k.at(p);
                if e.is_finite() {
                    e
                } else {
                    plane
                }
            }
            None => plane,
        }
    }

    fn at(&self, p: [f64; 2]) -> f64 {
        let z = self.base(p);
        let (mut num, mut den) = (0.0, 0.0);
        for (q, r) in &self.residuals {
            let d2 = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
            if d2 < 1e-18 {
                return z + r;
            }
            num += r / d2;
            den += 1.0 / d2;
        }
        if den > 0.0 {
            z + num / den
        } else {
            z
        }
    }
}

/// Least squares plane `z = a + b x + c y` through `pts` (x, y relative to `o`), `None` when
/// they are fewer than 3 or on one line.
fn plane_fit(pts: &[([f64; 2], f64)], o: [f64; 2]) -> Option<[f64; 3]> {
    if pts.len() < PLANE_CONTACTS {
        return None;
    }
    let mut m = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    for (p, z) in pts {
        let v = [1.0, p[0] - o[0], p[1] - o[1]];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += v[i] * v[j];
            }
            r[i] += v[i] * z;
        }
    }
    let det = |a: &[[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(&m);
    let scale = m[0][0] * m[1][1] * m[2][2];
    // nearly on one line: the plane's gradient is not fixed
    if d.abs().partial_cmp(&(1e-3 * scale.abs())) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut a = m;
        for row in 0..3 {
            a[row][k] = r[row];
        }
        *xk = det(&a) / d;
    }
    // back to absolute x, y
    Some([x[0] - x[1] * o[0] - x[2] * o[1], x[1], x[2]])
}

/// Where an interface of a block comes from, for `model.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InterfaceSource {
    /// The unit whose top it is.
    pub unit: String,
    /// `contacts` (fitted to the block's own contacts) or `throw` (the neighbouring block's
    /// surface shifted by the faults' throws).
    pub from: &'static str,
    /// How the surface it takes is interpolated: `kriging` (universal kriging with a linear
    /// drift of the block's contacts, at least [`KRIGED_CONTACTS`] distinct locations) or
    /// `plane` (their least-squares plane, or the interface's gradient through them, with
    /// fewer), each plus the residuals at the contacts by inverse distance; `gradient`
    /// without any block's surface.
    pub method: &'static str,
    /// The block's contacts of this interface.
    pub contacts: usize,
    /// For `throw`: the block whose surface it takes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub block: Option<String>,
    /// For `throw`: the vertical shift added, metres (negative: down).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shift: Option<f64>,
}

/// Every interface per fault block.
pub struct BlockInterfaces {
    /// Per block with contacts, per interface: its fit.
    /// (A sorted map: a few blocks, looked up for every node the mesher places, where hashing
    /// cost a fifth of `terramesh model`'s time.)
    fits: BTreeMap<BlockKey, Vec<Option<Fit>>>,
    /// Per interface, the gradient of all its contacts.
    gradient: Vec<[f64; 2]>,
    /// Per fault: the signed shift of the hanging wall (negative: down), where given.
    throws: Vec<Option<f64>>,
    /// Per block with contacts, per interface, the contacts.
    counts: HashMap<BlockKey, Vec<usize>>,
    /// Pinch-out thickness.
    min_thickness: f64,
    /// Fault names, for block names.
    names: Vec<String>,
    /// Every contact as `(hole, unit, xyz, block)`.
    pub contacts: Vec<Contact>,
    /// This set's number in the process, for the per-thread memo of [`BlockInterfaces::height`].
    id: u64,
}

/// The heights of the interfaces (from the top) that [`BlockInterfaces::height`] found at one
/// point of one block of one set: a slot of the per-thread memo. The first [`INLINE`] heights
/// lie in the slot itself, so that a look-up reads one place of memory (with them behind a
/// pointer, the second cache miss was a sixth of the look-up's time); more go to `more`.
struct Last {
    id: u64,
    key: BlockKey,
    p: [f64; 2],
    /// How many heights are known.
    n: usize,
    z: [f64; INLINE],
    more: Vec<f64>,
}

/// The heights kept in a memo's slot itself.
const INLINE: usize = 8;

impl Last {
    fn get(&self, k: usize) -> f64 {
        if k < INLINE {
            self.z[k]
        } else {
            self.more[k - INLINE]
        }
    }

    fn push(&mut self, z: f64) {
        if self.n < INLINE {
            self.z[self.n] = z;
        } else {
            self.more.push(z);
        }
        self.n += 1;
    }
}

/// Slots of the per-thread memo (a power of two): about 9 MB per thread.
const MEMO_SLOTS: usize = 1 << 16;

thread_local! {
    /// Per thread, the columns of heights last found, each in the slot its set, block and
    /// point hash to (a direct-mapped cache: a new point evicts the one in its slot).
    static MEMO: std::cell::RefCell<Vec<Last>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The memo's slot of set `id`, block `key` and point `p`.
fn slot(id: u64, key: BlockKey, p: [f64; 2]) -> usize {
    let mut h = id.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    for w in [
        key.positive,
        key.counts,
        p[0].to_bits(),
        p[1].to_bits().rotate_left(32),
    ] {
        h = (h ^ w).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        h ^= h >> 29;
    }
    (h >> (64 - MEMO_SLOTS.trailing_zeros())) as usize
}

/// The next [`BlockInterfaces`]' number.
static NEXT_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

impl BlockInterfaces {
    /// Assigns every contact of a unit below the first to the block it lies in
    /// ([`block_contacts`]) and fits every interface in every block that has contacts of it.
    pub fn new(
        g: &GeologyPlan,
        set: &FaultSet,
        boreholes: Option<&Boreholes>,
        picks: &[FaultPick],
    ) -> Result<BlockInterfaces> {
        let interfaces = g.units.len() - 1;
        let contacts = block_contacts(set, boreholes, picks, g)?;
        // A sorted map: the gradient below takes the block with the most contacts, and a tie
        // must not be broken by a hash map's per-process order (it was: the same project
        // gave a different mesh from run to run).
        let mut by_block: BTreeMap<BlockKey, Vec<Samples>> = BTreeMap::new();
        let mut all: Vec<Vec<([f64; 2], f64)>> = vec![Vec::new(); interfaces];
        for (_, unit, p, key) in &contacts {
            let k = unit - 1;
            by_block
                .entry(*key)
                .or_insert_with(|| vec![Vec::new(); interfaces])[k]
                .push(([p[0], p[1]], p[2]));
            all[k].push(([p[0], p[1]], p[2]));
        }
        for (k, a) in all.iter().enumerate() {
            if a.is_empty() {
                return Err(Error::NoContactOfTop {
                    unit: g.units[k + 1].clone(),
                });
            }
        }
        let origin = all
            .iter()
            .flatten()
            .next()
            .map(|(p, _)| *p)
            .unwrap_or([0.0; 2]);
        // The gradient of each interface from all its contacts, each block's offset removed:
        // the plane of the block with the most contacts when it has a plane, else flat.
        let gradient: Vec<[f64; 2]> = (0..interfaces)
            .map(|k| {
                by_block
                    .values()
                    .filter(|v| v[k].len() >= PLANE_CONTACTS)
                    .max_by_key(|v| v[k].len())
                    .and_then(|v| plane_fit(&v[k], origin))
                    .map(|p| [p[1], p[2]])
                    .unwrap_or([0.0, 0.0])
            })
            .collect();
        let mut fits = BTreeMap::new();
        let mut counts = HashMap::new();
        for (key, pts) in &by_block {
            let mut row = Vec::with_capacity(interfaces);
            for (k, p) in pts.iter().enumerate() {
                if p.is_empty() {
                    row.push(None);
                    continue;
                }
                let plane = plane_fit(p, origin).unwrap_or_else(|| {
                    let [gx, gy] = gradient[k];
                    let a = p
                        .iter()
                        .map(|(q, z)| z - gx * q[0] - gy * q[1])
                        .sum::<f64>()
                        / p.len() as f64;
                    [a, gx, gy]
                });
                let mut fit = Fit {
                    plane,
                    kriged: kriged(p),
                    residuals: Vec::new(),
                };
                fit.residuals = p.iter().map(|(q, z)| (*q, z - fit.base(*q))).collect();
                row.push(Some(fit));
            }
            counts.insert(*key, pts.iter().map(Vec::len).collect());
            fits.insert(*key, row);
        }
        Ok(BlockInterfaces {
            fits,
            gradient,
            throws: g
                .faults
                .iter()
                .map(|f| {
                    f.throw.map(|t| match f.kind {
                        FaultKind::Normal => -t,
                        FaultKind::Reverse => t,
                    })
                })
                .collect(),
            counts,
            min_thickness: g.min_thickness,
            names: set.faults.iter().map(|f| f.name.clone()).collect(),
            contacts,
            id: NEXT_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
        })
    }

    /// Where interface `k` of block `key` comes from: its own fit, or the block with a fit
    /// across the fewest faults and the shift by their throws (`Err` naming the first of those
    /// faults without a throw).
    fn source(&self, k: usize, key: BlockKey) -> std::result::Result<(BlockKey, f64), usize> {
        if self.fits.get(&key).is_some_and(|r| r[k].is_some()) {
            return Ok((key, 0.0));
        }
        // Bit f set: fault f counts in both blocks and they lie on opposite sides of it.
        let differ = |j: &BlockKey| (key.positive ^ j.positive) & key.counts & j.counts;
        let mut best: Option<(u32, BlockKey)> = None;
        // The blocks in order (a sorted map), the first with the fewest faults between wins.
        for (j, row) in &self.fits {
            if row[k].is_none() {
                continue;
            }
            let n = differ(j).count_ones();
            if best.is_none_or(|(m, _)| n < m) {
                best = Some((n, *j));
            }
        }
        let (_, j) = best.expect("every interface has a contact");
        let mut shift = 0.0;
        let bits = differ(&j);
        for f in (0..self.names.len()).filter(|&f| bits >> f & 1 == 1) {
            let Some(t) = self.throws[f] else {
                return Err(f);
            };
            // this block on the hanging wall: moved by t relative to the footwall
            shift += if key.positive >> f & 1 == 1 { t } else { -t };
        }
        Ok((j, shift))
    }

    /// The raw height of interface `k` in block `key` at `p`, before the column's order.
    fn raw(&self, k: usize, key: BlockKey, p: [f64; 2]) -> f64 {
        match self.source(k, key) {
            Ok((j, shift)) => self.fits[&j][k].as_ref().expect("a fit").at(p) + shift,
            // Checked before meshing for the blocks found; a block met only by the mesher
            // takes the gradient through the mean of all contacts.
            Err(_) => {
                let [gx, gy] = self.gradient[k];
                gx * p[0] + gy * p[1]
            }
        }
    }

    /// The height of interface `k` (the top of unit `k + 1`) in block `key` at `p`: never
    /// above the interface above it, and onto it where the unit between is thinner than
    /// `min_thickness` (pinched out), continuous where the unit starts (`pinched`).
    pub fn height(&self, k: usize, key: BlockKey, p: [f64; 2]) -> f64 {
        // The mesher asks for interfaces 0, 1, 2, ... at one point in turn, each needs those
        // above it, and it asks again at the same points (a column's nodes share their plan
        // point; the quality pass tests a node's cells many times): the heights found at a
        // point are kept per thread, in a slot of a memo, so that a point costs one evaluation
        // per interface. The values do not depend on what the memo holds.
        MEMO.with(|memo| {
            let mut memo = memo.borrow_mut();
            if memo.is_empty() {
                memo.resize_with(MEMO_SLOTS, || Last {
                    id: u64::MAX,
                    key: BlockKey {
                        positive: 0,
                        counts: 0,
                    },
                    p: [f64::NAN; 2],
                    n: 0,
                    z: [0.0; INLINE],
                    more: Vec::new(),
                });
            }
            let last = &mut memo[slot(self.id, key, p)];
            if last.id != self.id || last.key != key || last.p != p {
                last.id = self.id;
                last.key = key;
                last.p = p;
                last.n = 0;
                last.more.clear();
            }
            let mut above = match last.n {
                0 => f64::INFINITY,
                n => last.get(n - 1),
            };
            for j in last.n..=k {
                let mut z = self.raw(j, key, p).min(above);
                if above.is_finite() {
                    z = above - pinched(above - z, self.min_thickness.max(PINCH));
                }
                last.push(z);
                above = z;
            }
            last.get(k)
        })
    }

    /// Checks that every block in `keys` gets every interface: a block without contacts of one
    /// needs the throw of every fault between it and the block it takes it from.
    pub fn check_blocks(&self, keys: &[BlockKey], units: &[String]) -> Result<()> {
        for key in keys {
            for k in 0..self.gradient.len() {
                if let Err(f) = self.source(k, *key) {
                    return Err(Error::NoThrow {
                        fault: self.names[f].clone(),
                        block: block_name(&self.names, key),
                        unit: units[k + 1].clone(),
                    });
                }
            }
        }
        Ok(())
    }

    /// How interface `k` of block `j` (one with a fit) is interpolated.
    fn method(&self, k: usize, j: BlockKey) -> &'static str {
        self.fits
            .get(&j)
            .and_then(|r| r[k].as_ref())
            .map_or("gradient", Fit::method)
    }

    /// Where every interface of `key` comes from.
    pub fn sources(&self, key: BlockKey, units: &[String]) -> Vec<InterfaceSource> {
        (0..self.gradient.len())
            .map(|k| {
                let contacts = self.counts.get(&key).map(|c| c[k]).unwrap_or(0);
                match self.source(k, key) {
                    Ok((j, _)) if j == key => InterfaceSource {
                        unit: units[k + 1].clone(),
                        from: "contacts",
                        method: self.method(k, j),
                        contacts,
                        block: None,
                        shift: None,
                    },
                    Ok((j, s)) => InterfaceSource {
                        unit: units[k + 1].clone(),
                        from: "throw",
                        method: self.method(k, j),
                        contacts,
                        block: Some(block_name(&self.names, &j)),
                        shift: Some(s),
                    },
                    Err(_) => InterfaceSource {
                        unit: units[k + 1].clone(),
                        from: "gradient",
                        method: "gradient",
                        contacts,
                        block: None,
                        shift: None,
                    },
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::{kriged, pinched, PINCH};
    use terramesh_geostat::DualKriging;
    use terramesh_geostat::{
        kriging, Anisotropy, Data, Drift, Duplicates, Method, ModelKind, Neighbourhood, Structure,
        Variogram,
    };

    /// A bumpy interface of 25 contacts at UTM-sized coordinates (x 5e5, y 5e6), some 2 m
    /// apart, with a few decimetres of noise.
    fn contacts() -> Vec<([f64; 2], f64)> {
        let mut s = 7u64;
        let mut next = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut p: Vec<([f64; 2], f64)> = Vec::new();
        for i in 0..25 {
            let (x, y) = if i % 8 == 7 {
                (p[i - 1].0[0] - 5.0e5 + 2.0, p[i - 1].0[1] - 5.0e6 - 1.5)
            } else {
                (400.0 * next(), 400.0 * next())
            };
            let z = 120.0 - 0.05 * x
                + 0.02 * y
                + 3.0 * (x / 60.0).sin() * (y / 90.0).cos()
                + 0.4 * next();
            p.push(([5.0e5 + x, 5.0e6 + y], z));
        }
        p
    }

    /// The dual form (one solve per interface, then `Σ b_i γ(p − x_i) + a · (1, x, y)`) gives
    /// the global universal kriging predictor's estimate (a system per point) to 1e-7 m, at
    /// the contacts and between them, for bounded and unbounded models, a nugget, nested
    /// structures and anisotropy, and for the variogram the block's fit chooses.
    #[test]
    fn the_dual_form_is_the_kriging_estimate() {
        let p = contacts();
        let data = Data::new(
            p.iter().map(|(q, _)| *q).collect(),
            p.iter().map(|(_, z)| *z).collect(),
            Duplicates::Mean,
        )
        .unwrap();
        let one = |k, n, s, r| Variogram::single(k, n, s, r).unwrap();
        let mut nested = one(ModelKind::Spherical, 0.0, 2.0, 120.0);
        nested
            .structures
            .push(Structure::new(ModelKind::Gaussian, 1.5, 300.0));
        let mut aniso = one(ModelKind::Exponential, 0.05, 4.0, 200.0);
        aniso.anisotropy = Some(Anisotropy {
            angle: 30.0,
            ratio: 0.4,
        });
        let models = [
            one(ModelKind::Spherical, 0.0, 3.0, 150.0),
            one(ModelKind::Exponential, 0.1, 3.0, 250.0),
            one(ModelKind::Gaussian, 0.01, 3.0, 180.0),
            one(ModelKind::Power, 0.0, 0.5, 1.5),
            one(ModelKind::Linear, 0.02, 0.01, 1.0),
            nested,
            aniso,
        ];
        let mut targets: Vec<[f64; 2]> = p.iter().map(|(q, _)| *q).collect();
        for i in 0..21 {
            for j in 0..21 {
                targets.push([
                    5.0e5 - 50.0 + 25.0 * i as f64,
                    5.0e6 - 50.0 + 25.0 * j as f64,
                ]);
            }
        }
        let check = |dual: &DualKriging, v: &Variogram| {
            let k = kriging(
                &data,
                v,
                Method::Universal(Drift::Linear),
                Neighbourhood::All,
                false,
            )
            .unwrap();
            let mut want = vec![0.0; targets.len()];
            k.predict(&targets, &mut want, None).unwrap();
            for (t, w) in targets.iter().zip(&want) {
                let got = dual.at(*t);
                assert!((got - w).abs() < 1e-7, "{v:?} at {t:?}: {got} against {w}");
            }
            // exact at the contacts (kriging interpolates them)
            for (q, z) in &p {
                assert!((dual.at(*q) - z).abs() < 1e-7, "{v:?} at {q:?}");
            }
        };
        for v in &models {
            let dual = DualKriging::new(data.xy(), data.z(), v.clone()).expect("solvable");
            check(&dual, v);
        }
        let fitted = kriged(&p).expect("25 contacts are kriged");
        check(&fitted, &fitted.variogram().clone());
    }

    /// A pinching unit's thickness is continuous in the interfaces' distance and is that
    /// distance from `min + PINCH` on: nothing up to `min`, then a steep ramp.
    #[test]
    fn a_pinching_unit_thins_continuously() {
        for min in [PINCH, 0.5] {
            assert_eq!(pinched(0.0, min), 0.0);
            assert_eq!(pinched(min, min), 0.0);
            assert_eq!(pinched(min + PINCH, min), min + PINCH);
            assert_eq!(pinched(3.0, min), 3.0);
            let mut last = 0.0;
            for i in 0..=4000 {
                let t = min - PINCH + i as f64 * 1e-6;
                let z = pinched(t, min);
                assert!(z >= last && z - last <= (min + PINCH) / PINCH * 1e-6 + 1e-12);
                last = z;
            }
        }
    }
}
