//! Triangle quality in 2D (the planar mesh) and 3D (the mesh lifted to a surface): angles,
//! radius ratio, aspect ratio, area and edge statistics, and an angle histogram.

use std::fmt;

use rayon::prelude::*;

use crate::mesh::Mesh;

/// Triangles measured at a time by [`Quality::planar`] and [`Quality::surface`].
const QUALITY_BLOCK: usize = 65_536;

/// Shape measures of one triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleQuality {
    /// Smallest angle, degrees.
    pub min_angle: f64,
    /// Largest angle, degrees.
    pub max_angle: f64,
    /// The three angles, degrees, at the three vertices.
    pub angles: [f64; 3],
    /// Radius ratio `2 r / R` (inradius over circumradius, 1 for an equilateral triangle,
    /// 0 for a degenerate one).
    pub radius_ratio: f64,
    /// Aspect ratio `l_max / (2 sqrt(3) r)` (longest edge over inradius, normalised to 1 for
    /// an equilateral triangle; grows without bound as it degenerates).
    pub aspect_ratio: f64,
    /// Area.
    pub area: f64,
    /// Edge lengths (opposite vertices 0, 1, 2 in turn: `|p1 p2|`, `|p2 p0|`, `|p0 p1|`).
    pub edges: [f64; 3],
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross_norm(a: [f64; 3], b: [f64; 3]) -> f64 {
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    dot(c, c).sqrt()
}

/// Quality of the triangle `p` (3D points; use `z = 0` for planar triangles).
///
/// Angles use `atan2(|u x v|, u . v)`, accurate for needle-like triangles.
///
/// ```
/// use terramesh_mesh::triangle_quality;
/// let q = triangle_quality([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.75f64.sqrt(), 0.0]]);
/// assert!((q.min_angle - 60.0).abs() < 1e-9);
/// assert!((q.radius_ratio - 1.0).abs() < 1e-12 && (q.aspect_ratio - 1.0).abs() < 1e-12);
/// let r = triangle_quality([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
/// assert!((r.max_angle - 90.0).abs() < 1e-9 && (r.area - 0.5).abs() < 1e-15);
/// ```
pub fn triangle_quality(p: [[f64; 3]; 3]) -> TriangleQuality {
    let mut angles = [0.0; 3];
    for (k, angle) in angles.iter_mut().enumerate() {
        let u = sub(p[(k + 1) % 3], p[k]);
        let v = sub(p[(k + 2) % 3], p[k]);
        *angle = cross_norm(u, v).atan2(dot(u, v)).to_degrees();
    }
    let edges = [0, 1, 2].map(|k| {
        let d = sub(p[(k + 2) % 3], p[(k + 1) % 3]);
        dot(d, d).sqrt()
    });
    let area = 0.5 * cross_norm(sub(p[1], p[0]), sub(p[2], p[0]));
    let perim = edges[0] + edges[1] + edges[2];
    let r = if perim > 0.0 { 2.0 * area / perim } else { 0.0 };
    let prod = edges[0] * edges[1] * edges[2];
    let big_r = if area > 0.0 {
        prod / (4.0 * area)
    } else {
        f64::INFINITY
    };
    let lmax = edges[0].max(edges[1]).max(edges[2]);
    TriangleQuality {
        min_angle: angles[0].min(angles[1]).min(angles[2]),
        max_angle: angles[0].max(angles[1]).max(angles[2]),
        angles,
        radius_ratio: if big_r.is_finite() {
            2.0 * r / big_r
        } else {
            0.0
        },
        aspect_ratio: if r > 0.0 {
            lmax / (2.0 * 3f64.sqrt() * r)
        } else {
            f64::INFINITY
        },
        area,
        edges,
    }
}

/// Minimum, maximum and mean of a measure.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stats {
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Mean value.
    pub mean: f64,
}

/// Running minimum, maximum and sum.
#[derive(Clone, Copy)]
struct Acc {
    min: f64,
    max: f64,
    sum: f64,
    n: usize,
}

impl Default for Acc {
    fn default() -> Self {
        Acc {
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            sum: 0.0,
            n: 0,
        }
    }
}

impl Acc {
    fn add(&mut self, v: f64) {
        self.min = self.min.min(v);
        self.max = self.max.max(v);
        self.sum += v;
        self.n += 1;
    }
    fn stats(&self) -> Stats {
        if self.n == 0 {
            return Stats::default();
        }
        Stats {
            min: self.min,
            max: self.max,
            mean: self.sum / self.n as f64,
        }
    }
}

