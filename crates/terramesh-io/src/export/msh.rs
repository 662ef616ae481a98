//! Gmsh MSH 4.1 (`.msh`), ASCII: one surface entity holding every node and triangle.

use std::io::{self, Write};

use super::{MeshView, MeshWriter};
use crate::blocks::{write_in_blocks, BLOCK};
use crate::exactnum::{push_debug, push_u64};

/// The Gmsh MSH 4.1 writer.
pub struct Msh41;

impl MeshWriter for Msh41 {
    fn name(&self) -> &'static str {
        "Gmsh MSH 4.1"
    }
    fn extensions(&self) -> &'static [&'static str] {
        &["msh"]
    }
    fn write(&self, m: &MeshView, out: &mut dyn Write) -> io::Result<()> {
        let (np, nt) = (m.points.len(), m.triangles.len());
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for i in 0..np {
            let p = m.point(i);
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if np == 0 {
            (lo, hi) = ([0.0; 3], [0.0; 3]);
        }
        writeln!(out, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
        writeln!(out, "$Entities\n0 0 1 0")?;
        writeln!(
            out,
            "1 {:?} {:?} {:?} {:?} {:?} {:?} 0 0",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        )?;
        writeln!(out, "$EndEntities")?;
        writeln!(out, "$Nodes\n1 {np} 1 {np}\n2 1 0 {np}")?;
        write_in_blocks(out, np, BLOCK, |r, out| {
            for i in r {
                push_u64(out, i as u64 + 1);
                out.push(b'\n');
            }
            Ok(())
        })?;
        write_in_blocks(out, np, BLOCK, |r, out| {
            for i in r {
                let p = m.point(i);
                push_debug(out, p[0]);
                out.push(b' ');
                push_debug(out, p[1]);
                out.push(b' ');
                push_debug(out, p[2]);
                out.push(b'\n');
            }
            Ok(())
        })?;
        writeln!(out, "$EndNodes")?;
        writeln!(out, "$Elements\n1 {nt} 1 {nt}\n2 1 2 {nt}")?;
        write_in_blocks(out, nt, BLOCK, |r, out| {
            for k in r {
                let t = m.triangles[k];
                push_u64(out, k as u64 + 1);
                for c in t {
                    out.push(b' ');
                    push_u64(out, u64::from(c) + 1);
                }
                out.push(b'\n');
            }
            Ok(())
        })?;
        writeln!(out, "$EndElements")
    }
}
