//! `terramesh build`: the whole pipeline from a project to a DSM, its exports, pictures and a
//! report.
//!
//! Stages: region -> samples -> variogram -> planar mesh -> vertex elevations (UK, IDW,
//! cross-validation) -> exports (surfaces, sealed solid, grids, tables) -> pictures and
//! report. Each stage is a module with one entry point that calls the kernel crates; [`build`]
//! sequences them, times them and reports progress.
//!
//! A build is atomic as a whole ([`staging`]): every setting and input file is checked before
//! anything is written, the files go into a temporary sibling of the output folder, and that
//! folder replaces the output folder only when the build is complete. An error, a signal or
//! a crash leaves the previous build as it was.

mod adaptive;
mod ensemble;
mod exports;
mod model_dsm;
mod pictures;
mod report;
pub mod reuse;
pub mod scale;
pub(crate) mod stages;
pub mod staging;
pub mod terrain;
pub(crate) mod viewer;

use std::borrow::Cow;
use std::path::Path;
use std::time::Instant;

use crate::geology::stage::OpenedGrids;

pub use adaptive::AdaptiveInfo;
pub use exports::Written;
pub use pictures::{short_numbers, Picture};
/// The stages a tile of a tiled build (`terramesh-tiles`) shares with a one-piece build: the
/// samples, the variogram, the DSM grid's layout and the predictors.
pub use stages::{dsm_grid, model, model_of, sample, sample_into, SampleSink, Sampled, Surface};
pub use stages::{Interpolated, Meshed, Model, Samples};
pub use viewer::{VIEWER_MODEL_VERTICES, VIEWER_SAMPLES, VIEWER_VERTICES};

use crate::error::{Context, Error, Result};
use crate::progress::Progress;
use crate::project::Project;

/// Time spent in each stage (`.0`: name and seconds), the process's peak resident memory
/// after it (`.1`, bytes, in the same order; `None` where the system does not say), and when
/// it began and ended, seconds after the build's start (`.2`; `None` for a row that is not a
/// stage), for the log, `build.json` and the report. A stage's seconds are the time it
/// worked: the exports, the pictures and the report run at once, so their spans overlap,
/// and the report's seconds (its 3D view made beside the others, then the page) can be
/// less than its span.
#[derive(Debug, Default, Clone)]
pub struct Timings(
    pub Vec<(String, f64)>,
    pub Vec<Option<u64>>,
    pub Vec<Option<[f64; 2]>>,
);

impl Timings {
    /// Records a row that is not a stage (no span): its seconds and the peak memory now.
    pub fn push(&mut self, name: &str, seconds: f64) -> Option<u64> {
        self.push_span(name, seconds, None)
    }

    /// Records a stage: its seconds, when it began and ended (seconds after the build's
    /// start), and the peak memory now.
    pub fn push_span(&mut self, name: &str, seconds: f64, span: Option<[f64; 2]>) -> Option<u64> {
        // Linux's VmHWM is the larger of a high-water mark updated only on some events (an
        // unmap, an exit) and the current resident size, so it can read lower than it did
        // after an earlier stage once memory is given back (seen after the concurrent
        // exports): the peak so far is at least every earlier reading.
        let earlier = self.1.iter().flatten().copied().max();
        let peak = match (peak_memory(), earlier) {
            (Some(now), Some(e)) => Some(now.max(e)),
            (now, _) => now,
        };
        self.0.push((name.to_string(), seconds));
        self.1.push(peak);
        self.2.push(span);
        peak
    }

    /// The peak memory after stage `k`, `None` where unknown.
    pub fn peak(&self, k: usize) -> Option<u64> {
        self.1.get(k).copied().flatten()
    }

    /// When stage `k` began and ended, seconds after the build's start.
    pub fn span(&self, k: usize) -> Option<[f64; 2]> {
        self.2.get(k).copied().flatten()
    }

    /// The wall-clock seconds from the first to the last of the stages `names` that ran
    /// (together, where they overlap), `None` when none did.
    pub fn together(&self, names: &[&str]) -> Option<f64> {
        let spans = (0..self.0.len())
            .filter(|&k| names.contains(&self.0[k].0.as_str()))
            .filter_map(|k| self.span(k));
        let (lo, hi) = spans.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), [a, b]| {
            (lo.min(a), hi.max(b))
        });
        (lo <= hi).then_some(hi - lo)
    }
}

