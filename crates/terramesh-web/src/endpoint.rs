//! The elevation services: how to ask them and how to read their answers.

use std::fmt;

use crate::WebError;

/// Which service protocol an endpoint speaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ServiceKind {
    /// Google Maps Elevation API: `GET ?locations=lat,lng|...&key=KEY`, 512 locations.
    Google,
    /// OpenTopoData: `GET /v1/DATASET?locations=lat,lng|...`, 100 locations.
    OpenTopoData,
    /// Open-Elevation: `POST /api/v1/lookup` with a JSON list of locations.
    OpenElevation,
}

/// An elevation service endpoint: its protocol, base URL and (for Google) API key.
#[derive(Clone)]
pub struct Endpoint {
    /// The protocol.
    pub kind: ServiceKind,
    /// The URL requests go to (without query).
    pub base_url: String,
    key: Option<String>,
}

impl fmt::Debug for Endpoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Never print the key.
        f.debug_struct("Endpoint")
            .field("kind", &self.kind)
            .field("base_url", &self.base_url)
            .field("key", &self.key.as_ref().map(|_| "<set>"))
            .finish()
    }
}

const GOOGLE_URL: &str = "https://maps.googleapis.com/maps/api/elevation/json";
const OPENTOPO_URL: &str = "https://api.opentopodata.org/v1/";
const OPEN_ELEVATION_URL: &str = "https://api.open-elevation.com/api/v1/lookup";

impl Endpoint {
    /// Parses `google:`, `opentopodata:DATASET`, `open-elevation:`, each optionally followed
    /// by a base URL (`opentopodata:http://127.0.0.1:5000/v1/srtm90m`). `google_key` is the
    /// Google API key (the CLI reads it from `TERRAMESH_GOOGLE_KEY`).
    ///
    /// ```
    /// use terramesh_web::{Endpoint, ServiceKind};
    /// let e = Endpoint::parse("opentopodata:srtm90m", None)?;
    /// assert_eq!(e.base_url, "https://api.opentopodata.org/v1/srtm90m");
    /// let e = Endpoint::parse("opentopodata:http://127.0.0.1:5000/v1/eudem25m", None)?;
    /// assert_eq!(e.kind, ServiceKind::OpenTopoData);
    /// assert!(Endpoint::parse("google:", None).is_err()); // no key
    /// assert!(Endpoint::parse("/data/dem.tif", None).unwrap_err().to_string().contains("not a service"));
    /// # Ok::<(), terramesh_web::WebError>(())
    /// ```
    pub fn parse(spec: &str, google_key: Option<String>) -> Result<Endpoint, WebError> {
        let bad = |m: String| WebError::Config(m);
        let (scheme, rest) = spec.split_once(':').ok_or_else(|| {
            bad(format!(
                "'{spec}' is not a service (google:, opentopodata:DATASET, open-elevation:)"
            ))
        })?;
        let url = |rest: &str, default: &str| -> Result<String, WebError> {
            if rest.is_empty() {
                Ok(default.to_string())
            } else if rest.starts_with("http://") || rest.starts_with("https://") {
                Ok(rest.trim_end_matches('/').to_string())
            } else {
                Err(bad(format!(
                    "'{rest}' in '{spec}' is not an http:// or https:// URL"
                )))
            }
        };
        let (kind, base_url, key) = match scheme.to_ascii_lowercase().as_str() {
            "google" => {
                let key = google_key.filter(|k| !k.is_empty()).ok_or_else(|| {
                    bad("the Google Elevation API needs a key: set TERRAMESH_GOOGLE_KEY".into())
                })?;
                (ServiceKind::Google, url(rest, GOOGLE_URL)?, Some(key))
            }
            "opentopodata" => {
                let base = if rest.starts_with("http://") || rest.starts_with("https://") {
                    url(rest, "")?
                } else if !rest.is_empty()
                    && rest
                        .chars()
                        .all(|c| c.is_ascii_alphanumeric() || "-_,".contains(c))
                {
                    format!("{OPENTOPO_URL}{rest}")
                } else {
                    return Err(bad(
                        "opentopodata: needs a dataset, e.g. opentopodata:srtm30m, or a URL \
                         opentopodata:http://HOST:PORT/v1/DATASET"
                            .into(),
                    ));
                };
                (ServiceKind::OpenTopoData, base, None)
            }
            "open-elevation" => (
                ServiceKind::OpenElevation,
                url(rest, OPEN_ELEVATION_URL)?,
                None,
            ),
            _ => {
                return Err(bad(format!(
                    "'{spec}' is not a service (google:, opentopodata:DATASET, open-elevation:)"
                )))
            }
        };
        Ok(Endpoint {
            kind,
            base_url,
            key,
        })
    }

    /// Locations per request (the service's limit).
    ///
    /// ```
    /// let e = terramesh_web::Endpoint::parse("google:", Some("k".into()))?;
    /// assert_eq!(e.max_batch(), 512);
    /// assert_eq!(e.cache_id(), "google https://maps.googleapis.com/maps/api/elevation/json");
    /// # Ok::<(), terramesh_web::WebError>(())
    /// ```
    pub fn max_batch(&self) -> usize {
        match self.kind {
            ServiceKind::Google => 512,
            ServiceKind::OpenTopoData => 100,
            ServiceKind::OpenElevation => 200,
        }
    }

