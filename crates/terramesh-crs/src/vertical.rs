//! The vertical CRSs of the EPSG registry: what a project's heights may be said to refer to
//! (`[region] vertical_datum = "EPSG:<code>"`).
//!
//! The table (`vertical.csv`, written by `fixtures/crs/make_vertical.py` from PROJ's EPSG
//! database through pyproj) lists every EPSG vertical CRS, deprecated ones included, with the
//! direction of its axis (heights up, depths down) and its unit. The `crs-definitions` table of
//! [`Crs`](crate::Crs) has horizontal and compound CRSs only.
//!
//! ```
//! use terramesh_crs::vertical;
//! let navd88 = vertical::lookup(5703).unwrap();
//! assert_eq!(navd88.name, "NAVD88 height");
//! assert!(navd88.is_metre_height());
//! let ft = vertical::lookup(6360).unwrap(); // NAVD88 height (ftUS)
//! assert_eq!(ft.unit, "US survey foot");
//! assert_eq!(ft.metre_twin().map(|v| v.code), Some(5703));
//! assert!(!vertical::lookup(5715).unwrap().up); // MSL depth
//! assert!(vertical::lookup(4326).is_none()); // WGS 84 is horizontal
//! ```

use std::sync::OnceLock;

/// One EPSG vertical CRS.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VerticalCrs {
    /// The EPSG code.
    pub code: u32,
    /// Its EPSG name (`NAVD88 height`).
    pub name: &'static str,
    /// Whether its axis points up (a height); `false`: down (a depth).
    pub up: bool,
    /// The unit of its axis, as EPSG names it (`metre`, `foot`, `US survey foot`).
    pub unit: &'static str,
    /// Whether EPSG has deprecated the code.
    pub deprecated: bool,
}

impl VerticalCrs {
    /// Whether it measures heights in metres, as terramesh's outputs hold them.
    pub fn is_metre_height(&self) -> bool {
        self.up && self.unit == "metre"
    }

    /// The height CRS in metres on the same datum, for a CRS in feet or of depths: the one
    /// whose name is this name without its unit or direction (`NAVD88 height (ftUS)` ->
    /// `NAVD88 height`, `MSL depth` -> `MSL height`), when there is one.
    pub fn metre_twin(&self) -> Option<&'static VerticalCrs> {
        if self.is_metre_height() {
            return None;
        }
        let base = match self.name.rfind(" (") {
            Some(i) if self.name.ends_with(')') => &self.name[..i],
            _ => self.name,
        };
        let base = match base.strip_suffix(" depth") {
            Some(b) => format!("{b} height"),
            None => base.to_string(),
        };
        all()
            .iter()
            .find(|v| v.is_metre_height() && !v.deprecated && v.name == base)
    }
}

/// Every vertical CRS of the table, by code.
pub fn all() -> &'static [VerticalCrs] {
    static TABLE: OnceLock<Vec<VerticalCrs>> = OnceLock::new();
    TABLE.get_or_init(|| {
        include_str!("vertical.csv")
            .lines()
            .skip(1)
            .filter_map(|line| {
                // code,name,direction,unit,deprecated; the name may hold commas.
                let (code, rest) = line.split_once(',')?;
                let mut tail = rest.rsplitn(4, ',');
                let deprecated = tail.next()? == "1";
                let unit = tail.next()?;
                let up = tail.next()? == "up";
                let name = tail.next()?.trim_matches('"');
                Some(VerticalCrs {
                    code: code.parse().ok()?,
                    name,
                    up,
                    unit,
                    deprecated,
                })
            })
            .collect()
    })
}

/// The vertical CRS of an EPSG code, `None` when the code is not one (a horizontal CRS, or no
/// CRS at all).
pub fn lookup(code: u32) -> Option<&'static VerticalCrs> {
    all()
        .binary_search_by_key(&code, |v| v.code)
        .ok()
        .map(|i| &all()[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table is whole: every row parsed, sorted by code, and the datums terramesh names
    /// (`KNOWN_VERTICAL_DATUMS` of the facade) are metre heights but NGVD29's.
    #[test]
    fn the_table_parses_whole_and_sorted() {
        let rows = include_str!("vertical.csv").lines().count() - 1;
        assert_eq!(all().len(), rows);
        assert!(all().windows(2).all(|w| w[0].code < w[1].code));
        for c in [5773, 3855, 5703, 5709, 5783, 7837, 5720, 5701] {
            assert!(lookup(c).is_some_and(|v| v.is_metre_height()), "{c}");
        }
        // NGVD29 in US survey feet (5702) and in metres (7968, what the name `ngvd29` names).
        assert_eq!(lookup(5702).map(|v| v.unit), Some("US survey foot"));
        assert_eq!(
            lookup(5715).and_then(|v| v.metre_twin()).map(|v| v.code),
            Some(5714)
        );
    }
}