/// The peak resident memory of this process so far, in bytes: `VmHWM` of `/proc/self/status`
/// on Linux, `None` elsewhere (or where it cannot be read).
pub fn peak_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// A peak memory in words: `123.4 MB`, or `unknown`.
pub fn memory_text(bytes: Option<u64>) -> String {
    bytes.map_or("unknown".into(), |b| format!("{:.1} MB", b as f64 / 1e6))
}

/// The file of every build's stages, times and peak memory, and what it computed.
pub const BUILD_JSON: &str = "build.json";

/// `build.json`: every stage's seconds and peak memory after it, the whole build's, and what
/// the interpolation computed and why ([`scale`]).
fn write_build_json(
    out: &Path,
    timings: &Timings,
    total: f64,
    interpolation: Option<&scale::Record>,
) -> Result<std::path::PathBuf> {
    #[derive(serde::Serialize)]
    struct Stage<'a> {
        stage: &'a str,
        seconds: f64,
        #[serde(skip_serializing_if = "Option::is_none")]
        start_seconds: Option<f64>,
        #[serde(skip_serializing_if = "Option::is_none")]
        end_seconds: Option<f64>,
        peak_memory_bytes: Option<u64>,
    }
    #[derive(serde::Serialize)]
    struct File<'a> {
        stages: Vec<Stage<'a>>,
        #[serde(skip_serializing_if = "Option::is_none")]
        outputs_seconds: Option<f64>,
        seconds: f64,
        peak_memory_bytes: Option<u64>,
        peak_memory: &'a str,
        #[serde(skip_serializing_if = "Option::is_none")]
        interpolation: Option<&'a scale::Record>,
    }
    let stages: Vec<Stage> = timings
        .0
        .iter()
        .enumerate()
        .filter(|(_, (n, _))| n != TOTAL_BEFORE_REPORT)
        .map(|(k, (n, t))| Stage {
            stage: n,
            seconds: *t,
            start_seconds: timings.span(k).map(|s| s[0]),
            end_seconds: timings.span(k).map(|s| s[1]),
            peak_memory_bytes: timings.peak(k),
        })
        .collect();
    let peak = peak_memory();
    let how = match peak {
        Some(_) => "VmHWM of /proc/self/status after each stage",
        None => "unknown on this system",
    };
    let json = serde_json::to_string_pretty(&File {
        stages,
        outputs_seconds: timings.together(&OUTPUTS),
        seconds: total,
        peak_memory_bytes: peak,
        peak_memory: how,
        interpolation,
    })
    .map_err(|e| Error::about("build.json", e))?;
    let path = out.join(BUILD_JSON);
    terramesh_io::output::write_atomic(&path, format!("{json}\n").as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(path)
}

/// The report's row of the time up to it.
const TOTAL_BEFORE_REPORT: &str = "total before report";

/// The stages that run at once after the interpolation: `build.json`'s `outputs_seconds` is
/// their wall-clock time together, from the first one's start to the last one's end.
pub const OUTPUTS: [&str; 3] = ["exports", "pictures", "report"];

/// The number of stages [`build`] reports (one more with `[geology]`).
pub const STAGES: usize = 7;

/// What a build made.
#[derive(Debug)]
pub struct Built {
    /// Files written, in order (pictures and the report not included).
    pub files: Vec<std::path::PathBuf>,
    /// Vertices of the DSM.
    pub vertices: usize,
    /// Triangles of the DSM.
    pub triangles: usize,
    /// Seconds and peak memory per stage.
    pub timings: Timings,
    /// What the interpolation computed and why ([`scale`]); `None` for `terramesh model`.
    pub interpolation: Option<scale::Record>,
}

struct Stages<'a> {
    progress: &'a dyn Progress,
    k: usize,
    total: usize,
    timings: Timings,
    /// The build's start, which the stages' spans count from.
    t0: Instant,
}

