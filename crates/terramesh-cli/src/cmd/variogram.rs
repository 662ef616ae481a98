//! `terramesh variogram`: experimental semivariogram of x,y,z data and a fitted model.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use terramesh::fitting::{fit as fit_plan, AnisotropyPlan, FitPlan};
use terramesh_geostat::{
    experimental, AutoSettings, CandidateEntry, Direction, Drift, Duplicates, Estimator, FitMethod,
    FitSummary, LagSettings, LagSummary, VariogramFile, Weighting,
};
use terramesh_io::output::Output;

use terramesh::interpolate::read_data;

use super::geodata::in_file;

/// Lag and fitting flags, shared with `interpolate --variogram auto` and `cv`.
#[derive(clap::Args, Debug, Clone)]
pub struct LagArgs {
    /// Number of lag classes.
    #[arg(long, default_value_t = terramesh_geostat::DEFAULT_LAGS)]
    pub lags: usize,
    /// Largest lag distance (default: half the data diameter).
    #[arg(long, allow_hyphen_values = true)]
    pub max_dist: Option<f64>,
    /// Directional variogram: azimuth in degrees clockwise from north.
    #[arg(long, allow_hyphen_values = true)]
    pub azimuth: Option<f64>,
    /// Angular tolerance of --azimuth, degrees.
    #[arg(long, default_value_t = terramesh_geostat::DEFAULT_TOLERANCE)]
    pub tolerance: f64,
    /// Semivariance estimator.
    #[arg(long, value_parser = crate::named::<Estimator>(), default_value_t = Estimator::Matheron)]
    pub estimator: Estimator,
    /// Least-squares weights of the fit.
    #[arg(long, value_parser = crate::named::<Weighting>(), default_value_t = Weighting::Cressie)]
    pub weights: Weighting,
    /// Compute the experimental variogram on at most this many data, drawn pseudo-randomly
    /// (the same draw every run); 0 uses all (the pair count grows with the square).
    #[arg(long, default_value_t = terramesh_geostat::DEFAULT_MAX_POINTS)]
    pub max_points: usize,
    /// How the model's parameters are fitted: reml (restricted maximum likelihood with the
    /// kriging's drift, from the WLS fit) or wls (weighted least squares on the lag classes).
    /// With auto, both keep the model of least leave-one-out RMSE (REML: of kriging with the
    /// drift; WLS: of ordinary kriging in 32 neighbours). Default: wls.
    #[arg(long, value_parser = crate::named::<FitMethod>())]
    pub fit: Option<FitMethod>,
    /// REML in spatial blocks of at most this many data (a composite likelihood; each
    /// evaluation is a Cholesky of this order per block); 0: exact REML on all data.
    #[arg(long, default_value_t = terramesh_geostat::DEFAULT_REML_BLOCK)]
    pub reml_block: usize,
}

impl LagArgs {
    pub fn settings(&self) -> LagSettings {
        LagSettings {
            lags: self.lags,
            max_dist: self.max_dist,
            direction: self.azimuth.map(|a| Direction {
                azimuth: a,
                tolerance: self.tolerance,
            }),
            estimator: self.estimator,
            max_points: (self.max_points > 0).then_some(self.max_points),
        }
    }
    pub fn weighting(&self) -> Weighting {
        self.weights
    }
    /// The fitting plan of `model` (`auto`, a name or a nested sum) for kriging with `drift`.
    pub fn plan(&self, model: &str, drift: Drift) -> FitPlan {
        FitPlan {
            model: model.to_string(),
            method: self.fit,
            auto: AutoSettings {
                drift,
                weighting: self.weights,
                block: (self.reml_block > 0).then_some(self.reml_block),
                ..AutoSettings::default()
            },
            anisotropy: None,
        }
    }

    /// The anisotropy fit of `--anisotropy auto`: 8 azimuths, these lag classes and
    /// `--tolerance`; a directional `--azimuth` contradicts it.
    pub fn anisotropy_plan(&self) -> Result<AnisotropyPlan> {
        if let Some(a) = self.azimuth {
            anyhow::bail!("--azimuth {a} and --anisotropy auto: the anisotropy fit makes its own directional variograms (8 azimuths within --tolerance); give one of them");
        }
        if !(self.tolerance > 0.0 && self.tolerance <= 90.0) {
            anyhow::bail!("--tolerance {}: must be in (0, 90] degrees", self.tolerance);
        }
        Ok(AnisotropyPlan {
            lags: self.settings(),
            tolerance: self.tolerance,
            ..AnisotropyPlan::default()
        })
    }
}

