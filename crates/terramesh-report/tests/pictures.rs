//! Pictures render deterministically and show what they should.

use plotters::prelude::{BitMapBackend, IntoDrawingArea};
use terramesh_report::pictures::{
    draw_bodies_view3d, draw_mesh, draw_samples, draw_surface, draw_view3d, render_both, ColourMap,
    DynBackend, RGBColor, SurfaceMap,
};

/// A hill on a grid at UTM magnitudes.
fn hill() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let n = 30;
    let mut v = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f64 * 10.0, j as f64 * 10.0);
            let r2 = (x - 150.0).powi(2) + (y - 140.0).powi(2);
            v.push([
                377_676.0 + x,
                5_397_931.0 + y,
                350.0 + 80.0 * (-r2 / 8000.0).exp(),
            ]);
        }
    }
    let mut t = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = (j * n + i) as u32;
            t.push([a, a + 1, a + n as u32 + 1]);
            t.push([a, a + n as u32 + 1, a + n as u32]);
        }
    }
    (v, t)
}

fn render_all(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let (v, t) = hill();
    let xy: Vec<[f64; 2]> = v.iter().map(|p| [p[0], p[1]]).collect();
    let z: Vec<f64> = v.iter().map(|p| p[2]).collect();
    let outline = vec![vec![
        [377_676.0, 5_397_931.0],
        [377_966.0, 5_397_931.0],
        [377_966.0, 5_398_221.0],
        [377_676.0, 5_398_221.0],
    ]];
    let mut files = Vec::new();
    files.extend(
        render_both(&dir.join("samples"), (640, 480), |r| {
            draw_samples(r, &v, &outline, "Samples")
        })
        .unwrap(),
    );
    files.extend(
        render_both(&dir.join("mesh"), (640, 480), |r| {
            draw_mesh(r, &xy, &t, &outline, "Mesh")
        })
        .unwrap(),
    );
    let map = SurfaceMap {
        xy: &xy,
        values: &z,
        shade_z: Some(&z),
        triangles: &t,
        title: "Elevation",
        unit: "elevation (m)",
        colours: ColourMap::Terrain,
        symmetric: false,
        outlines: &outline,
    };
    files.extend(render_both(&dir.join("surface"), (640, 480), |r| draw_surface(r, &map)).unwrap());
    files.extend(
        render_both(&dir.join("view3d"), (640, 480), |r| {
            draw_view3d(r, &v, &t, 2.0, "3D")
        })
        .unwrap(),
    );
    files
}

#[test]
fn pictures_are_deterministic_and_not_blank() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let fa = render_all(a.path());
    let fb = render_all(b.path());
    assert_eq!(fa.len(), 8);
    for (x, y) in fa.iter().zip(&fb) {
        let (bx, by) = (std::fs::read(x).unwrap(), std::fs::read(y).unwrap());
        assert_eq!(bx, by, "{} differs between two renders", x.display());
        assert!(bx.len() > 2000, "{} is suspiciously small", x.display());
    }
    let svg = std::fs::read_to_string(a.path().join("surface.svg")).unwrap();
    // 29 x 29 x 2 filled triangles, contour paths, and the title.
    assert!(
        svg.matches("<polygon").count() >= 29 * 29 * 2,
        "filled triangles"
    );
    assert!(svg.contains("Elevation") && svg.contains("elevation (m)"));
    if let Ok(dir) = std::env::var("TERRAMESH_KEEP_PICTURES") {
        for f in &fa {
            std::fs::copy(f, std::path::Path::new(&dir).join(f.file_name().unwrap())).unwrap();
        }
    }
}

/// A jittered grid of `n` x `n` points over 3 km with a rough surface: at picture size most
/// of its triangles are smaller than a pixel, some thin, some sharing pixels.
fn dense(n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut rand = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let h = 3000.0 / n as f64;
    let mut v = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (
                i as f64 * h + 0.45 * h * (rand() - 0.5),
                j as f64 * h + 0.45 * h * (rand() - 0.5),
            );
            let z = 200.0 + 60.0 * (x / 400.0).sin() * (y / 700.0).cos() + 3.0 * rand();
            v.push([500_000.0 + x, 4_000_000.0 + y, z]);
        }
    }
    let mut t = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            t.push([a, a + 1, a + n + 1]);
            t.push([a, a + n + 1, a + n]);
        }
    }
    (v, t)
}