impl Stages<'_> {
    fn run<T>(
        &mut self,
        name: &str,
        f: impl FnOnce() -> Result<T>,
        detail: impl FnOnce(&T) -> String,
    ) -> Result<T> {
        self.check()?;
        self.start(name);
        let t = Instant::now();
        let out = f()?;
        let span = self.span(t);
        self.done(name, span[1] - span[0], span, &detail(&out));
        self.check()?;
        Ok(out)
    }

    /// The next stage begins: its number and name to the front end.
    fn start(&mut self, name: &str) {
        self.k += 1;
        self.progress.stage_start(self.k, self.total, name);
    }

    /// The stage ended: its `seconds` (the time it worked), its `span` and the peak memory
    /// recorded, and its line (`detail`, then the peak memory) to the front end.
    fn done(&mut self, name: &str, seconds: f64, span: [f64; 2], detail: &str) {
        let peak = self.timings.push_span(name, seconds, Some(span));
        let detail = format!("{detail}; peak memory {}", memory_text(peak));
        self.progress.stage_done(name, &detail, seconds);
    }

    /// The variogram stage: the model fitted when `fit`, else the samples' data alone, with
    /// `why` as the stage's line.
    fn variogram(
        &mut self,
        fit: bool,
        why: &str,
        project: &Project,
        samples: &stages::Samples,
        base: &Path,
    ) -> Result<stages::Fit> {
        if fit {
            let m = self.run(
                "variogram",
                || stages::model(project, samples, base),
                |m| m.detail(),
            )?;
            Ok(stages::Fit::Model(Box::new(m)))
        } else {
            let d = self.run("variogram", || stages::sample_data(samples), |_| why.into())?;
            Ok(stages::Fit::Data(d))
        }
    }

    /// When something that began at `start` began and ended (now), seconds after the
    /// build's start.
    fn span(&self, start: Instant) -> [f64; 2] {
        let at = |i: Instant| i.saturating_duration_since(self.t0).as_secs_f64();
        [at(start), at(Instant::now())]
    }

    /// Runs `f`: what it returns, and when it began and ended ([`Stages::span`]).
    fn timed<T>(&self, f: impl FnOnce() -> T) -> (T, [f64; 2]) {
        let t = Instant::now();
        let r = f();
        (r, self.span(t))
    }

    /// Stops the build when the front end asks.
    fn check(&self) -> Result<()> {
        if self.progress.cancelled() {
            Err(Error::Cancelled)
        } else {
            Ok(())
        }
    }
}

/// Builds the discrete surface model of `project` (whose paths are relative to `base`, the
/// folder of its file) into `out`: samples, mesh, kriging and IDW, exports, pictures and
/// `report.html`.
///
/// The settings and input files are checked first ([`Project::check_inputs`]); the build is
/// written into a temporary sibling of `out` that replaces `out` at the end
/// ([`staging::Staging`]), so an error, or [`Progress::cancelled`], leaves `out` as it was.
/// An existing `out` that is not a build folder (see [`staging::MARKER`]) is refused.
pub fn build(project: &Project, base: &Path, out: &Path, progress: &dyn Progress) -> Result<Built> {
    build_as(project, base, out, progress, What::Everything)
}

/// Builds only the geological model of `project` (`terramesh model`): the DSM is made in
/// memory as [`build`] makes it (the same samples, mesh and elevations), and `out` receives
/// the samples table, the model's files and `model.json`, not the DSM's exports, pictures or
/// report. Atomic like [`build`]. A project without `[geology]` is refused.
pub fn build_model(
    project: &Project,
    base: &Path,
    out: &Path,
    progress: &dyn Progress,
) -> Result<Built> {
    if project.geology().is_none() {
        return Err(Error::NoGeology);
    }
    build_as(project, base, out, progress, What::ModelOnly)
}

/// The DSM the geological model stands on.
struct Dsm<'a> {
    mesh: &'a terramesh_mesh::Mesh,
    z: &'a [f64],
    grid: &'a terramesh_io::grid_write::RasterGrid,
    /// A geographic project (worked in a UTM zone).
    geographic: bool,
}

