use terramesh_faults::*;
fn site(faults: Vec<SynthFault>, tops: Vec<f64>, jitter: f64) -> Site {
    Site::new(
        200.0,
        10,
        jitter,
        3,
        [120.0, 0.03, 0.01],
        0.0,
        tops,
        [0.02, -0.01],
        faults,
    )
    .unwrap()
}
fn main() {
    let which = std::env::args().nth(1).unwrap_or_default();
    let s = if which == "apart" {
        site(
            vec![
                SynthFault::new("A", [100.0, -20.0], [100.0, 220.0], 70.0, 90.0, 5.0),
                SynthFault::new("B", [101.0, -20.0], [101.0, 220.0], 70.0, 90.0, 8.0),
            ],
            vec![90.0, 50.0],
            0.2,
        )
    } else {
        site(
            vec![SynthFault::new(
                "F",
                [60.0, -20.0],
                [140.0, 220.0],
                55.0,
                100.0,
                3.0,
            )],
            vec![90.0, 89.5, 45.0],
            0.2,
        )
    };
    let set = FaultSet::new(&s.specs(), &s.terrain, s.base).unwrap();
    let h = |k: usize, key: BlockKey, p: [f64; 2]| s.height(k, key, p);
    let st = MeshSettings::new(s.base, 8.0);
    let m = faulted_mesh(&s.terrain, &set, s.tops.len(), &h, &st).unwrap();
    let mut on_fault = vec![false; m.points.len()];
    for f in &m.fault_faces {
        for &v in &f.nodes {
            on_fault[v as usize] = true;
        }
    }
    let mut bad: Vec<(f64, usize)> = (0..m.tets.len())
        .map(|c| (min_dihedral(m.tets[c].map(|v| m.points[v as usize])), c))
        .filter(|x| x.0 < 5.0)
        .collect();
    bad.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut terr, mut side, mut fault, mut base) = (0, 0, 0, 0);
    for &(a, c) in &bad {
        let t = m.tets[c];
        let ps = t.map(|v| m.points[v as usize]);
        let on_t = ps
            .iter()
            .any(|p| (s.terrain.height([p[0], p[1]]).unwrap() - p[2]).abs() < 1e-6);
        let on_s = ps.iter().any(|p| {
            p[0].abs() < 1e-6
                || p[1].abs() < 1e-6
                || (p[0] - 200.0).abs() < 1e-6
                || (p[1] - 200.0).abs() < 1e-6
        });
        let on_f = t.iter().any(|&v| on_fault[v as usize]);
        let on_b = ps.iter().any(|p| p[2].abs() < 1e-6);
        terr += on_t as usize;
        side += on_s as usize;
        fault += on_f as usize;
        base += on_b as usize;
        if a < 2.0 {
            let cen = [0, 1, 2].map(|k| ps.iter().map(|p| p[k]).sum::<f64>() / 4.0);
            println!("{a:.2} deg cell {c} unit {} at ({:.1},{:.1},{:.2}) terrain {on_t} side {on_s} fault {on_f} base {on_b}", m.unit[c], cen[0], cen[1], cen[2]);
        }
    }
    println!(
        "{} below 5: terrain {terr} side {side} fault {fault} base {base}; cells {}",
        bad.len(),
        m.tets.len()
    );
}
