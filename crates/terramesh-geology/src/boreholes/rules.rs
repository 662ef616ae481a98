//! The rules that turn the units present in a hole into contacts and thicknesses: placing
//! every top on the desurveyed path, repairing small inversions (onlap), giving absent units
//! zero thickness, and censoring the bases the log does not show.

use terramesh_core::desurvey::HolePath;

use super::{At, Contact, ContactError, ContactKind, HoleRules, Present, Repair, Thickness};

/// The measured depth at which `path` reaches elevation `z` (bisection: a hole never rises).
fn md_at_elevation(path: &HolePath, z: f64) -> Option<f64> {
    let z_at = |md: f64| path.at(md).map(|p| p[2]).ok();
    let mut hi = (path.collar()[2] - z).max(1.0);
    while z_at(hi)? > z {
        hi *= 2.0;
        if hi > 1e8 {
            return None;
        }
    }
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if z_at(mid)? > z {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(hi)
}

/// The contacts (per unit of the column), the thicknesses and the repairs of one hole.
pub type HoleResult = (Vec<Option<Contact>>, Vec<Thickness>, Vec<Repair>);

/// Applies the rules of the module documentation to the units `present` in one hole (in
/// column order, each unit once), desurveyed as `path`.
///
/// # Errors
/// A top the path cannot place ([`ContactError::Outside`]); an inversion larger than
/// [`HoleRules::max_inversion`] ([`ContactError::Inversion`]).
pub fn contacts(
    ctx: &HoleRules,
    path: &HolePath,
    present: &[Present],
) -> Result<HoleResult, ContactError> {
    let outside = |line: u64, what: String| ContactError::Outside { line, what };
    let n = ctx.units;
    let mut tops: Vec<Option<Contact>> = vec![None; n];
    let mut repairs = Vec::new();
    // The lowest top placed so far (rule 2 compares against it).
    let mut lowest: Option<Contact> = None;
    for p in present {
        let Some(at) = p.top else { continue };
        let (md, position) = match at {
            At::Depth(md) => {
                let pos = path.at(md).map_err(|e| outside(p.line, e.to_string()))?;
                (md, pos)
            }
            At::Elevation(z) => {
                let md = md_at_elevation(path, z).ok_or_else(|| {
                    outside(
                        p.line,
                        format!("the surveyed hole never reaches elevation {z} m"),
                    )
                })?;
                let pos = path.at(md).map_err(|e| outside(p.line, e.to_string()))?;
                // Keep the elevation as given, exactly.
                (md, [pos[0], pos[1], z])
            }
        };
        let mut c = Contact {
            unit: p.unit,
            md,
            position,
            kind: p.kind,
            line: p.line,
        };
        match lowest {
            Some(low) if c.position[2] > low.position[2] => {
                let amount = c.position[2] - low.position[2];
                if amount > ctx.max_inversion || amount.is_nan() {
                    return Err(ContactError::Inversion {
                        line: p.line,
                        unit: p.unit,
                        above: low.unit,
                        above_line: low.line,
                        amount,
                        max: ctx.max_inversion,
                    });
                }
                repairs.push(Repair {
                    hole: ctx.hole.to_string(),
                    unit: p.unit,
                    above: low.unit,
                    line: p.line,
                    amount,
                });
                c.md = low.md;
                c.position = low.position;
                c.kind = ContactKind::Repaired;
            }
            _ => lowest = Some(c),
        }
        tops[p.unit] = Some(c);
    }
    // Rule 3: an absent unit above a present one has zero thickness at its top.
    let is_present = |u: usize| present.iter().any(|p| p.unit == u);
    for u in 0..n {
        if is_present(u) {
            continue;
        }
        if let Some(next) = present.iter().find(|p| p.unit > u) {
            if let Some(c) = tops[next.unit] {
                tops[u] = Some(Contact {
                    unit: u,
                    kind: ContactKind::Absent,
                    ..c
                });
            }
        }
    }
    // Rule 4: thickness where both the top and the base are contacts.
    let thickness = (0..n)
        .map(|u| match (tops[u], tops.get(u + 1).copied().flatten()) {
            (None, _) => Thickness::Unknown,
            (Some(t), Some(b)) => Thickness::Known(t.position[2] - b.position[2]),
            (Some(_), None) => Thickness::Censored,
        })
        .collect();
    Ok((tops, thickness, repairs))
}
