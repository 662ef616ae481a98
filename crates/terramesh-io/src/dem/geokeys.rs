//! The CRS of a GeoTIFF from its GeoKeys: an EPSG code, or a user-defined projected CRS
//! (GeoKey 3072 = 32767) whose projection parameters the keys carry, turned into a PROJ string.

use std::path::Path;

use terramesh_crs::Crs;
use tiff::decoder::Decoder;
use tiff::tags::Tag;

use super::{DemError, SourceCrs};

const GT_MODEL_TYPE: u16 = 1024;
const GEOGRAPHIC_TYPE: u16 = 2048;
const GEOG_ANGULAR_UNITS: u16 = 2054;
const GEOG_SEMI_MAJOR: u16 = 2057;
const GEOG_SEMI_MINOR: u16 = 2058;
const GEOG_INV_FLATTENING: u16 = 2059;
const GEOG_TOWGS84: u16 = 2062;
const PROJECTED_CS_TYPE: u16 = 3072;
const PROJ_COORD_TRANS: u16 = 3075;
const PROJ_LINEAR_UNITS: u16 = 3076;
const USER_DEFINED: u16 = 32767;

/// The GeoKeys of a file: short values and double-valued keys.
#[derive(Debug, Default)]
pub(crate) struct GeoKeys {
    pub(crate) shorts: Vec<(u16, u16)>,
    doubles: Vec<(u16, Vec<f64>)>,
}

impl GeoKeys {
    pub(crate) fn short(&self, id: u16) -> Option<u16> {
        self.shorts.iter().find(|k| k.0 == id).map(|k| k.1)
    }

    fn double(&self, id: u16) -> Option<f64> {
        self.doubles
            .iter()
            .find(|k| k.0 == id)
            .and_then(|k| k.1.first().copied())
    }

    fn doubles(&self, id: u16) -> Option<&[f64]> {
        self.doubles
            .iter()
            .find(|k| k.0 == id)
            .map(|k| k.1.as_slice())
    }
}

/// Reads the GeoKeyDirectory (and the doubles it points to); `None` without one.
pub(crate) fn geokeys<R: std::io::Read + std::io::Seek>(
    dec: &mut Decoder<R>,
) -> Result<Option<GeoKeys>, tiff::TiffError> {
    let Some(v) = dec.find_tag(Tag::GeoKeyDirectoryTag)? else {
        return Ok(None);
    };
    let d = v.into_u16_vec()?;
    let params = match dec.find_tag(Tag::GeoDoubleParamsTag)? {
        Some(v) => v.into_f64_vec()?,
        None => Vec::new(),
    };
    let n = d.get(3).copied().unwrap_or(0) as usize;
    let mut out = GeoKeys::default();
    for k in 0..n {
        let e = &d.get(4 + 4 * k..8 + 4 * k).unwrap_or(&[]);
        if e.len() != 4 {
            continue;
        }
        match e[1] {
            0 => out.shorts.push((e[0], e[3])),
            34736 => {
                let (count, at) = (e[2] as usize, e[3] as usize);
                if let Some(v) = params.get(at..at.saturating_add(count)) {
                    out.doubles.push((e[0], v.to_vec()));
                }
            }
            _ => {}
        }
    }
    Ok(Some(out))
}

/// The CRS the keys declare.
pub(crate) fn crs_of(path: &Path, keys: &GeoKeys) -> Result<SourceCrs, DemError> {
    let unsupported = |what: String| {
        DemError::crs(
            path,
            format!(
                "{what} is not supported: terramesh reads GeoTIFFs whose GeoKeys name an EPSG \
                 code of its CRS table (WGS 84, UTM, national grids) or a user-defined \
                 Transverse Mercator, Lambert conformal conic, Albers, Mercator or Lambert \
                 azimuthal projection; reproject with gdalwarp -t_srs EPSG:4326"
            ),
        )
    };
    let any = |kind: &str, c: u16| {
        if matches!(c, 3857 | 3785) {
            // Pseudo-Mercator: a display projection (spherical formulas on WGS-84 degrees),
            // not a survey CRS; proj4rs's definition has no datum to transform from.
            return Err(unsupported(format!(
                "{kind} CRS EPSG:{c} (Web Mercator, a display projection)"
            )));
        }
        SourceCrs::from_any_epsg(u32::from(c))
            .map_err(|e| unsupported(format!("{kind} CRS EPSG:{c} ({e})")))
    };
    match keys.short(GT_MODEL_TYPE) {
        Some(2) => match keys.short(GEOGRAPHIC_TYPE) {
            Some(4326) => Ok(SourceCrs::Geographic),
            Some(USER_DEFINED) => Err(unsupported("a user-defined geographic CRS".into())),
            Some(c) => any("geographic", c),
            None => Err(unsupported("a geographic CRS without an EPSG code".into())),
        },
        Some(1) => match keys.short(PROJECTED_CS_TYPE) {
            Some(USER_DEFINED) => user_defined(keys)
                .map_err(|m| unsupported(format!("a user-defined projected CRS ({m})"))),
            Some(c) => any("projected", c),
            None => Err(unsupported("a projected CRS without an EPSG code".into())),
        },
        Some(m) => Err(unsupported(format!("model type {m}"))),
        None => Err(unsupported("a GeoTIFF without a model type".into())),
    }
}