/// Quality summary of a mesh, planar or lifted to a surface.
///
/// ```
/// use terramesh_core::geometry::Region;
/// use terramesh_mesh::{MeshBuilder, Quality};
/// let r = Region::from_ring(vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
/// let (mesh, _) = MeshBuilder::new().max_area(2.0).build(&r)?;
/// let q = Quality::planar(&mesh);
/// assert!(q.min_angle >= 30.0 && q.area.max <= 2.0);
/// assert_eq!(q.angle_histogram.iter().sum::<usize>(), 3 * q.triangles);
/// let z: Vec<f64> = mesh.points.iter().map(|p| 0.1 * p[0]).collect();
/// let s = Quality::surface(&mesh, &z);
/// assert!(s.area.mean > q.area.mean); // a tilted plane has more area
/// println!("{q}");
/// # Ok::<(), terramesh_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Quality {
    /// `"2D"` or `"3D"`.
    pub dimension: &'static str,
    /// Number of triangles.
    pub triangles: usize,
    /// Number of vertices.
    pub vertices: usize,
    /// Smallest angle, degrees.
    pub min_angle: f64,
    /// Largest angle, degrees.
    pub max_angle: f64,
    /// Radius ratio `2r/R` statistics.
    pub radius_ratio: Stats,
    /// Aspect ratio statistics.
    pub aspect_ratio: Stats,
    /// Triangle area statistics.
    pub area: Stats,
    /// Edge length statistics (each triangle's three edges).
    pub edge: Stats,
    /// Count of angles in 10-degree bins: `[0, 10)`, `[10, 20)`, ..., `[170, 180]`.
    pub angle_histogram: [usize; 18],
}

impl Quality {
    /// Quality of the planar mesh.
    pub fn planar(mesh: &Mesh) -> Quality {
        Self::compute(mesh, None)
    }

    /// Quality of the mesh lifted to heights `z` (one per vertex).
    ///
    /// # Panics
    /// If `z.len() != mesh.points.len()`.
    pub fn surface(mesh: &Mesh, z: &[f64]) -> Quality {
        Self::try_surface(mesh, z).expect("one height per vertex")
    }

    /// Quality of the mesh lifted to heights `z`; `None` unless there is one height per
    /// vertex.
    ///
    /// ```
    /// # use terramesh_mesh::{Mesh, Quality};
    /// let m = Mesh {
    ///     origin: [0.0, 0.0],
    ///     points: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
    ///     triangles: vec![[0, 1, 2]],
    ///     constraint_edges: vec![],
    /// };
    /// assert!(Quality::try_surface(&m, &[0.0, 0.0]).is_none());
    /// assert_eq!(Quality::try_surface(&m, &[0.0, 0.0, 1.0]).unwrap().dimension, "3D");
    /// ```
    pub fn try_surface(mesh: &Mesh, z: &[f64]) -> Option<Quality> {
        (z.len() == mesh.points.len()).then(|| Self::compute(mesh, Some(z)))
    }

    fn compute(mesh: &Mesh, z: Option<&[f64]>) -> Quality {
        // In blocks: each block's triangles measured in parallel, then added up in triangle
        // order (the same sums on any number of threads); no per-triangle storage beyond a
        // block (a million-triangle mesh stays cheap).
        let mut acc = [
            Acc::default(),
            Acc::default(),
            Acc::default(),
            Acc::default(),
        ];
        let (mut min_angle, mut max_angle) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut hist = [0usize; 18];
        let measure = |t: &[u32; 3]| {
            triangle_quality(t.map(|i| {
                let p = mesh.points[i as usize];
                [p[0], p[1], z.map_or(0.0, |z| z[i as usize])]
            }))
        };
        let mut block = Vec::new();
        for chunk in mesh.triangles.chunks(QUALITY_BLOCK) {
            chunk
                .par_iter()
                .with_min_len(QUALITY_BLOCK / 16)
                .map(measure)
                .collect_into_vec(&mut block);
            for q in &block {
                for a in q.angles {
                    hist[((a / 10.0) as usize).min(17)] += 1;
                }
                min_angle = min_angle.min(q.min_angle);
                max_angle = max_angle.max(q.max_angle);
                acc[0].add(q.radius_ratio);
                acc[1].add(q.aspect_ratio);
                acc[2].add(q.area);
                for e in q.edges {
                    acc[3].add(e);
                }
            }
        }
        let empty = mesh.triangles.is_empty();
        Quality {
            dimension: if z.is_some() { "3D" } else { "2D" },
            triangles: mesh.triangles.len(),
            vertices: mesh.points.len(),
            min_angle: if empty { 0.0 } else { min_angle },
            max_angle: if empty { 0.0 } else { max_angle },
            radius_ratio: acc[0].stats(),
            aspect_ratio: acc[1].stats(),
            area: acc[2].stats(),
            edge: acc[3].stats(),
            angle_histogram: hist,
        }
    }