/// The geology stage on `dsm`, and `model.glb` when the project exports glb.
#[allow(clippy::too_many_arguments)]
fn geology_stage(
    st: &mut Stages,
    project: &Project,
    g: &crate::plan::GeologyPlan,
    boreholes: Option<terramesh_io::boreholes::Boreholes>,
    dsm: Dsm,
    model_crs: Option<&terramesh_crs::Crs>,
    out: &Path,
    grids: OpenedGrids,
) -> Result<crate::geology::stage::ModelBuilt> {
    let mut built = st.run(
        "geology",
        || {
            crate::geology::stage::run(
                project, g, boreholes, dsm.mesh, dsm.z, dsm.grid, model_crs, out, grids,
            )
        },
        |m| {
            format!(
                "{} units, {} cells, {} contacts within {:.3} m",
                m.model.stats.len(),
                m.model.mesh.cells.len(),
                m.model.misfits.len(),
                m.model
                    .misfits
                    .iter()
                    .map(|f| f.misfit.abs())
                    .fold(0.0, f64::max)
            )
        },
    )?;
    if let Some(b) = (built.summary.faulted.as_ref()).and_then(|f| f.refine_budget.as_ref()) {
        st.progress.warn(&b.warning());
    }
    if project
        .export
        .formats
        .iter()
        .any(|f| terramesh_core::vocab::Named::name(*f) == "glb")
    {
        built.files.push(crate::geology::web::write_build_glb(
            out,
            &built.model.mesh,
            &built.summary.crs,
            dsm.geographic,
            project.named_height_datum().as_ref(),
            project.title.as_deref(),
        )?);
    }
    Ok(built)
}

/// `terramesh model` on the DSM kept in `previous` ([`reuse`]) when it was made from the same
/// settings, inputs and borehole points: the geology stage alone, `samples.csv` and the kept
/// DSM carried over into `out`. `None` when there is no such DSM (the caller builds one).
#[allow(clippy::too_many_arguments)]
fn model_on_kept_dsm(
    project: &Project,
    g: &crate::plan::GeologyPlan,
    key: u64,
    out: &Path,
    previous: &Path,
    progress: &dyn Progress,
    grids: &mut GridsAhead,
    t0: Instant,
) -> Result<Option<Built>> {
    let Some(kept) = reuse::DsmState::read(previous, key) else {
        if previous.join(reuse::FILE).is_file() {
            progress.note(&format!(
                "{} was made from other settings or inputs: building the DSM again",
                previous.join(reuse::FILE).display()
            ));
        }
        return Ok(None);
    };
    let crs = project.region.crs.crs();
    let boreholes = crate::geology::stage::read_boreholes(g, kept.zone, crs)?;
    let collars = boreholes
        .as_ref()
        .map(crate::geology::stage::collar_points)
        .unwrap_or_default();
    if collars[..] != kept.collars[..] {
        progress.note("the boreholes moved, or others were added: building the DSM again");
        return Ok(None);
    }
    let model_crs = crate::geology::stage::project_crs(kept.zone, crs)?;
    let mut st = Stages {
        progress,
        k: 0,
        total: 2,
        timings: Timings::default(),
        t0,
    };
    st.run(
        "dsm",
        || {
            kept.write(out)?;
            let samples = previous.join("samples.csv");
            if samples.is_file() {
                std::fs::copy(&samples, out.join("samples.csv"))
                    .with_context(|| format!("cannot copy {}", samples.display()))?;
            }
            Ok(())
        },
        |_| {
            format!(
                "reused {} ({} vertices, {} triangles from {} samples of {}; same settings)",
                previous.join(reuse::FILE).display(),
                kept.mesh.points.len(),
                kept.mesh.triangles.len(),
                kept.samples,
                kept.source
            )
        },
    )?;
    let geo = geology_stage(
        &mut st,
        project,
        g,
        boreholes,
        Dsm {
            mesh: &kept.mesh,
            z: &kept.dsm,
            grid: &kept.grid,
            geographic: kept.zone.is_some(),
        },
        model_crs.as_ref(),
        out,
        grids.take(),
    )?;
    st.check()?;
    Ok(Some(Built {
        files: geo.files,
        vertices: kept.mesh.points.len(),
        triangles: kept.mesh.triangles.len(),
        timings: st.timings,
        interpolation: None,
    }))
}