    /// A name for the cache: protocol and base URL (never the key).
    pub fn cache_id(&self) -> String {
        let kind = match self.kind {
            ServiceKind::Google => "google",
            ServiceKind::OpenTopoData => "opentopodata",
            ServiceKind::OpenElevation => "open-elevation",
        };
        format!("{kind} {}", self.base_url)
    }

    /// Removes the key from a message.
    pub(crate) fn redact(&self, s: &str) -> String {
        match &self.key {
            Some(k) => s.replace(k.as_str(), "<key>"),
            None => s.to_string(),
        }
    }

    /// Sends one batch of `[lat, lon]` points; returns the HTTP outcome.
    pub(crate) fn send(
        &self,
        agent: &ureq::Agent,
        points: &[[f64; 2]],
    ) -> Result<ureq::Response, Box<ureq::Error>> {
        match self.kind {
            ServiceKind::Google | ServiceKind::OpenTopoData => {
                let mut locs = String::with_capacity(points.len() * 26);
                for (i, p) in points.iter().enumerate() {
                    if i > 0 {
                        locs.push('|');
                    }
                    locs.push_str(&format!("{:.7},{:.7}", p[0], p[1]));
                }
                let mut req = agent.get(&self.base_url).query("locations", &locs);
                if let Some(k) = &self.key {
                    req = req.query("key", k);
                }
                req.call().map_err(Box::new)
            }
            ServiceKind::OpenElevation => {
                let locs: Vec<String> = points
                    .iter()
                    .map(|p| format!("{{\"latitude\":{:.7},\"longitude\":{:.7}}}", p[0], p[1]))
                    .collect();
                agent
                    .post(&self.base_url)
                    .set("Content-Type", "application/json")
                    .send_string(&format!("{{\"locations\":[{}]}}", locs.join(",")))
                    .map_err(Box::new)
            }
        }
    }

    /// Reads the elevations of a response for `points`, in order. `Err(Retry)` for answers
    /// worth asking again (malformed, short, wrong locations, over quota), `Err(Fatal)` for
    /// refusals (bad key, invalid request). Public for the fuzzing harnesses.
    ///
    /// ```
    /// use terramesh_web::{Endpoint, Reply};
    /// let e = Endpoint::parse("open-elevation:", None)?;
    /// let body = r#"{"results":[{"latitude":48.7,"longitude":7.3,"elevation":412.5}]}"#;
    /// assert_eq!(e.parse_reply(body, &[[48.7, 7.3]]).ok(), Some(vec![Some(412.5)]));
    /// assert!(matches!(e.parse_reply("{", &[[48.7, 7.3]]), Err(Reply::Retry(_))));
    /// # Ok::<(), terramesh_web::WebError>(())
    /// ```
    pub fn parse_reply(&self, body: &str, points: &[[f64; 2]]) -> Result<Vec<Option<f64>>, Reply> {
        let v: serde_json::Value = serde_json::from_str(body)
            .map_err(|e| Reply::Retry(format!("malformed JSON ({e})")))?;
        if let Some(status) = v.get("status").and_then(|s| s.as_str()) {
            match status {
                "OK" => {}
                "OVER_QUERY_LIMIT" | "UNKNOWN_ERROR" | "OVER_DAILY_LIMIT" => {
                    return Err(Reply::Retry(format!("service status {status}")))
                }
                other => {
                    let msg = v
                        .get("error_message")
                        .or_else(|| v.get("error"))
                        .and_then(|m| m.as_str())
                        .unwrap_or("");
                    return Err(Reply::Fatal(
                        self.redact(&format!("service status {other}: {msg}")),
                    ));
                }
            }
        }
        let results = v
            .get("results")
            .and_then(|r| r.as_array())
            .ok_or_else(|| Reply::Retry("no 'results' list in the reply".into()))?;
        if results.len() != points.len() {
            return Err(Reply::Retry(format!(
                "{} results for {} locations",
                results.len(),
                points.len()
            )));
        }
        let mut out = Vec::with_capacity(points.len());
        for (r, p) in results.iter().zip(points) {
            let (lat, lon) = match self.kind {
                ServiceKind::OpenElevation => (r.get("latitude"), r.get("longitude")),
                _ => {
                    let l = r.get("location");
                    (l.and_then(|l| l.get("lat")), l.and_then(|l| l.get("lng")))
                }
            };
            // A reply that names its locations must name ours, in our order.
            if let (Some(lat), Some(lon)) =
                (lat.and_then(|x| x.as_f64()), lon.and_then(|x| x.as_f64()))
            {
                if (lat - p[0]).abs() > 1e-5 || (lon - p[1]).abs() > 1e-5 {
                    return Err(Reply::Retry(format!(
                        "a result for ({lat}, {lon}) where ({:.7}, {:.7}) was asked",
                        p[0], p[1]
                    )));
                }
            }
            match r.get("elevation") {
                Some(serde_json::Value::Null) => out.push(None),
                Some(e) => match e.as_f64() {
                    Some(z) if z.is_finite() => out.push(Some(z)),
                    _ => return Err(Reply::Retry(format!("elevation {e} is not a number"))),
                },
                None => return Err(Reply::Retry("a result without 'elevation'".into())),
            }
        }
        Ok(out)
    }
}

/// How a reply is judged.
#[derive(Debug)]
pub enum Reply {
    /// Worth retrying.
    Retry(String),
    /// The service refuses the request; retrying will not help.
    Fatal(String),
}