/// The RGB pixels of `draw` on plotters' own bitmap backend and on the buffer backend
/// whose triangles are filled directly.
fn both_ways(
    size: (u32, u32),
    draw: impl Fn(
        &plotters::drawing::DrawingArea<DynBackend<'_>, plotters::coord::Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>,
) -> (Vec<u8>, Vec<u8>) {
    let n = size.0 as usize * size.1 as usize * 3;
    let (mut theirs, mut ours) = (vec![255u8; n], vec![255u8; n]);
    {
        let root =
            DynBackend::Bitmap(BitMapBackend::with_buffer(&mut theirs, size)).into_drawing_area();
        draw(&root).unwrap();
        root.present().unwrap();
    }
    {
        let root = DynBackend::Pixels(&mut ours, size).into_drawing_area();
        draw(&root).unwrap();
        root.present().unwrap();
    }
    (theirs, ours)
}

fn assert_same(what: &str, size: (u32, u32), (theirs, ours): (Vec<u8>, Vec<u8>)) {
    let differ = theirs
        .chunks(3)
        .zip(ours.chunks(3))
        .position(|(a, b)| a != b);
    if let Some(p) = differ {
        panic!(
            "{what}: pixel ({}, {}) differs: {:?} vs {:?}",
            p % size.0 as usize,
            p / size.0 as usize,
            &theirs[p * 3..p * 3 + 3],
            &ours[p * 3..p * 3 + 3]
        );
    }
    // Not blank: the drawing covers a good part of the picture.
    let drawn = theirs.chunks(3).filter(|p| p != &[255, 255, 255]).count();
    eprintln!("{what}: {drawn} pixels drawn");
    assert!(drawn > theirs.len() / 3 / 8, "{what}: mostly white");
}

#[test]
fn direct_fills_give_plotters_pixels() {
    // (Any rendering registers the bundled font, which the drawings' text needs.)
    let dir = tempfile::tempdir().unwrap();
    render_both(&dir.path().join("font"), (10, 10), |_| Ok(())).unwrap();
    for (n, size) in [(30, (640, 480)), (260, (420, 330))] {
        let (v, t) = if n == 30 { hill() } else { dense(n) };
        let xy: Vec<[f64; 2]> = v.iter().map(|p| [p[0], p[1]]).collect();
        let z: Vec<f64> = v.iter().map(|p| p[2]).collect();
        // A difference field with a hole of NaN values, symmetric colours.
        let d: Vec<f64> = z
            .iter()
            .enumerate()
            .map(|(k, z)| {
                if k % 97 == 5 {
                    f64::NAN
                } else {
                    (z - 230.0) * 0.01
                }
            })
            .collect();
        for (values, shade_z, colours, symmetric) in [
            (&z, Some(&z[..]), ColourMap::Terrain, false),
            (&d, None, ColourMap::Diverging, true),
        ] {
            let map = SurfaceMap {
                xy: &xy,
                values,
                shade_z,
                triangles: &t,
                title: "Map",
                unit: "m",
                colours,
                symmetric,
                outlines: &[],
            };
            assert_same(
                &format!("surface of {} triangles", t.len()),
                size,
                both_ways(size, |r| draw_surface(r, &map)),
            );
        }
        assert_same(
            &format!("3D view of {} triangles", t.len()),
            size,
            both_ways(size, |r| draw_view3d(r, &v, &t, 3.0, "3D")),
        );
        // Bodies: the surface's triangles in turns of colour, those facing away left out.
        let c: Vec<RGBColor> = (0..t.len())
            .map(|k| RGBColor((k * 37 % 256) as u8, 120, (k * 11 % 256) as u8))
            .collect();
        let folded: Vec<[u32; 3]> = t
            .iter()
            .enumerate()
            .map(|(k, t)| if k % 3 == 0 { [t[0], t[2], t[1]] } else { *t })
            .collect();
        assert_same(
            &format!("bodies of {} triangles", t.len()),
            size,
            both_ways(size, |r| {
                draw_bodies_view3d(r, &v, &folded, &c, 2.0, "bodies")
            }),
        );
    }
}