/// The mesh stage's line of the log.
fn mesh_detail(m: &Meshed) -> String {
    let adaptive = m.adaptive.as_ref().map_or(String::new(), |a| {
        format!(
            ", adaptive: within {:.3} m of kriging (target {} m), min 3D angle {:.1} deg",
            a.verified_error, a.target, a.report.min_angle_3d
        )
    });
    format!(
        "{} vertices, {} triangles, min angle {:.1} deg{adaptive}",
        m.mesh.points.len(),
        m.mesh.triangles.len(),
        m.after.min_angle
    )
}

/// What a build writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum What {
    Everything,
    ModelOnly,
}

fn build_as(
    project: &Project,
    base: &Path,
    out: &Path,
    progress: &dyn Progress,
    what: What,
) -> Result<Built> {
    let t0 = Instant::now();
    project.check_inputs(base)?;
    let staging = staging::Staging::begin(out, progress)?;
    let mut built = build_into(project, base, staging.dir(), out, progress, t0, what)?;
    if progress.cancelled() {
        return Err(Error::Cancelled);
    }
    built.files.push(write_build_json(
        staging.dir(),
        &built.timings,
        t0.elapsed().as_secs_f64(),
        built.interpolation.as_ref(),
    )?);
    let files = built
        .files
        .iter()
        .map(|f| out.join(f.strip_prefix(staging.dir()).unwrap_or(f)))
        .collect();
    staging.commit()?;
    Ok(Built { files, ..built })
}

/// The horizon grids being read on a thread of their own ([`OpenedGrids`]), for `terramesh
/// model`; none for the full build (its DSM keeps both cores busy).
pub(super) struct GridsAhead<'scope>(Option<std::thread::ScopedJoinHandle<'scope, OpenedGrids>>);

impl GridsAhead<'_> {
    /// The grids read (waiting for them), or none when nothing was read ahead.
    pub(super) fn take(&mut self) -> OpenedGrids {
        match self.0.take() {
            Some(h) => h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)),
            None => OpenedGrids::default(),
        }
    }
}

/// Builds into `out` (the staging folder of `previous`, the build folder as it was).
fn build_into(
    project: &Project,
    base: &Path,
    out: &Path,
    previous: &Path,
    progress: &dyn Progress,
    t0: Instant,
    what: What,
) -> Result<Built> {
    match (&what, project.geology()) {
        // `terramesh model`: the horizon grids need nothing of the DSM; they are read while
        // the DSM is made (its mesh is one core's work) or read
        (What::ModelOnly, Some(g)) => std::thread::scope(|s| {
            let mut ahead = GridsAhead(Some(s.spawn(|| OpenedGrids::open(g))));
            build_into_with(project, base, out, previous, progress, t0, what, &mut ahead)
        }),
        _ => {
            let mut none = GridsAhead(None);
            build_into_with(project, base, out, previous, progress, t0, what, &mut none)
        }
    }
}

