//! Writers read back structurally: counts, declared precision, exact coordinates and area.

use super::*;

/// A 3 x 2 grid of unit squares, two triangles each, at UTM magnitudes.
fn grid() -> (Vec<[f64; 2]>, Vec<[u32; 3]>, Vec<f64>) {
    let mut pts = Vec::new();
    for j in 0..3 {
        for i in 0..4 {
            pts.push([i as f64 + 0.125, j as f64 + 0.375]);
        }
    }
    let mut tris = Vec::new();
    for j in 0..2u32 {
        for i in 0..3u32 {
            let a = j * 4 + i;
            tris.push([a, a + 1, a + 5]);
            tris.push([a, a + 5, a + 4]);
        }
    }
    let z = (0..pts.len()).map(|i| i as f64 * 0.5).collect();
    (pts, tris, z)
}

const ORIGIN: [f64; 2] = [377_676.934_123, 5_397_931.494_567];

/// Planar area of triangles over absolute points.
fn area(points: &[[f64; 3]], tris: &[[usize; 3]]) -> f64 {
    tris.iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| points[i]);
            // Shift to a for precision.
            0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
        })
        .sum()
}

fn nums(line: &str) -> Vec<f64> {
    line.split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

fn written(ext: &str) -> (String, MeshView<'static>) {
    let (bytes, m) = written_bytes(ext);
    (String::from_utf8_lossy(&bytes).into_owned(), m)
}

fn written_bytes(ext: &str) -> (Vec<u8>, MeshView<'static>) {
    let (pts, tris, z) = grid();
    let (pts, tris, z) = (pts.leak(), tris.leak(), z.leak());
    let mut m = MeshView::planar(ORIGIN, pts, tris);
    m.z = Some(z);
    m.point_data.push(("elevation", z));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join(format!("m.{ext}"));
    write_mesh(&p, &m).unwrap();
    (std::fs::read(&p).unwrap(), m)
}

fn check(points: &[[f64; 3]], tris: &[[usize; 3]], m: &MeshView) {
    assert_eq!(points.len(), m.points.len());
    assert_eq!(tris.len(), m.triangles.len());
    for (i, p) in points.iter().enumerate() {
        assert_eq!(*p, m.point(i), "point {i} round trip");
    }
    assert!((area(points, tris) - 6.0).abs() < 1e-6);
}

#[test]
fn vtu_has_float64_points_and_round_trips() {
    let (text, m) = written("vtu");
    assert!(text.contains("type=\"Float64\" NumberOfComponents=\"3\""));
    assert!(text.contains("Name=\"elevation\""));
    let section = |name: &str| -> Vec<String> {
        let start = text.find(&format!("Name=\"{name}\"")).unwrap();
        let body = &text[start..];
        let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
        body.lines()
            .filter(|l| !l.trim().is_empty())
            .map(String::from)
            .collect()
    };
    let start = text.find("NumberOfComponents=\"3\"").unwrap();
    let body = &text[start..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    let points: Vec<[f64; 3]> = body
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v = nums(l);
            [v[0], v[1], v[2]]
        })
        .collect();
    let tris: Vec<[usize; 3]> = section("connectivity")
        .iter()
        .map(|l| {
            let v = nums(l);
            [v[0] as usize, v[1] as usize, v[2] as usize]
        })
        .collect();
    assert_eq!(section("offsets").last().unwrap(), "36");
    check(&points, &tris, &m);
}

#[test]
fn obj_round_trips() {
    let (text, m) = written("obj");
    let points: Vec<[f64; 3]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v = nums(l);
            [v[0], v[1], v[2]]
        })
        .collect();
    let tris: Vec<[usize; 3]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|l| {
            let v = nums(l);
            [v[0] as usize - 1, v[1] as usize - 1, v[2] as usize - 1]
        })
        .collect();
    check(&points, &tris, &m);
}

#[test]
fn ply_round_trips() {
    let (bytes, m) = written_bytes("ply");
    let at = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let head = std::str::from_utf8(&bytes[..at]).unwrap();
    assert!(head.contains("format binary_little_endian 1.0"));
    assert!(head.contains("property double x") && head.contains("property double elevation"));
    assert!(head.contains("element vertex 12") && head.contains("element face 12"));
    let f64_at = |o: usize| f64::from_le_bytes(bytes[o..o + 8].try_into().unwrap());
    let points: Vec<[f64; 3]> = (0..12)
        .map(|i| {
            let o = at + i * 32;
            assert_eq!(f64_at(o + 24), f64_at(o + 16), "elevation field equals z");
            [f64_at(o), f64_at(o + 8), f64_at(o + 16)]
        })
        .collect();
    let faces = at + 12 * 32;
    assert_eq!(bytes.len(), faces + 12 * 13);
    let tris: Vec<[usize; 3]> = (0..12)
        .map(|k| {
            let o = faces + k * 13;
            assert_eq!(bytes[o], 3);
            let i = |j: usize| {
                i32::from_le_bytes(bytes[o + 1 + 4 * j..o + 5 + 4 * j].try_into().unwrap()) as usize
            };
            [i(0), i(1), i(2)]
        })
        .collect();
    check(&points, &tris, &m);
}

#[test]
fn msh41_round_trips() {
    let (text, m) = written("msh");
    assert!(text.starts_with("$MeshFormat\n4.1 0 8\n"));
    let nodes = &text[text.find("$Nodes\n").unwrap() + 7..text.find("$EndNodes").unwrap()];
    let lines: Vec<&str> = nodes.lines().collect();
    assert_eq!(lines[0], "1 12 1 12");
    let points: Vec<[f64; 3]> = lines[2 + 12..]
        .iter()
        .map(|l| {
            let v = nums(l);
            [v[0], v[1], v[2]]
        })
        .collect();
    let elems = &text[text.find("$Elements\n").unwrap() + 10..text.find("$EndElements").unwrap()];
    let tris: Vec<[usize; 3]> = elems
        .lines()
        .skip(2)
        .map(|l| {
            let v = nums(l);
            [v[1] as usize - 1, v[2] as usize - 1, v[3] as usize - 1]
        })
        .collect();
    check(&points, &tris, &m);
}

#[test]
fn unknown_extension_and_unwritable_path_are_errors() {
    let (pts, tris, _) = grid();
    let m = MeshView::planar(ORIGIN, &pts, &tris);
    let e = write_mesh(Path::new("/tmp/x.stl"), &m)
        .unwrap_err()
        .to_string();
    assert!(e.contains("x.stl") && e.contains(".msh"), "{e}");
    let e = write_mesh(Path::new("/nonexistent-dir/x.vtu"), &m)
        .unwrap_err()
        .to_string();
    assert!(e.contains("/nonexistent-dir"), "{e}");
}
