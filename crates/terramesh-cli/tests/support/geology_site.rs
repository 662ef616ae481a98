//! The small geological site of the CLI tests (`model_build.rs`, `report_viewer.rs`), written
//! into a test's temporary folder.

use std::path::{Path, PathBuf};

/// A 600 x 450 m site near Saverne: the ground, 12 holes, three units; the clay thins to
/// nothing towards the east (a pinch-out).
pub fn site(dir: &Path) -> PathBuf {
    let (lat0, lon0) = (48.7200, 7.3350);
    let ground = |i: f64, j: f64| 300.0 + 8.0 * (i / 5.0).sin() + 0.6 * j;
    let mut heights = String::from("lat,lon,z\n");
    for i in 0..16 {
        for j in 0..16 {
            let (lat, lon) = (lat0 + 0.0003 * i as f64, lon0 + 0.0004 * j as f64);
            heights += &format!("{lat},{lon},{}\n", ground(i as f64, j as f64));
        }
    }
    std::fs::write(dir.join("heights.csv"), heights).unwrap();
    let mut collars = String::from("hole,lat,lon,z\n");
    let mut tops = String::from("hole,unit,depth\n");
    for k in 0..12 {
        let (i, j) = (3.0 + 3.5 * (k / 4) as f64, 3.0 + 3.3 * (k % 4) as f64);
        let (lat, lon) = (lat0 + 0.0003 * i, lon0 + 0.0004 * j);
        collars += &format!("B{k},{lat},{lon},{}\n", ground(i, j));
        let clay = (12.0 - 1.1 * j).max(0.0);
        tops += &format!(
            "B{k},sand,0\nB{k},clay,{}\nB{k},gravel,{}\n",
            6.0 + 0.3 * i,
            6.0 + 0.3 * i + clay
        );
    }
    std::fs::write(dir.join("collars.csv"), collars).unwrap();
    std::fs::write(dir.join("tops.csv"), tops).unwrap();
    let project = dir.join("site.toml");
    std::fs::write(
        &project,
        r#"
[region]
corners = "48.7206 7.3358; 48.7206 7.3408; 48.7240 7.3408; 48.7240 7.3358"
[source]
path = "heights.csv"
[mesh]
max_area = 400.0
[interpolation]
methods = ["uk", "idw"]
[export]
formats = ["vtu", "glb"]
pictures = false
report = false
[geology]
collars = "collars.csv"
tops = "tops.csv"
units = ["sand", "clay", "gravel"]
base = 250.0
min_thickness = 0.5
layers = { sand = 2 }
"#,
    )
    .unwrap();
    project
}
