//! The variogram file (`variogram.json`): the model and what it was computed from.
//!
//! Two commands write it: `terramesh variogram` (every section, candidates with their fits)
//! and `terramesh build` (no `lags` or `fit`, candidates as a summary). One type,
//! [`VariogramFile`], writes both and reads either. Text only: reading and writing the file
//! is the caller's.
//!
//! The JSON is written as it always has been: through a `serde_json::Value`, so the keys of
//! every object are in alphabetical order, and sections that are `None` are left out.

use serde::{Deserialize, Serialize};

use crate::aniso::DirectionalLags;
use crate::auto::Selection;
use crate::cv::Candidate;
use crate::error::GeostatError;
use crate::experimental::{Estimator, Lag};
use crate::fit::Weighting;
use crate::model::{ModelKind, Variogram};

/// The contents of a variogram file.
///
/// Only [`VariogramFile::model`] is needed to krige; the other sections say what the model
/// was computed from. Reading requires only a valid `model`: any other section that is
/// missing or does not parse reads as empty (`""`, `0`, `None`, `[]`), so that a hand-written
/// `{"model": {...}}` is a variogram file.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use terramesh_geostat::{ModelKind, Variogram, VariogramFile};
/// let mut f = VariogramFile::new(Variogram::single(ModelKind::Spherical, 0.5, 2.0, 100.0)?);
/// f.data = "samples.csv".into();
/// let text = f.to_json_pretty();
/// assert!(text.starts_with("{\n  \"candidates\": [],\n  \"data\": \"samples.csv\""));
/// assert_eq!(VariogramFile::from_json(&text)?, f);
/// let only = VariogramFile::from_json(r#"{"model": {"nugget": 1.0, "structures": []}}"#)?;
/// assert_eq!(only.model.nugget, 1.0);
/// assert!(VariogramFile::from_json(r#"{"experimental": []}"#).is_err());
/// # Ok(()) }
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VariogramFile {
    /// The data file the variogram was computed from.
    pub data: String,
    /// Number of data points used.
    pub points: usize,
    /// The lag classes asked for (written by `terramesh variogram`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lags: Option<LagSummary>,
    /// The experimental variogram.
    pub experimental: Vec<Lag>,
    /// The variogram model.
    pub model: Variogram,
    /// How the model was fitted (written by `terramesh variogram`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitSummary>,
    /// The models tried by an automatic fit; empty when the model was given.
    pub candidates: Vec<CandidateEntry>,
    /// What chose the model among the candidates (written by an automatic REML fit only:
    /// files without it are as they always were).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub selection: Option<Selection>,
    /// The directional variograms a fitted anisotropy came from (`--anisotropy auto`); left
    /// out otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub directions: Vec<DirectionalLags>,
}

/// The `lags` section: the lag classes asked for.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LagSummary {
    /// Number of lag classes.
    pub classes: usize,
    /// Upper bound of the last non-empty class (`None` without one).
    pub max_dist: Option<f64>,
    /// Azimuth of a directional variogram, degrees clockwise from north.
    pub azimuth: Option<f64>,
    /// Its angular tolerance, degrees (`None` when omnidirectional).
    pub tolerance: Option<f64>,
    /// The estimator.
    pub estimator: Estimator,
}

/// The `fit` section: weights and quality of the fit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitSummary {
    /// Least-squares weights.
    pub weights: Weighting,
    /// The weighted criterion minimised.
    pub objective: f64,
    /// RMSE of the model over the lag classes.
    pub rmse: f64,
}

/// One entry of `candidates`, in either of the two shapes written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum CandidateEntry {
    /// As `terramesh build` writes it: model, cross-validation RMSE and fit RMSE.
    Summary(CandidateSummary),
    /// As `terramesh variogram` writes it: a whole [`Candidate`] (fit, error).
    Full(Candidate),
}

/// A candidate in short: `{model, cv_rmse, fit_rmse}`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CandidateSummary {
    /// The model.
    pub model: ModelKind,
    /// Leave-one-out RMSE of ordinary kriging with it.
    pub cv_rmse: Option<f64>,
    /// RMSE of its fit to the experimental variogram.
    pub fit_rmse: Option<f64>,
    /// Restricted log-likelihood of its REML fit (left out for a WLS fit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_likelihood: Option<f64>,
    /// Its AIC, the REML selection criterion (left out for a WLS fit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aic: Option<f64>,
    /// The second structure of a nested candidate (left out otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub with: Option<ModelKind>,
}

impl CandidateSummary {
    /// The candidate's name: `spherical`, or `matern+exponential` for a nested one.
    pub fn name(&self) -> String {
        candidate_name(self.model, self.with)
    }
}