/// Compute an experimental semivariogram and fit a model to it.
///
/// Writes JSON with the lag classes (mean distance, semivariance, pair count), the fitted
/// model (nugget, psill, range: GSLIB practical range) and the fit error; with --model auto
/// also every candidate with its cross-validation RMSE and, for a REML fit (the default of
/// auto), its restricted log-likelihood and AIC (`log_likelihood`, `aic`; `fit.objective` is
/// then −ℓ) and a `selection` section (method, drift, number of data). The file can be given
/// to `interpolate --variogram FILE`.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  \
    terramesh variogram --data pts.csv -o variogram.json --plot variogram.svg\n  \
    terramesh variogram --data pts.csv --model spherical --lags 20 --max-dist 8000 -o v.json\n  \
    terramesh variogram --data pts.csv --azimuth 45 --tolerance 22.5 --estimator cressie\n  \
    terramesh variogram --data pts.csv --model spherical+exponential --fit reml -o v.json\n  \
    terramesh variogram --data pts.csv --model gaussian --anisotropy auto -o v.json")]
pub struct Args {
    /// Data: CSV with columns x, y, z (projected coordinates, e.g. UTM metres).
    #[arg(long)]
    data: PathBuf,
    /// Model to fit: auto (default), spherical, exponential, gaussian, matern, power, linear,
    /// nugget, or a nested sum of up to three joined by + (spherical+exponential: nugget and
    /// every structure fitted jointly by WLS, then REML with --fit reml).
    #[arg(long, default_value = "auto")]
    model: String,
    /// auto: fit geometric anisotropy too, from directional variograms along 8 azimuths (0,
    /// 22.5, ..., 157.5 degrees clockwise from north, each within --tolerance); the model's
    /// angle is then degrees counter-clockwise from +x, and `directions` in the JSON holds
    /// each azimuth's lags and fitted range.
    #[arg(long)]
    anisotropy: Option<String>,
    #[command(flatten)]
    lag: LagArgs,
    /// The drift that a REML fit filters out: that of the kriging that will use the model
    /// (constant for ok and sk, the --drift of uk).
    #[arg(long, value_parser = crate::named::<Drift>(), default_value_t = Drift::Linear)]
    drift: Drift,
    /// Points at one location.
    #[arg(long, value_parser = crate::named::<Duplicates>(), default_value_t = Duplicates::Reject)]
    duplicates: Duplicates,
    /// Output JSON (default: standard output).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Also draw the experimental points (sized by pair count) and the model as a chart:
    /// SVG or PNG by the file extension.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    if let Some(p) = &args.plot {
        let ext = p
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if !matches!(ext.as_deref(), Some("svg" | "png")) {
            anyhow::bail!(
                "--plot {}: the file name must end in .svg or .png",
                p.display()
            );
        }
    }
    let fd = read_data(&args.data, args.duplicates).map_err(crate::flag_error)?;
    let s = args.lag.settings();
    let lags = experimental(&fd.data, &s).map_err(|e| in_file(&fd.name, e))?;
    let mut plan = args.lag.plan(&args.model, args.drift);
    match args.anisotropy.as_deref() {
        None => {}
        Some(a) if a.eq_ignore_ascii_case("auto") => {
            plan.anisotropy = Some(args.lag.anisotropy_plan()?)
        }
        Some(a) => anyhow::bail!("--anisotropy '{a}': expected auto"),
    }
    let fitted = fit_plan(&fd.data, &lags, &plan)
        .map_err(|e| crate::flag_error(e).context(fd.name.clone()))?;
    let (fit, cands, directions) = (fitted.fit, fitted.candidates, fitted.directions);
    let file = VariogramFile {
        data: fd.name.clone(),
        points: fd.data.len(),
        lags: Some(LagSummary {
            classes: s.lags,
            max_dist: lags.last().map(|l| l.hi),
            azimuth: args.lag.azimuth,
            tolerance: args.lag.azimuth.map(|_| args.lag.tolerance),
            estimator: s.estimator,
        }),
        experimental: lags.clone(),
        model: fit.variogram.clone(),
        fit: Some(FitSummary {
            weights: args.lag.weighting(),
            objective: fit.objective,
            rmse: fit.rmse,
        }),
        candidates: cands.into_iter().map(CandidateEntry::Full).collect(),
        selection: fitted.selection,
        directions,
    };
    let mut out = Output::create(args.output.as_deref())?;
    out.write_all(file.to_json_pretty().as_bytes())?;
    out.write_all(b"\n")?;
    out.commit()?;
    if let Some(p) = &args.plot {
        let title = format!("{}: {} points", fd.name, fd.data.len());
        let pts: Vec<(f64, f64, u64)> = lags
            .iter()
            .map(|l| (l.distance, l.gamma, l.pairs))
            .collect();
        let label = fit.variogram.to_string();
        terramesh_io::pictures::render_file(p, (900, 600), |root| {
            terramesh_io::pictures::draw_variogram(
                root,
                &pts,
                &|h| fit.variogram.gamma(h),
                &title,
                &label,
            )
        })
        .with_context(|| format!("--plot {}", p.display()))?;
    }
    if args.output.is_some() {
        eprintln!("terramesh: variogram model: {}", fit.variogram);
    }
    Ok(())
}
