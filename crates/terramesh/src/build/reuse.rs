//! The DSM kept in a build folder for `terramesh model` to reuse: `dsm-cache.bin`.
//!
//! Every `build` and `model` writes the DSM that the geological model stands on (the planar
//! mesh, its vertex elevations, the DSM grid's layout, the UTM zone and the borehole points
//! inserted as vertices) with a key of everything that made it: the `[region]`, `[source]`,
//! `[sampling]`, `[mesh]` and `[interpolation]` settings, `export.grid_spacing`, the bytes of
//! every local input file they name (the source or its fallback, a region or corners file, a
//! variogram file; a web source by its address only) and terramesh's version. `terramesh
//! model` into a folder whose `dsm-cache.bin` has the same key, and the same borehole points,
//! reads that DSM instead of sampling, fitting, meshing and interpolating again. Anything else
//! (no file, another key, other boreholes, a damaged file, realisations asked for) builds the
//! DSM afresh. The `[geology]` settings other than the boreholes are not in the key: changing
//! them is what the reuse is for.
//!
//! Layout (little-endian): the magic `TMDSM\0\0\x01`, the key (u64), the zone (u8: 0 none,
//! else its number; u8: 1 north), the origin (2 f64), points (u64 count, 2 f64 each),
//! triangles (u64, 3 u32 each), constraint edges (u64, 2 u32 each), borehole points (u64, 2
//! f64 each), elevations (one f64 per point), the grid (4 f64, 2 u64), the sample count
//! (u64), the source's name (u64 length, UTF-8), and a checksum of all that (u64).

use std::borrow::Cow;
use std::hash::{Hash, Hasher};
use std::io::Write;
use std::path::Path;

use terramesh_core::coords::Zone;
use terramesh_io::grid_write::RasterGrid;
use terramesh_io::output::Output;
use terramesh_mesh::Mesh;

use crate::error::{Context, Result};
use crate::project::Project;

/// The file's name in the build folder.
pub const FILE: &str = "dsm-cache.bin";

const MAGIC: &[u8; 8] = b"TMDSM\0\0\x01";

/// A DSM as kept in [`FILE`]: the build writes it from its own mesh and elevations
/// (borrowed), a reading owns them.
#[derive(Debug, Clone, PartialEq)]
pub struct DsmState<'a> {
    /// The key of the settings and inputs that made it ([`key`]).
    pub key: u64,
    /// The UTM zone of a geographic project.
    pub zone: Option<Zone>,
    /// The planar mesh.
    pub mesh: Cow<'a, Mesh>,
    /// The borehole points inserted as vertices.
    pub collars: Cow<'a, [[f64; 2]]>,
    /// The DSM elevation at every vertex.
    pub dsm: Cow<'a, [f64]>,
    /// The DSM grid's layout (the interface grids use it).
    pub grid: RasterGrid,
    /// How many samples it was made from.
    pub samples: u64,
    /// The source actually sampled.
    pub source: String,
}

fn hasher() -> std::collections::hash_map::DefaultHasher {
    std::collections::hash_map::DefaultHasher::new()
}