    /// A table with one column per quality (e.g. before and after smoothing).
    ///
    /// ```
    /// # use terramesh_core::geometry::Region;
    /// # use terramesh_mesh::{MeshBuilder, Quality};
    /// # let r = Region::from_ring(vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
    /// # let (mesh, _) = MeshBuilder::new().max_area(2.0).build(&r)?;
    /// let q = Quality::planar(&mesh);
    /// let t = Quality::table(&[("before", &q), ("after", &q)]);
    /// assert!(t.contains("min angle") && t.contains("before"));
    /// # Ok::<(), terramesh_mesh::MeshError>(())
    /// ```
    pub fn table(columns: &[(&str, &Quality)]) -> String {
        let mut rows: Vec<(String, Vec<String>)> = Vec::new();
        let mut row = |name: &str, f: &dyn Fn(&Quality) -> String| {
            rows.push((
                name.to_string(),
                columns.iter().map(|(_, q)| f(q)).collect(),
            ));
        };
        row("triangles", &|q| q.triangles.to_string());
        row("vertices", &|q| q.vertices.to_string());
        row("min angle (deg)", &|q| format!("{:.2}", q.min_angle));
        row("max angle (deg)", &|q| format!("{:.2}", q.max_angle));
        let st = |s: &Stats, p: usize| format!("{:.p$} / {:.p$} / {:.p$}", s.min, s.mean, s.max);
        row("radius ratio min/mean/max", &|q| st(&q.radius_ratio, 3));
        row("aspect ratio min/mean/max", &|q| st(&q.aspect_ratio, 3));
        row("area min/mean/max", &|q| st(&q.area, 3));
        row("edge min/mean/max", &|q| st(&q.edge, 3));
        for b in 0..18 {
            row(&format!("angles {:>3}-{:<3}", b * 10, b * 10 + 10), &|q| {
                q.angle_histogram[b].to_string()
            });
        }
        let w0 = rows.iter().map(|r| r.0.len()).max().unwrap_or(0);
        let widths: Vec<usize> = (0..columns.len())
            .map(|c| {
                rows.iter()
                    .map(|r| r.1[c].len())
                    .chain([columns[c].0.len() + 5])
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let mut out = format!("{:w0$}", "");
        for (c, (name, q)) in columns.iter().enumerate() {
            out += &format!(
                "  {:>w$}",
                format!("{name} ({})", q.dimension),
                w = widths[c]
            );
        }
        out.push('\n');
        for (name, vals) in rows {
            out += &format!("{name:w0$}");
            for (c, v) in vals.iter().enumerate() {
                out += &format!("  {v:>w$}", w = widths[c]);
            }
            out.push('\n');
        }
        out
    }
}

impl fmt::Display for Quality {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&Quality::table(&[("mesh", self)]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn right_isoceles_measures() {
        let q = triangle_quality([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
        assert!((q.min_angle - 45.0).abs() < 1e-12);
        // r = 2A / P = 4 / (4 + 2 sqrt 2), R = hypotenuse / 2 = sqrt 2.
        let r = 4.0 / (4.0 + 2.0 * 2f64.sqrt());
        assert!((q.radius_ratio - 2.0 * r / 2f64.sqrt()).abs() < 1e-12);
        assert!((q.aspect_ratio - 8f64.sqrt() / (2.0 * 3f64.sqrt() * r)).abs() < 1e-12);
    }

    #[test]
    fn lifted_triangle_angles_change() {
        let flat = triangle_quality([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let lifted = triangle_quality([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 5.0]]);
        assert!(lifted.min_angle < flat.min_angle);
        assert!((lifted.angles.iter().sum::<f64>() - 180.0).abs() < 1e-9);
        let degenerate = triangle_quality([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]);
        assert_eq!(degenerate.radius_ratio, 0.0);
        assert!(degenerate.aspect_ratio.is_infinite());
    }
}
