//! The boreholes in the report's 3D viewer: each hole as a square tube along its desurveyed
//! path, in the colour of each logged unit ([`borehole_traces`]).

use terramesh_io::boreholes::{ContactKind, Hole, Thickness};
use terramesh_report::pictures::unit_colour;

/// Half-width of a borehole trace, as a fraction of the scene's horizontal extent.
pub(crate) const TRACE_RADIUS: f64 = 0.004;
/// Colour of a hole's stretch above its first logged top.
pub(crate) const UNLOGGED: [u8; 3] = [110, 110, 110];
/// How far (percent of the logged depth) a hole is drawn below the top of its lowest logged
/// unit when that unit's base is not observed.
pub(crate) const STUB_FRACTION_PERCENT: f64 = 5.0;

/// Borehole traces: triangles with one colour per vertex.
pub(crate) struct Traces {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub colours: Vec<[u8; 3]>,
}

/// Each hole as a square tube of half-width `radius` along its desurveyed path: from the
/// collar to its first logged top in [`UNLOGGED`] grey, then every logged unit from its top to
/// the next logged top in [`unit_colour`]; the lowest logged unit down to its observed base
/// (its vertical thickness), or [`STUB_FRACTION_PERCENT`] of the logged depth when the base
/// is not observed. Curved stretches are drawn as up to 16 straight pieces, as many as keep the
/// chords within a quarter of `radius` of the path; straight ones as one.
pub(crate) fn borehole_traces(holes: &[&Hole], radius: f64) -> Traces {
    let mut t = Traces {
        positions: Vec::new(),
        triangles: Vec::new(),
        colours: Vec::new(),
    };
    for h in holes {
        // Absent units share the next unit's top: left out; of two tops at one depth (a
        // repaired inversion) the lower unit of the column is the one logged below.
        let mut contacts: Vec<(f64, usize)> = h
            .tops
            .iter()
            .flatten()
            .filter(|c| c.kind != ContactKind::Absent)
            .map(|c| (c.md, c.unit))
            .collect();
        contacts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        contacts.reverse();
        contacts.dedup_by(|b, a| b.0 == a.0);
        contacts.reverse();
        let Some(&(last_md, last_unit)) = contacts.last() else {
            continue;
        };
        let mut spans: Vec<(f64, f64, [u8; 3])> = Vec::new();
        if contacts[0].0 > 0.0 {
            spans.push((0.0, contacts[0].0, UNLOGGED));
        }
        let colour = |k: usize| {
            let c = unit_colour(k);
            [c.0, c.1, c.2]
        };
        for w in contacts.windows(2) {
            spans.push((w[0].0, w[1].0, colour(w[0].1)));
        }
        let below = match h.thickness.get(last_unit) {
            Some(Thickness::Known(th)) if *th > 0.0 => *th,
            _ => (last_md * STUB_FRACTION_PERCENT / 100.0).max(radius),
        };
        spans.push((last_md, last_md + below, colour(last_unit)));
        let first = t.positions.len() as u32;
        for (a, b, c) in spans {
            if b <= a {
                continue;
            }
            let (Ok(pa), Ok(pm), Ok(pb)) = (h.path.at(a), h.path.at(0.5 * (a + b)), h.path.at(b))
            else {
                continue;
            };
            // Pieces enough that the chords stay within a quarter of the radius of the path
            // (the sagitta falls as the square of their number): a straight stretch is one.
            let sag = (0..3)
                .map(|k| (pm[k] - 0.5 * (pa[k] + pb[k])).powi(2))
                .sum::<f64>()
                .sqrt();
            let pieces = ((sag / (0.25 * radius)).sqrt().ceil() as usize).clamp(1, 16);
            let mut prev = pa;
            for k in 1..=pieces {
                let Ok(next) = h.path.at(a + (b - a) * k as f64 / pieces as f64) else {
                    break;
                };
                tube(&mut t, prev, next, radius, c);
                prev = next;
            }
        }
        // The tube's two ends (the pieces' own ends meet inside it).
        let last = t.positions.len() as u32;
        if last > first {
            let (a, z) = (first, last - 4);
            t.triangles.push([a, a + 2, a + 1]);
            t.triangles.push([a, a + 3, a + 2]);
            t.triangles.push([z, z + 1, z + 2]);
            t.triangles.push([z, z + 2, z + 3]);
        }
    }
    t
}