/// The exports, the pictures and the report, at once: the exports' jobs, the pictures' and
/// the report's 3D view (its level-of-detail copy of the DSM, the costliest part of the
/// report) run together on the thread pool, then the report's page is made from what they
/// made. Each stage's line comes after all three, in the stages' order, with its own time;
/// the report's time is its 3D view's plus its page's, its span from the start of the three
/// to its end. `build.json`'s `outputs_seconds` is their time together. `keep` writes the
/// DSM kept for `terramesh model` beside the exports, in their time.
#[allow(clippy::too_many_arguments)]
fn outputs(
    st: &mut Stages,
    project: &Project,
    out: &Path,
    samples: &stages::Samples,
    mesh: &stages::Meshed,
    interp: &stages::Interpolated,
    geo: Option<&crate::geology::stage::ModelBuilt>,
    keep: impl FnOnce() -> Result<()> + Send,
) -> Result<exports::Written> {
    st.check()?;
    st.start("exports");
    let want_pictures = project.export.pictures || project.export.report;
    let base = exports::base_elevation(project, interp);
    let stages = &*st;
    // The pictures: the DSM's, then the geological model's (with `[geology]`), which the
    // report's sections show.
    let draw = || -> Result<(Vec<Picture>, Vec<terramesh_report::report::Section>)> {
        let pics = pictures::draw_all(out, samples, mesh, interp)?;
        let mut extra = Vec::new();
        if let Some(g) = geo {
            extra.push(crate::geology::report::model_section(out, g, &mesh.mesh)?);
            extra.extend(crate::geology::ensemble_report::ensemble_section(
                out, g, &mesh.mesh,
            )?);
        }
        Ok((pics, extra))
    };
    let ((written, t_exports), ((pics, t_pictures), (scene, t_scene))) = rayon::join(
        || {
            stages.timed(|| {
                let (w, kept) = rayon::join(
                    || exports::write_all(project, out, samples, mesh, interp, base),
                    keep,
                );
                w.and_then(|w| kept.map(|()| w))
            })
        },
        || {
            rayon::join(
                || stages.timed(|| want_pictures.then(draw).transpose()),
                || {
                    stages.timed(|| {
                        project
                            .export
                            .report
                            .then(|| viewer::scene(samples, mesh, interp, base, geo))
                            .transpose()
                    })
                },
            )
        },
    );
    let written = written?;
    let secs = |s: [f64; 2]| s[1] - s[0];
    st.done(
        "exports",
        secs(t_exports),
        t_exports,
        &format!("{} files", written.files.len()),
    );
    let Some((pics, extra)) = pics? else {
        return Ok(written);
    };
    st.start("pictures");
    st.done(
        "pictures",
        secs(t_pictures),
        t_pictures,
        &format!("{} pictures, drawn beside the exports", pics.len()),
    );
    let Some(scene) = scene? else {
        return Ok(written);
    };
    st.start("report");
    let t = Instant::now();
    st.timings
        .push(TOTAL_BEFORE_REPORT, st.t0.elapsed().as_secs_f64());
    report::write_report(
        out,
        project,
        samples,
        mesh,
        interp,
        &written,
        &pics,
        &st.timings,
        extra,
        scene,
    )?;
    // The report worked on its 3D view beside the others, then on its page.
    let page = st.span(t);
    st.done(
        "report",
        secs(t_scene) + secs(page),
        [t_scene[0], page[1]],
        "report.html (its 3D view made beside the exports)",
    );
    if let Some(all) = st.timings.together(&OUTPUTS) {
        st.progress.note(&format!(
            "exports, pictures and report at once: {all:.2} s together"
        ));
    }
    Ok(written)
}