/// Feeds a local file's bytes into `h`, or, for a folder of tiles (which may be large), the
/// name, size and modification time of every entry under it (sorted by name); nothing for a
/// path that does not exist or is remote (its name is in the settings already).
fn hash_path(h: &mut impl Hasher, path: &Path) -> Result<()> {
    if path.is_file() {
        let bytes =
            std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
        bytes.hash(h);
    } else if path.is_dir() {
        let mut entries: Vec<_> = std::fs::read_dir(path)
            .with_context(|| format!("cannot list {}", path.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        entries.sort();
        for e in entries {
            e.file_name().hash(h);
            if e.is_dir() {
                hash_path(h, &e)?;
            } else if let Ok(m) = e.metadata() {
                m.len().hash(h);
                m.modified().ok().hash(h);
            }
        }
    }
    Ok(())
}

/// The mesh sub-plan as the key has always written it (`MeshSection { .. }`, its Debug form
/// before the plan), with the keys added since (`max_vertices`, `strips`) only when set.
fn mesh_key(m: &crate::plan::MeshPlan) -> String {
    let mut text = format!(
        "MeshSection {{ max_area: {:?}, max_edge: {:?}, min_angle: {:?}, smooth: {:?}, \
         smoother: {:?}, insert_samples: {:?}, max_error: {:?} }}",
        m.max_area, m.max_edge, m.min_angle, m.smooth, m.smoother, m.insert_samples, m.max_error
    );
    if m.max_vertices.is_some() || m.strips.is_some() {
        text += &format!(
            " max_vertices: {:?}, strips: {:?}",
            m.max_vertices, m.strips
        );
    }
    text
}

/// The interpolation sub-plan as the key has always written it (`InterpolationSection { .. }`,
/// its Debug form before the single commands' settings joined the plan): the settings a build
/// reads, in their order, an unset `variogram` as `"auto"`. The fields that only the single
/// commands set (`mean`, `parts`, `lag`, `radius`, `modes`, `external_drift`, `duplicates`;
/// no project key reaches them) are not in it, so that adding one keeps every kept DSM.
fn interpolation_key(ip: &crate::plan::InterpolationPlan) -> String {
    format!(
        "InterpolationSection {{ methods: {:?}, drift: {:?}, variogram: {:?}, model: {:?}, \
         neighbors: {:?}, idw_power: {:?}, idw_neighbors: {:?}, cv_folds: {:?}, \
         realisations: {:?}, seed: {:?}, fit: {:?}, fit_model: {:?}, anisotropy: {:?}, \
         external_drift_grid: {:?} }}",
        ip.methods,
        ip.drift,
        ip.variogram_or_auto(),
        ip.model,
        ip.neighbors,
        ip.idw_power,
        ip.idw_neighbors,
        ip.cv_folds,
        ip.realisations,
        ip.seed,
        ip.fit.unwrap_or_default(),
        ip.fit_model,
        ip.anisotropy,
        ip.external_drift_grid
    )
}

/// The key of what makes `p`'s DSM (paths relative to `base`): see the module documentation.
pub fn key(p: &Project, base: &Path) -> Result<u64> {
    let mut h = hasher();
    env!("CARGO_PKG_VERSION").hash(&mut h);
    format!(
        "{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{}|{}|{:?}",
        p.region.corners,
        p.region.file,
        p.region.zone,
        p.region.crs,
        p.source,
        p.sampling,
        mesh_key(&p.mesh),
        interpolation_key(&p.interpolation),
        p.export.grid_spacing
    )
    // The sub-plan's name as the key has always written it, so that a DSM kept by an earlier
    // version stays valid.
    .replace("SamplingPlan {", "SamplingSection {")
    .hash(&mut h);
    // `interpolation.neighbors` and `cv_folds` print 0 whether set to 0 or unset (left to the
    // build, `scale.rs`), so that the keys of projects setting neither are what they were; an
    // explicit 0 (asked for at every size) is told apart here.
    let ip = &p.interpolation;
    if ip.neighbors.get() == Some(0) || ip.cv_folds.get() == Some(0) {
        (ip.neighbors.get(), ip.cv_folds.get()).hash(&mut h);
    }
    let mut files = Vec::new();
    if let Ok(s) = p.source_spec(base) {
        files.push(std::path::PathBuf::from(s));
    }
    if let Some(c) = &p.region.corners {
        files.push(base.join(c.trim()));
    }
    if let Some(f) = &p.region.file {
        files.push(base.join(f));
    }
    if p.interpolation.variogram_or_auto() != "auto" {
        files.push(base.join(p.interpolation.variogram_or_auto()));
    }
    for f in files {
        hash_path(&mut h, &f)?;
    }
    Ok(h.finish())
}

/// The file's bytes on their way to a writer, and the checksum of them (the hash of the
/// bytes as one slice: their length, then the bytes, fed in pieces).
struct Sink<'w, W: Write> {
    w: &'w mut W,
    h: std::collections::hash_map::DefaultHasher,
}

impl<W: Write> Sink<'_, W> {
    fn put(&mut self, b: &[u8]) -> std::io::Result<()> {
        self.h.write(b);
        self.w.write_all(b)
    }
    fn u64(&mut self, v: u64) -> std::io::Result<()> {
        self.put(&v.to_le_bytes())
    }
    /// Numbers as their little-endian bytes, in pieces of 4 KiB: no copy of a whole array.
    fn nums<T: Copy, const N: usize>(
        &mut self,
        v: &[T],
        bytes: impl Fn(T) -> [u8; N],
    ) -> std::io::Result<()> {
        let mut piece = [0u8; 4096];
        for c in v.chunks(4096 / N) {
            for (k, &x) in c.iter().enumerate() {
                piece[N * k..N * (k + 1)].copy_from_slice(&bytes(x));
            }
            self.put(&piece[..N * c.len()])?;
        }
        Ok(())
    }
    fn f64s(&mut self, v: &[f64]) -> std::io::Result<()> {
        self.nums(v, f64::to_le_bytes)
    }
    fn u32s(&mut self, v: &[u32]) -> std::io::Result<()> {
        self.nums(v, u32::to_le_bytes)
    }
}

