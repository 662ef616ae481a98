//! The quality pass's operations for a gently dipping fault's trace (the kernel's module
//! `improve::trace`: a trace node moved along the trace, a new node on a fault in a cavity of
//! the cells on its two sides), on the site of `dihedral_pinned` (`sites.rs`) whose fault
//! dips 20 degrees: without them 6 cells of its hanging wall's wedge under the terrain stay
//! below 5 degrees (the smallest 2.29), with them none. A binary of its own: the switch is
//! global.

use terramesh_faults::*;

#[test]
fn trace_operations_mend_the_wedge_of_a_20_degree_dip() {
    let site = Site::new(
        200.0,
        10,
        0.2,
        3,
        [120.0, 0.03, 0.01],
        0.0,
        vec![90.0, 50.0],
        [0.02, -0.01],
        vec![SynthFault::new(
            "L",
            [95.0, -20.0],
            [105.0, 220.0],
            20.0,
            90.0,
            7.0,
        )],
    )
    .unwrap();
    let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
    let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
    let settings = MeshSettings::new(site.base, 8.0);
    // Every operation checked as it is made (volume, conformity, sides, units).
    verify_each_operation(true);
    let mut seen = Vec::new();
    for on in [false, true] {
        trace_operations(on);
        let mesh = faulted_mesh(&site.terrain, &set, site.tops.len(), &h, &settings).unwrap();
        let s = check(&mesh, &site.terrain, &set, &settings, &h).unwrap();
        println!(
            "trace operations {on}: {} cells, {} nodes, below 5 degrees {}, smallest {:.3}",
            mesh.tets.len(),
            mesh.points.len(),
            s.quality.below_5,
            s.quality.min
        );
        seen.push((s.quality.below_5, s.quality.min));
    }
    trace_operations(true);
    assert!(seen[0].0 >= 1 && seen[0].1 < 5.0, "{seen:?}");
    assert_eq!(seen[1].0, 0, "{seen:?}");
    assert!(seen[1].1 >= 5.0, "{seen:?}");
}
