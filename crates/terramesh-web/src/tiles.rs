//! Terrain tiles from a URL template `.../{z}/{x}/{y}.png`, cached on disk.

use std::io::Read;
use std::path::PathBuf;
use std::time::Duration;

use crate::WebError;

/// Settings for fetching tiles.
#[derive(Debug, Clone)]
pub struct TileOptions {
    /// Cache directory (tiles are kept under a folder named after the template's hash).
    pub cache_dir: Option<PathBuf>,
    /// Timeout of one request.
    pub timeout: Duration,
    /// Retries of a failed request (5xx, 429, connection errors).
    pub retries: u32,
    /// First backoff, doubled at each retry.
    pub backoff: Duration,
}

impl Default for TileOptions {
    fn default() -> Self {
        TileOptions {
            cache_dir: None,
            timeout: Duration::from_secs(30),
            retries: 3,
            backoff: Duration::from_millis(500),
        }
    }
}

/// FNV-1a, to name a template's cache folder.
fn fnv(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Fetches tiles `(x, y)` at zoom `z` from `template` (containing `{z}`, `{x}`, `{y}`),
/// reading and filling the cache. Returns the PNG bytes of each tile, in the order asked.
///
/// ```no_run
/// # fn main() -> Result<(), terramesh_web::WebError> {
/// let t = terramesh_web::fetch_tiles(
///     "https://s3.amazonaws.com/elevation-tiles-prod/terrarium/{z}/{x}/{y}.png",
///     11, &[(385, 803)], &Default::default())?;
/// assert_eq!(t.len(), 1);
/// # Ok(()) }
/// ```
pub fn fetch_tiles(
    template: &str,
    z: u8,
    tiles: &[(u32, u32)],
    opts: &TileOptions,
) -> Result<Vec<Vec<u8>>, WebError> {
    if !(template.contains("{z}") && template.contains("{x}") && template.contains("{y}")) {
        return Err(WebError::Config(format!(
            "tile URL '{template}' must contain {{z}}, {{x}} and {{y}}"
        )));
    }
    let agent = ureq::AgentBuilder::new()
        .timeout_connect(opts.timeout)
        .timeout(opts.timeout)
        .build();
    let dir = opts
        .cache_dir
        .as_ref()
        .map(|d| d.join(format!("tiles-{:016x}", fnv(template))));
    let mut out = Vec::with_capacity(tiles.len());
    for &(x, y) in tiles {
        let name = format!("{z}/{x}/{y}");
        let err = |message: String| WebError::Tile {
            tile: name.clone(),
            message,
        };
        let cached = dir.as_ref().map(|d| d.join(format!("{z}-{x}-{y}.png")));
        if let Some(bytes) = cached.as_ref().and_then(|p| std::fs::read(p).ok()) {
            out.push(bytes);
            continue;
        }
        let url = template
            .replace("{z}", &z.to_string())
            .replace("{x}", &x.to_string())
            .replace("{y}", &y.to_string());
        let mut last = String::new();
        let mut got = None;
        for attempt in 0..=opts.retries {
            if attempt > 0 {
                std::thread::sleep(opts.backoff.saturating_mul(1 << (attempt - 1).min(16)));
            }
            match agent.get(&url).call() {
                Ok(resp) => {
                    let mut bytes = Vec::new();
                    match resp.into_reader().take(64 << 20).read_to_end(&mut bytes) {
                        Ok(_) => {
                            got = Some(bytes);
                            break;
                        }
                        Err(e) => last = format!("reply cut short: {e}"),
                    }
                }
                Err(ureq::Error::Status(code, _)) if code == 429 || code >= 500 => {
                    last = format!("HTTP {code} from {url}")
                }
                Err(ureq::Error::Status(code, _)) => {
                    return Err(err(format!("HTTP {code} from {url}")))
                }
                Err(ureq::Error::Transport(t)) => last = format!("{t}"),
            }
        }
        let bytes = got.ok_or_else(|| {
            err(format!(
                "failed after {} attempts: {last}",
                opts.retries + 1
            ))
        })?;
        if let (Some(d), Some(p)) = (&dir, &cached) {
            let tmp = d.join(format!(".{z}-{x}-{y}.png.tmp"));
            let stored = std::fs::create_dir_all(d)
                .and_then(|_| std::fs::write(&tmp, &bytes))
                .and_then(|_| std::fs::rename(&tmp, p));
            if let Err(source) = stored {
                return Err(WebError::Store {
                    file: p.display().to_string(),
                    source,
                });
            }
        }
        out.push(bytes);
    }
    Ok(out)
}