/// `model`, or `model+with` for a nested candidate.
pub(crate) fn candidate_name(model: ModelKind, with: Option<ModelKind>) -> String {
    use crate::Named;
    match with {
        Some(w) => format!("{}+{}", model.name(), w.name()),
        None => model.name().to_string(),
    }
}

impl From<&Candidate> for CandidateSummary {
    fn from(c: &Candidate) -> Self {
        CandidateSummary {
            model: c.model,
            cv_rmse: c.cv_rmse,
            fit_rmse: c.fit.as_ref().map(|f| f.rmse),
            log_likelihood: c.log_likelihood,
            aic: c.aic,
            with: c.with,
        }
    }
}

/// A JSON syntax error as "line L, column C: what" (serde_json puts the position last).
fn json_error(e: &serde_json::Error) -> String {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let what = if e.is_eof() {
        "the text ends before the JSON does (a truncated file?)"
    } else {
        full.strip_suffix(&suffix).unwrap_or(&full)
    };
    format!("line {}, column {}: {what}", e.line(), e.column())
}

/// Why a text is not a variogram file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum VariogramFileError {
    /// The text is not JSON.
    #[error("not JSON: {0}")]
    NotJson(String),
    /// There is no `model` key (or the JSON is not an object).
    #[error("no \"model\" key")]
    NoModel,
    /// `model` does not have the shape of a variogram.
    #[error("\"model\" is not a variogram: {0}")]
    BadModel(String),
    /// `model` is a variogram with an invalid parameter.
    #[error("model: {0}")]
    InvalidModel(GeostatError),
}

impl VariogramFile {
    /// A file with only a model (every other section empty).
    pub fn new(model: Variogram) -> VariogramFile {
        VariogramFile {
            data: String::new(),
            points: 0,
            lags: None,
            experimental: Vec::new(),
            model,
            fit: None,
            candidates: Vec::new(),
            selection: None,
            directions: Vec::new(),
        }
    }

    /// The JSON text, pretty-printed, without a final newline.
    pub fn to_json_pretty(&self) -> String {
        // Through a Value: its objects sort their keys, which is how the files are written.
        let value = serde_json::to_value(self).expect("a variogram file is always JSON");
        serde_json::to_string_pretty(&value).expect("a JSON value always prints")
    }

    /// Reads a variogram file; the model is validated ([`Variogram::validate`]).
    pub fn from_json(text: &str) -> Result<VariogramFile, VariogramFileError> {
        let json: serde_json::Value =
            serde_json::from_str(text).map_err(|e| VariogramFileError::NotJson(json_error(&e)))?;
        let serde_json::Value::Object(mut map) = json else {
            return Err(VariogramFileError::NoModel);
        };
        let model = map.remove("model").ok_or(VariogramFileError::NoModel)?;
        let model: Variogram = serde_json::from_value(model)
            .map_err(|e| VariogramFileError::BadModel(e.to_string()))?;
        model.validate().map_err(VariogramFileError::InvalidModel)?;
        Ok(VariogramFile {
            data: section(&mut map, "data"),
            points: section(&mut map, "points"),
            lags: section(&mut map, "lags"),
            experimental: section(&mut map, "experimental"),
            model,
            fit: section(&mut map, "fit"),
            candidates: section(&mut map, "candidates"),
            selection: section(&mut map, "selection"),
            directions: section(&mut map, "directions"),
        })
    }
}

