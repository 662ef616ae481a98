//! Check 4 of [`crate::check`]: the tagged faces against the boundary and interface faces
//! found from the cells.

use terramesh_core::volume::{FaceTag, VolumeMesh};

use crate::buckets::sort_by_node;
use crate::check::fail;
use crate::check_faces::{canonical, triangles, used};
use crate::GeologyError;

/// Check 4: the tagged faces against the boundary and interface faces found from the cells.
pub(crate) fn check_tags(
    mesh: &VolumeMesh,
    boundary: &[([u32; 4], bool, u32)],
    interfaces: &[([u32; 4], bool, u32)],
) -> Result<(), GeologyError> {
    let mut outer = Vec::with_capacity(boundary.len());
    let mut inner = Vec::with_capacity(interfaces.len());
    for (i, f) in mesh.faces.iter().enumerate() {
        let Some(tag) = mesh.tags.get(f.tag as usize) else {
            return Err(fail(
                mesh,
                0,
                format!("tagged face {i} has tag {} of {}", f.tag, mesh.tags.len()),
            ));
        };
        let nodes = used(&f.nodes);
        if nodes.iter().any(|&v| v as usize >= mesh.points.len())
            || f.cell as usize >= mesh.cells.len()
        {
            return Err(fail(
                mesh,
                0,
                format!("tagged face {i} names a missing node or cell"),
            ));
        }
        let (key, o) = canonical(f.nodes);
        // Its direction: the z of its normal, against its extent.
        let r = mesh.points[nodes[0] as usize];
        let nz: f64 = triangles(&f.nodes)
            .map(|t| {
                let [a, b, c] = t.map(|k| mesh.points[k as usize]);
                (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
            })
            .sum();
        let ok = match tag {
            FaceTag::Top => nz > 0.0,
            FaceTag::Bottom => nz < 0.0,
            FaceTag::Side(_) => {
                let scale = nodes
                    .iter()
                    .map(|&k| {
                        let p = mesh.points[k as usize];
                        (p[0] - r[0]).abs().max((p[1] - r[1]).abs())
                    })
                    .fold(0.0, f64::max);
                nz.abs() <= 1e-9 * scale * scale
            }
            FaceTag::Interface(u) => {
                let m = mesh.material[f.cell as usize];
                mesh.units.get(m as usize) == Some(u) && m > 0
            }
        };
        if !ok {
            return Err(fail(
                mesh,
                nodes[0],
                format!(
                    "tagged face {i} ({}) points the wrong way or names the wrong unit",
                    tag.name()
                ),
            ));
        }
        match tag {
            FaceTag::Interface(_) => inner.push((key, o, f.cell)),
            _ => outer.push((key, o, f.cell)),
        }
    }
    for (what, tagged, found) in [
        ("boundary", outer, boundary),
        ("interface", inner, interfaces),
    ] {
        let tagged = sort_by_node(&tagged, mesh.points.len(), |f| f.0[0]);
        // `found` is in key order already (taken from the sorted faces), keys unique.
        if tagged.as_slice() != found {
            let diff = tagged
                .iter()
                .zip(found.iter())
                .find(|(a, b)| a != b)
                .map(|(a, _)| a.0[0])
                .unwrap_or(0);
            return Err(fail(
                mesh,
                diff,
                format!(
                    "{} {what} faces are tagged but the cells have {} (or one differs in nodes, \
                     orientation or cell)",
                    tagged.len(),
                    found.len()
                ),
            ));
        }
    }
    Ok(())
}