/// The four sides of a square tube from `a` to `b`: its vertices at `a` then at `b`.
fn tube(t: &mut Traces, a: [f64; 3], b: [f64; 3], r: f64, c: [u8; 3]) {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if len == 0.0 {
        return;
    }
    let u = d.map(|v| v / len);
    // A horizontal unit vector across the hole (east for a vertical one), and a second one.
    let n = u[0].hypot(u[1]);
    let p = if n < 1e-9 {
        [1.0, 0.0, 0.0]
    } else {
        [-u[1] / n, u[0] / n, 0.0]
    };
    let q = [
        u[1] * p[2] - u[2] * p[1],
        u[2] * p[0] - u[0] * p[2],
        u[0] * p[1] - u[1] * p[0],
    ];
    let base = t.positions.len() as u32;
    for end in [a, b] {
        for (sp, sq) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
            t.positions
                .push([0, 1, 2].map(|k| end[k] + r * (sp * p[k] + sq * q[k])));
            t.colours.push(c);
        }
    }
    for k in 0..4u32 {
        let (i, j) = (base + k, base + (k + 1) % 4);
        t.triangles.push([i, j, j + 4]);
        t.triangles.push([i, j + 4, i + 4]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_trace_runs_down_the_hole_in_each_logged_units_colour() {
        use terramesh_core::desurvey::HolePath;
        use terramesh_io::boreholes::Contact;
        let collar = [500.0, 300.0, 100.0];
        let top = |unit, md, kind| {
            Some(Contact {
                unit,
                md,
                position: [500.0, 300.0, 100.0 - md],
                kind,
                line: 2,
            })
        };
        let hole = Hole {
            name: "B1".into(),
            line: 2,
            collar,
            path: HolePath::vertical(collar),
            // unit 0 absent (its top is unit 1's), units 1-3 logged; unit 3's base unseen
            tops: vec![
                top(0, 4.0, ContactKind::Absent),
                top(1, 4.0, ContactKind::Logged),
                top(2, 10.0, ContactKind::Logged),
                top(3, 30.0, ContactKind::Logged),
            ],
            thickness: vec![
                Thickness::Known(0.0),
                Thickness::Known(6.0),
                Thickness::Known(20.0),
                Thickness::Censored,
            ],
            repeated: Vec::new(),
            restarts: Vec::new(),
        };
        let r = 0.5;
        let t = borehole_traces(&[&hole], r);
        assert_eq!(t.positions.len(), t.colours.len());
        let rgb = |k: usize| {
            let c = unit_colour(k);
            [c.0, c.1, c.2]
        };
        // Depth range of each colour: grey 0-4, unit 1 4-10, unit 2 10-30, unit 3 30-31.5
        // (the stub: 5 % of 30 m); unit 0 (absent) nowhere.
        for (c, lo, hi) in [
            (UNLOGGED, 0.0, 4.0),
            (rgb(1), 4.0, 10.0),
            (rgb(2), 10.0, 30.0),
            (rgb(3), 30.0, 31.5),
        ] {
            let d: Vec<f64> = t
                .positions
                .iter()
                .zip(&t.colours)
                .filter(|(_, k)| **k == c)
                .map(|(p, _)| 100.0 - p[2])
                .collect();
            let (a, b) = d
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            assert!(
                (a - lo).abs() < 1e-9 && (b - hi).abs() < 1e-9,
                "{c:?}: {a}..{b}"
            );
        }
        assert!(!t.colours.contains(&rgb(0)) || rgb(0) == rgb(3));
        // A tube of half-width r around the axis, every triangle one colour.
        for p in &t.positions {
            let off = (p[0] - 500.0).abs().max((p[1] - 300.0).abs());
            assert!((off - r).abs() < 1e-9, "{p:?}");
        }
        for tri in &t.triangles {
            let c = tri.map(|i| t.colours[i as usize]);
            assert!(c[0] == c[1] && c[1] == c[2]);
        }
    }

    #[test]
    fn a_curved_hole_is_drawn_in_pieces_along_its_path_and_a_straight_one_in_one() {
        use terramesh_core::desurvey::{HolePath, Station};
        use terramesh_io::boreholes::Contact;
        let collar = [0.0, 0.0, 0.0];
        let st = |depth, dip| Station {
            depth,
            azimuth: 90.0,
            dip,
        };
        let path = HolePath::new(collar, &[st(0.0, 90.0), st(100.0, 45.0)]).unwrap();
        let contact = |unit, md| {
            Some(Contact {
                unit,
                md,
                position: path.at(md).unwrap(),
                kind: ContactKind::Logged,
                line: 2,
            })
        };
        let hole = Hole {
            name: "C".into(),
            line: 2,
            collar,
            path: path.clone(),
            tops: vec![contact(0, 0.0), contact(1, 100.0)],
            thickness: vec![Thickness::Known(60.0), Thickness::Known(10.0)],
            repeated: Vec::new(),
            restarts: Vec::new(),
        };
        let t = borehole_traces(&[&hole], 0.5);
        // Rings of four vertices: each piece has one at either end.
        let centres: Vec<[f64; 3]> = t
            .positions
            .chunks(4)
            .map(|r| [0, 1, 2].map(|k| r.iter().map(|p| p[k]).sum::<f64>() / 4.0))
            .collect();
        let pieces = centres.len() / 2;
        assert!(pieces > 2, "{pieces} pieces");
        // The first span (0-100 m, curved) in n pieces ending on the path at k/n of it.
        let n = (0..pieces)
            .take_while(|&k| t.colours[8 * k] == t.colours[0])
            .count();
        assert!(n > 1, "the curved span in {n} piece(s)");
        for k in 1..=n {
            let want = path.at(100.0 * k as f64 / n as f64).unwrap();
            let got = centres[2 * k - 1];
            assert!(
                (0..3).all(|j| (got[j] - want[j]).abs() < 1e-9),
                "{got:?} {want:?}"
            );
        }
        // The lowest unit, straight below the last station, in one piece.
        assert_eq!(pieces - n, 1);
    }
}