/// [`build_into`], with the grids read ahead.
#[allow(clippy::too_many_arguments)]
fn build_into_with(
    project: &Project,
    base: &Path,
    out: &Path,
    previous: &Path,
    progress: &dyn Progress,
    t0: Instant,
    what: What,
    grids: &mut GridsAhead,
) -> Result<Built> {
    // The key of the DSM's settings and inputs (reuse.rs); an input that cannot be read
    // leaves none, and the DSM is built (and its reading reports the error).
    let dsm_key = reuse::key(project, base).ok();
    if let (What::ModelOnly, Some(key), Some(g), 0) = (
        what,
        dsm_key,
        project.geology(),
        project.interpolation.realisations,
    ) {
        if let Some(built) = model_on_kept_dsm(project, g, key, out, previous, progress, grids, t0)?
        {
            return Ok(built);
        }
    }
    let mut st = Stages {
        progress,
        k: 0,
        total: match what {
            What::Everything => {
                let (geo, sim) = (
                    project.geology().is_some(),
                    project.interpolation.realisations > 0,
                );
                STAGES + usize::from(geo) + usize::from(sim) + usize::from(geo && sim)
            }
            What::ModelOnly => 5 + 2 * usize::from(project.interpolation.realisations > 0),
        },
        timings: Timings::default(),
        t0,
    };
    let samples = st.run(
        "samples",
        || stages::sample(project, base, out, progress),
        |s| format!("{} samples from {}", s.xyz.len(), s.source),
    )?;
    // `terramesh model` makes only what the geological model stands on (model_dsm.rs).
    if what == What::ModelOnly && project.interpolation.realisations == 0 {
        return model_dsm::build_rest(&mut st, project, base, out, &samples, dsm_key, grids);
    }
    // What is computed: kriging only when something reported needs it; the neighbourhood
    // and the cross-validation by the number of samples (scale.rs).
    let fit = st.variogram(
        scale::needs_kriging(project),
        "not fitted: interpolation.methods is idw alone",
        project,
        &samples,
        base,
    )?;
    let (model, data) = (fit.model(), fit.data());
    let choice = scale::choose(project, data.len());
    progress.note(&choice.describe());
    let geology = project.geology();
    let model_crs = crate::geology::stage::project_crs(samples.zone, samples.crs.as_ref())?;
    let (boreholes, collars) =
        crate::geology::stage::boreholes_and_collars(geology, samples.zone, samples.crs.as_ref())?;
    let mesh = st.run(
        "mesh",
        || match model {
            Some(m) => stages::mesh(project, &samples, m, &collars),
            None => stages::mesh_refined(project, &samples, &collars),
        },
        mesh_detail,
    )?;
    let mut interp = st.run(
        "interpolation",
        || stages::interpolate(project, &samples, &mesh, model, data, &choice),
        |i| {
            let hood = match i.choice.neighbours {
                scale::Neighbours::All => "all samples".to_string(),
                scale::Neighbours::Nearest(k) => format!("{k} neighbours"),
            };
            if i.kriged() {
                format!(
                    "UK ({hood}) and IDW at {} vertices, {} cross-validation",
                    i.idw.len(),
                    i.choice.folds_name()
                )
            } else {
                format!(
                    "IDW at {} vertices (nothing kriged), {} cross-validation",
                    i.idw.len(),
                    i.choice.folds_name()
                )
            }
        },
    )?;
    // The DSM kept for `terramesh model` (reuse.rs): written here for a model alone, beside
    // the exports for a whole build.
    let keep = || -> Result<()> {
        match dsm_key {
            Some(key) => reuse::DsmState {
                key,
                zone: samples.zone,
                mesh: Cow::Borrowed(&mesh.mesh),
                collars: Cow::Borrowed(&collars),
                dsm: Cow::Borrowed(&interp.dsm),
                grid: interp.grid.0,
                samples: samples.xyz.len() as u64,
                source: samples.source.clone(),
            }
            .write(out),
            None => Ok(()),
        }
    };
    if what == What::ModelOnly {
        keep()?;
    }
    if let (true, Some(model)) = (project.interpolation.realisations > 0, model) {
        let e = st.run(
            "simulation",
            || ensemble::simulate_vertices(project, model, &mesh, &interp),
            |e| {
                let refit = e.refit.as_ref().map_or(String::new(), |v| {
                    format!(
                        ", with {} (the fit has no sill)",
                        short_numbers(&v.to_string())
                    )
                });
                format!(
                    "{} realisations at {} vertices{refit}",
                    e.len(),
                    e.mean.len()
                )
            },
        )?;
        interp.ensemble = Some(e);
    }
    let geo = match geology {
        Some(g) => Some(geology_stage(
            &mut st,
            project,
            g,
            boreholes,
            Dsm {
                mesh: &mesh.mesh,
                z: &interp.dsm,
                grid: &interp.grid.0,
                geographic: samples.zone.is_some(),
            },
            model_crs.as_ref(),
            out,
            OpenedGrids::default(),
        )?),
        None => None,
    };
    let mut geo = geo;
    if let (Some(g), Some(built), Some(e)) = (geology, geo.as_mut(), interp.ensemble.as_ref()) {
        st.run(
            "geology realisations",
            || crate::geology::ensemble::run(project, g, built, &mesh.mesh, &e.realisations, out),
            |_| format!("{} sealed models", e.len()),
        )?;
    }
    if what == What::ModelOnly {
        st.check()?;
        return Ok(Built {
            files: geo.map(|g| g.files).unwrap_or_default(),
            vertices: mesh.mesh.points.len(),
            triangles: mesh.mesh.triangles.len(),
            timings: st.timings,
            interpolation: Some(interp.choice.record()),
        });
    }
    let written = outputs(
        &mut st,
        project,
        out,
        &samples,
        &mesh,
        &interp,
        geo.as_ref(),
        keep,
    )?;
    st.check()?;
    let mut files = written.files;
    if let Some(g) = geo {
        files.extend(g.files);
    }
    Ok(Built {
        files,
        vertices: mesh.mesh.points.len(),
        triangles: mesh.mesh.triangles.len(),
        timings: st.timings,
        interpolation: Some(interp.choice.record()),
    })
}