/// A PROJ string from the keys of a user-defined projected CRS (GeoTIFF 1.1, section 7.5).
fn user_defined(k: &GeoKeys) -> Result<SourceCrs, String> {
    if k.short(GEOG_ANGULAR_UNITS).is_some_and(|u| u != 9102) {
        return Err("angular units other than degrees".into());
    }
    let datum = match k.short(GEOGRAPHIC_TYPE) {
        Some(USER_DEFINED) | None => {
            let a = k.double(GEOG_SEMI_MAJOR).ok_or("no semi-major axis")?;
            let shape = match (k.double(GEOG_INV_FLATTENING), k.double(GEOG_SEMI_MINOR)) {
                (Some(rf), _) => format!("+rf={rf}"),
                (None, Some(b)) => format!("+b={b}"),
                _ => return Err("no flattening or semi-minor axis".into()),
            };
            let shift = k
                .doubles(GEOG_TOWGS84)
                .map(|t| {
                    let v: Vec<String> = t.iter().map(f64::to_string).collect();
                    format!(" +towgs84={}", v.join(","))
                })
                .unwrap_or_default();
            format!("+a={a} {shape}{shift}")
        }
        Some(code) => {
            let base = Crs::from_epsg(u32::from(code)).map_err(|e| e.to_string())?;
            base.definition()
                .split_whitespace()
                .filter(|t| !t.starts_with("+proj=") && *t != "+no_defs")
                .collect::<Vec<_>>()
                .join(" ")
        }
    };
    let (unit, metres) = match k.short(PROJ_LINEAR_UNITS) {
        Some(9001) | None => ("m", 1.0),
        Some(9002) => ("ft", 0.3048),
        Some(9003) => ("us-ft", 1200.0 / 3937.0),
        Some(u) => return Err(format!("linear unit {u}")),
    };
    // GeoKey ids of the projection parameters; the first present of each list is taken.
    let p = |ids: &[u16]| ids.iter().find_map(|&id| k.double(id));
    let (lat0, lon0) = (
        p(&[3081, 3085, 3089]).unwrap_or(0.0),
        p(&[3080, 3084, 3088]).unwrap_or(0.0),
    );
    let fe = p(&[3082, 3086]).unwrap_or(0.0) * metres;
    let fn_ = p(&[3083, 3087]).unwrap_or(0.0) * metres;
    let k0 = p(&[3092, 3093]).unwrap_or(1.0);
    let sp = |id| p(&[id]).ok_or(format!("no standard parallel (GeoKey {id})"));
    let proj = match k.short(PROJ_COORD_TRANS) {
        Some(1) => format!("+proj=tmerc +lat_0={lat0} +lon_0={lon0} +k={k0}"),
        Some(7) => format!("+proj=merc +lon_0={lon0} +k={k0}"),
        Some(8) => format!(
            "+proj=lcc +lat_1={} +lat_2={} +lat_0={lat0} +lon_0={lon0}",
            sp(3078)?,
            sp(3079)?
        ),
        Some(9) => format!("+proj=lcc +lat_1={lat0} +lat_0={lat0} +lon_0={lon0} +k_0={k0}"),
        Some(10) => format!("+proj=laea +lat_0={lat0} +lon_0={lon0}"),
        Some(11) => format!(
            "+proj=aea +lat_1={} +lat_2={} +lat_0={lat0} +lon_0={lon0}",
            sp(3078)?,
            sp(3079)?
        ),
        Some(t) => return Err(format!("coordinate transformation {t}")),
        None => return Err("no coordinate transformation (GeoKey 3075)".into()),
    };
    let def = format!("{proj} +x_0={fe} +y_0={fn_} {datum} +units={unit} +no_defs");
    Crs::parse(&def)
        .map(SourceCrs::Epsg)
        .map_err(|e| e.to_string())
}