impl DsmState<'_> {
    /// The file's length before its checksum.
    fn body_len(&self) -> usize {
        let m = &self.mesh;
        MAGIC.len()
            + 8
            + 2
            + 16
            + 8
            + 16 * m.points.len()
            + 8
            + 12 * m.triangles.len()
            + 8
            + 8 * m.constraint_edges.len()
            + 8
            + 16 * self.collars.len()
            + 8 * self.dsm.len()
            + 32
            + 16
            + 8
            + 8
            + self.source.len()
    }

    /// Writes the file's bytes to `w` as they are made, no copy of the DSM held.
    pub fn write_to<W: Write>(&self, w: &mut W) -> std::io::Result<()> {
        let m = &self.mesh;
        let mut s = Sink { w, h: hasher() };
        s.h.write_usize(self.body_len());
        s.put(MAGIC)?;
        s.u64(self.key)?;
        match self.zone {
            Some(z) => s.put(&[z.number(), u8::from(z.is_north())])?,
            None => s.put(&[0, 0])?,
        }
        s.f64s(&m.origin)?;
        s.u64(m.points.len() as u64)?;
        s.f64s(m.points.as_flattened())?;
        s.u64(m.triangles.len() as u64)?;
        s.u32s(m.triangles.as_flattened())?;
        s.u64(m.constraint_edges.len() as u64)?;
        s.u32s(m.constraint_edges.as_flattened())?;
        s.u64(self.collars.len() as u64)?;
        s.f64s(self.collars.as_flattened())?;
        s.f64s(&self.dsm)?;
        let g = &self.grid;
        s.f64s(&[g.xmin, g.ymin, g.xmax, g.ymax])?;
        s.u64(g.nx as u64)?;
        s.u64(g.ny as u64)?;
        s.u64(self.samples)?;
        s.u64(self.source.len() as u64)?;
        s.put(self.source.as_bytes())?;
        let sum = s.h.finish();
        s.w.write_all(&sum.to_le_bytes())
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(self.body_len() + 8);
        // Writing into a vector cannot fail.
        let _ = self.write_to(&mut b);
        b
    }

    /// Reads the bytes of [`DsmState::to_bytes`]; `None` when they are not such a file (another
    /// version, truncated, damaged: the checksum differs, an index is out of range).
    pub fn from_bytes(b: &[u8]) -> Option<DsmState<'static>> {
        let body = b.len().checked_sub(8)?;
        let mut h = hasher();
        b[..body].hash(&mut h);
        if h.finish().to_le_bytes() != b[body..] || !b.starts_with(MAGIC) {
            return None;
        }
        let mut r = Reader {
            b: &b[..body],
            at: MAGIC.len(),
        };
        let key = r.u64()?;
        let (number, north) = (r.u8()?, r.u8()?);
        let zone = match number {
            0 => None,
            n => Some(Zone::new(n, north == 1).ok()?),
        };
        let origin = [r.f64()?, r.f64()?];
        let np = r.count(16)?;
        let points = (0..np)
            .map(|_| Some([r.f64()?, r.f64()?]))
            .collect::<Option<Vec<_>>>()?;
        let nt = r.count(12)?;
        let triangles = (0..nt)
            .map(|_| Some([r.u32()?, r.u32()?, r.u32()?]))
            .collect::<Option<Vec<_>>>()?;
        let ne = r.count(8)?;
        let constraint_edges = (0..ne)
            .map(|_| Some([r.u32()?, r.u32()?]))
            .collect::<Option<Vec<_>>>()?;
        let in_range = |v: &u32| (*v as usize) < np;
        if !triangles.iter().flatten().all(in_range)
            || !constraint_edges.iter().flatten().all(in_range)
        {
            return None;
        }
        let nc = r.count(16)?;
        let collars = (0..nc)
            .map(|_| Some([r.f64()?, r.f64()?]))
            .collect::<Option<Vec<_>>>()?;
        let dsm = (0..np).map(|_| r.f64()).collect::<Option<Vec<_>>>()?;
        let grid = RasterGrid {
            xmin: r.f64()?,
            ymin: r.f64()?,
            xmax: r.f64()?,
            ymax: r.f64()?,
            nx: usize::try_from(r.u64()?).ok()?,
            ny: usize::try_from(r.u64()?).ok()?,
        };
        let samples = r.u64()?;
        let len = r.count(1)?;
        let source = String::from_utf8(r.take(len)?.to_vec()).ok()?;
        (r.at == r.b.len()).then_some(DsmState {
            key,
            zone,
            mesh: Cow::Owned(Mesh {
                origin,
                points,
                triangles,
                constraint_edges,
            }),
            collars: Cow::Owned(collars),
            dsm: Cow::Owned(dsm),
            grid,
            samples,
            source,
        })
    }

    /// Writes [`FILE`] into `dir`, atomically.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let path = dir.join(FILE);
        let mut o = Output::create(Some(&path))
            .with_context(|| format!("cannot write {}", path.display()))?;
        self.write_to(&mut o)
            .with_context(|| format!("writing {}", path.display()))?;
        o.commit()
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(())
    }

    /// The state kept in `dir` when it has the key `key`; `None` when there is none, it was
    /// made from other settings, or it cannot be read.
    pub fn read(dir: &Path, key: u64) -> Option<DsmState<'static>> {
        let bytes = std::fs::read(dir.join(FILE)).ok()?;
        DsmState::from_bytes(&bytes).filter(|s| s.key == key)
    }
}

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.at.checked_add(n)?;
        let s = self.b.get(self.at..end)?;
        self.at = end;
        Some(s)
    }
    fn u8(&mut self) -> Option<u8> {
        self.take(1).map(|s| s[0])
    }
    fn u32(&mut self) -> Option<u32> {
        self.take(4)
            .map(|s| u32::from_le_bytes(s.try_into().unwrap()))
    }
    fn u64(&mut self) -> Option<u64> {
        self.take(8)
            .map(|s| u64::from_le_bytes(s.try_into().unwrap()))
    }
    fn f64(&mut self) -> Option<f64> {
        self.take(8)
            .map(|s| f64::from_le_bytes(s.try_into().unwrap()))
    }
    /// A count of items of `size` bytes each, refused when more than the bytes left hold.
    fn count(&mut self, size: usize) -> Option<usize> {
        let n = usize::try_from(self.u64()?).ok()?;
        (n.checked_mul(size)? <= self.b.len() - self.at).then_some(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state() -> DsmState<'static> {
        DsmState {
            key: 42,
            zone: Some(Zone::new(32, true).unwrap()),
            mesh: Cow::Owned(Mesh {
                origin: [500_000.0, 5_400_000.0],
                points: vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]],
                triangles: vec![[0, 1, 2], [0, 2, 3]],
                constraint_edges: vec![[0, 1], [1, 2], [2, 3], [3, 0]],
            }),
            collars: Cow::Owned(vec![[500_005.0, 5_400_005.0]]),
            dsm: Cow::Owned(vec![1.0, 2.5, -3.25, 1e-300]),
            grid: RasterGrid {
                xmin: 0.0,
                ymin: 0.0,
                xmax: 10.0,
                ymax: 10.0,
                nx: 3,
                ny: 3,
            },
            samples: 400,
            source: "dem.tif".into(),
        }
    }

    /// The `[interpolation]` part of the key, as the derived `Debug` of the plan wrote it
    /// before the single commands' settings joined the plan (captured from that build), so
    /// that every DSM kept before stays reused.
    #[test]
    fn the_interpolation_key_is_what_it_was() {
        use crate::project::{Project, TEMPLATE};
        let cases: [(&[&str], &str); 3] = [
            (&[], "InterpolationSection { methods: [Universal, Idw], drift: Linear, variogram: \"auto\", model: None, neighbors: 0, idw_power: 2.0, idw_neighbors: 16, cv_folds: 0, realisations: 0, seed: 0, fit: WlsLoo, fit_model: \"auto\", anisotropy: \"none\", external_drift_grid: None }"),
            (
                &[
                    "interpolation.methods=[\"ok\", \"idw\"]",
                    "interpolation.drift=\"quadratic\"",
                    "interpolation.neighbors=32",
                    "interpolation.cv_folds=5",
                    "interpolation.model={ model = \"spherical+exponential\", psill = [8.0, 4.0], range = [300.0, 900.0], nugget = 1.0, shape = 1.5, anisotropy_angle = 30.0, anisotropy_ratio = 0.5 }",
                    "interpolation.idw_power=3.0",
                    "interpolation.idw_neighbors=8",
                    "interpolation.realisations=4",
                    "interpolation.seed=9",
                    "interpolation.fit=\"reml\"",
                    "interpolation.fit_model=\"spherical\"",
                    "interpolation.anisotropy=\"auto\"",
                    "interpolation.external_drift_grid=\"coarse.tif\"",
                ],
                "InterpolationSection { methods: [Ordinary, Idw], drift: Quadratic, variogram: \"auto\", model: Some(VariogramSpec { model: \"spherical+exponential\", psill: Many([8.0, 4.0]), range: Many([300.0, 900.0]), nugget: 1.0, shape: Some(One(1.5)), anisotropy_angle: Some(30.0), anisotropy_ratio: Some(0.5) }), neighbors: 32, idw_power: 3.0, idw_neighbors: 8, cv_folds: 5, realisations: 4, seed: 9, fit: Reml, fit_model: \"spherical\", anisotropy: \"auto\", external_drift_grid: Some(\"coarse.tif\") }",
            ),
            (
                &[
                    "interpolation.variogram=\"v.json\"",
                    "interpolation.model={ model = \"gaussian\", psill = 2.0, range = 50.0 }",
                ],
                "InterpolationSection { methods: [Universal, Idw], drift: Linear, variogram: \"v.json\", model: Some(VariogramSpec { model: \"gaussian\", psill: One(2.0), range: One(50.0), nugget: 0.0, shape: None, anisotropy_angle: None, anisotropy_ratio: None }), neighbors: 0, idw_power: 2.0, idw_neighbors: 16, cv_folds: 0, realisations: 0, seed: 0, fit: WlsLoo, fit_model: \"auto\", anisotropy: \"none\", external_drift_grid: None }",
            ),
        ];
        for (sets, want) in cases {
            let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
            let p = Project::parse("t.toml", TEMPLATE, &sets).unwrap();
            assert_eq!(interpolation_key(&p.interpolation), want);
            // The single commands' own settings (no project key sets them) leave it alone.
            let mut q = p.interpolation.clone();
            (q.mean, q.radius, q.modes) = (Some(1.0), Some(5.0), 7);
            (q.lag.lags, q.parts.nugget) = (3, Some(1.0));
            q.external_drift = Some("dem".into());
            q.duplicates = terramesh_geostat::Duplicates::Mean;
            assert_eq!(interpolation_key(&q), want);
        }
    }

    /// A project cannot set the single commands' own settings, and they take their defaults.
    #[test]
    fn a_project_leaves_the_single_commands_settings_at_their_defaults() {
        use crate::project::{Project, TEMPLATE};
        let p = Project::parse("t.toml", TEMPLATE, &[]).unwrap();
        assert_eq!(p.interpolation.modes, terramesh_geostat::DEFAULT_MODES);
        assert_eq!(p.interpolation.lag, crate::plan::LagPlan::default());
        assert_eq!(p.interpolation.variogram_or_auto(), "auto");
        for key in ["mean=1.0", "radius=5.0", "modes=3", "duplicates=\"mean\""] {
            let set = vec![format!("interpolation.{key}")];
            assert!(Project::parse("t.toml", TEMPLATE, &set).is_err(), "{key}");
        }
    }

    #[test]
    fn reads_back_what_it_wrote_and_nothing_damaged() {
        let s = state();
        let b = s.to_bytes();
        assert_eq!(DsmState::from_bytes(&b), Some(s.clone()));
        // every truncation, and a changed byte anywhere, is refused (not read as another DSM)
        for n in 0..b.len() {
            assert_eq!(DsmState::from_bytes(&b[..n]), None, "cut at {n}");
        }
        for i in (0..b.len()).step_by(7) {
            let mut c = b.clone();
            c[i] ^= 0x10;
            assert_eq!(DsmState::from_bytes(&c), None, "byte {i}");
        }
        let dir = tempfile::tempdir().unwrap();
        s.write(dir.path()).unwrap();
        assert_eq!(DsmState::read(dir.path(), 42), Some(s));
        assert_eq!(DsmState::read(dir.path(), 43), None);
    }

    #[test]
    fn the_key_follows_the_dsm_settings_and_the_input_bytes_not_the_geology() {
        let dir = tempfile::tempdir().unwrap();
        let text = crate::project::TEMPLATE;
        let parse = |sets: &[&str]| {
            let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
            crate::project::Project::parse("t.toml", text, &sets).unwrap()
        };
        let k0 = key(&parse(&[]), dir.path()).unwrap();
        assert_eq!(k0, key(&parse(&[]), dir.path()).unwrap());
        assert_ne!(k0, key(&parse(&["mesh.min_angle=20"]), dir.path()).unwrap());
        assert_ne!(
            k0,
            key(&parse(&["export.grid_spacing=5"]), dir.path()).unwrap()
        );
        // export formats and pictures do not change the DSM
        assert_eq!(
            k0,
            key(&parse(&["export.pictures=false"]), dir.path()).unwrap()
        );
        // the bytes of a local source
        let dem = dir.path().join("dem.asc");
        std::fs::write(&dem, "a").unwrap();
        let p = parse(&["source.path=dem.asc"]);
        let k1 = key(&p, dir.path()).unwrap();
        std::fs::write(&dem, "b").unwrap();
        assert_ne!(k1, key(&p, dir.path()).unwrap());
    }
}