/// An informative section: its value if present and well-formed, else empty.
fn section<T: serde::de::DeserializeOwned + Default>(
    map: &mut serde_json::Map<String, serde_json::Value>,
    key: &str,
) -> T {
    map.remove(key)
        .and_then(|v| serde_json::from_value(v).ok())
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::Fit;
    use crate::model::Structure;

    fn lags() -> Vec<Lag> {
        (1..=3)
            .map(|k| Lag {
                lo: k as f64 - 1.0,
                hi: k as f64,
                distance: k as f64 - 0.5,
                gamma: 0.25 * k as f64,
                pairs: 10 * k,
            })
            .collect()
    }

    fn model() -> Variogram {
        let mut v = Variogram::single(ModelKind::Matern, 0.25, 3.5, 1200.0).unwrap();
        v.structures[0] = Structure {
            shape: 2.5,
            ..v.structures[0]
        };
        v
    }

    fn candidates() -> Vec<Candidate> {
        vec![
            Candidate {
                model: ModelKind::Matern,
                fit: Some(Fit {
                    variogram: model(),
                    objective: 0.125,
                    rmse: 0.0625,
                }),
                cv_rmse: Some(1.5),
                error: None,
                log_likelihood: None,
                aic: None,
                with: None,
            },
            Candidate {
                model: ModelKind::Linear,
                fit: None,
                cv_rmse: None,
                error: Some("no fit".into()),
                log_likelihood: None,
                aic: None,
                with: None,
            },
        ]
    }

    /// `terramesh variogram`'s file, built as the command built it before this type.
    #[test]
    fn the_variogram_command_shape_is_written_byte_for_byte_and_read_back() {
        let (lags, cands) = (lags(), candidates());
        let old = serde_json::json!({
            "data": "pts.csv",
            "points": 42usize,
            "lags": {
                "classes": 15usize,
                "max_dist": lags.last().map(|l| l.hi),
                "azimuth": Some(45.0),
                "tolerance": Some(22.5),
                "estimator": "cressie",
            },
            "experimental": lags,
            "model": model(),
            "fit": {
                "weights": Weighting::Pairs,
                "objective": 0.125,
                "rmse": 0.0625,
            },
            "candidates": cands,
        });
        let f = VariogramFile {
            data: "pts.csv".into(),
            points: 42,
            lags: Some(LagSummary {
                classes: 15,
                max_dist: lags.last().map(|l| l.hi),
                azimuth: Some(45.0),
                tolerance: Some(22.5),
                estimator: Estimator::CressieHawkins,
            }),
            experimental: lags.clone(),
            model: model(),
            fit: Some(FitSummary {
                weights: Weighting::Pairs,
                objective: 0.125,
                rmse: 0.0625,
            }),
            candidates: cands.into_iter().map(CandidateEntry::Full).collect(),
            selection: None,
            directions: Vec::new(),
        };
        let text = f.to_json_pretty();
        assert_eq!(text, serde_json::to_string_pretty(&old).unwrap());
        assert_eq!(VariogramFile::from_json(&text).unwrap(), f);
        // An omnidirectional variogram writes nulls, as before.
        let mut g = f.clone();
        g.lags = Some(LagSummary {
            azimuth: None,
            tolerance: None,
            ..g.lags.unwrap()
        });
        let text = g.to_json_pretty();
        assert!(text.contains("\"azimuth\": null"), "{text}");
        assert_eq!(VariogramFile::from_json(&text).unwrap(), g);
    }

    /// `terramesh build`'s file, built as the command built it before this type.
    #[test]
    fn the_build_shape_is_written_byte_for_byte_and_read_back() {
        let lags = lags();
        let rows: Vec<(String, Option<f64>, Option<f64>)> = vec![
            ("matern".into(), Some(1.5), Some(0.0625)),
            ("linear".into(), None, None),
        ];
        let old = serde_json::json!({
            "data": "samples.csv",
            "points": 7usize,
            "experimental": lags,
            "model": model(),
            "candidates": rows.iter().map(|(m, cv, fit)| serde_json::json!({"model": m, "cv_rmse": cv, "fit_rmse": fit})).collect::<Vec<_>>(),
        });
        let f = VariogramFile {
            data: "samples.csv".into(),
            points: 7,
            experimental: lags.clone(),
            candidates: candidates()
                .iter()
                .map(|c| CandidateEntry::Summary(c.into()))
                .collect(),
            ..VariogramFile::new(model())
        };
        let text = f.to_json_pretty();
        assert_eq!(text, serde_json::to_string_pretty(&old).unwrap());
        assert_eq!(VariogramFile::from_json(&text).unwrap(), f);
    }

    #[test]
    fn a_model_alone_reads_and_a_missing_or_bad_model_is_a_typed_error() {
        let only = format!(
            "{{\"model\": {}, \"points\": \"not a number\"}}",
            serde_json::to_string(&model()).unwrap()
        );
        let f = VariogramFile::from_json(&only).unwrap();
        assert_eq!(f, VariogramFile::new(model()));
        let e = |t: &str| VariogramFile::from_json(t).unwrap_err();
        assert!(matches!(e("{\"model\": 1"), VariogramFileError::NotJson(_)));
        assert_eq!(e("{\"experimental\": []}"), VariogramFileError::NoModel);
        assert_eq!(e("[1, 2]"), VariogramFileError::NoModel);
        assert!(matches!(
            e("{\"model\": {\"nugget\": \"x\"}}"),
            VariogramFileError::BadModel(_)
        ));
        let zero = r#"{"model": {"nugget": 0.0, "structures": []}}"#;
        assert_eq!(
            e(zero),
            VariogramFileError::InvalidModel(GeostatError::ZeroSill)
        );
        assert_eq!(e("{}").to_string(), "no \"model\" key");
    }
}
