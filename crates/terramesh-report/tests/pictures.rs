//! Pictures render deterministically and show what they should.

use terramesh_report::pictures::{
    draw_mesh, draw_samples, draw_surface, draw_view3d, render_both, ColourMap, SurfaceMap,
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
