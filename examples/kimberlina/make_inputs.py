#!/usr/bin/env python3
"""Converts the Kimberlina well tops into terramesh's borehole contract files (stdlib only).

Run from the repository root, with the shared data beside it:
    python3 examples/kimberlina/make_inputs.py

Reads ../shared/data/geology/kimberlina/collars.csv and tops_long.csv (derived from
`doggr_jlw_vedder_final.utm.dat` of softwareunderground/subsurface, Apache-2.0, (c) 2020 The
subsurface Developers; DOGGR/CalGEM public well records with picks from the LLNL Kimberlina
model; UTM zone 11N, NAD27 (EPSG:26711), metres; see that folder's README) and writes here:
* collars.csv: hole,x,y,z,wellname (hole = wellid, unique; z = the land-surface "topo"
  elevation; wellname is not unique and only informative);
* tops.csv: hole,unit,elevation: the top of every unit met, in the column order, the tops
  flagged below_z_field6 (below the total depth: not drilled picks) dropped as censored;
* facts.json: what terramesh's reader must report on these two files, computed here in plain
  Python by the rules of docs/geology.md ("Inputs"): holes, units, contacts, zero-thickness
  (hole, unit) pairs, repaired inversions (a top higher than the lowest top above it, lowered
  onto it) and the largest one; plus the README's count of inversions between consecutive
  tops, for comparison.
"""
import csv
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.join(HERE, "..", "..", "..", "shared", "data", "geology", "kimberlina")
MAX_INVERSION = 10.0  # terramesh_io::boreholes::DEFAULT_MAX_INVERSION


def main():
    with open(os.path.join(SRC, "collars.csv"), newline="") as f:
        collars = list(csv.DictReader(f))
    with open(os.path.join(SRC, "tops_long.csv"), newline="") as f:
        tops = list(csv.DictReader(f))
    units = [None] * 15
    for r in tops:
        units[int(r["unit_order"]) - 1] = r["formation"]
    assert all(units), units
    collar_z = {c["wellid"]: float(c["collar_z"]) for c in collars}
    kept = {}
    dropped = 0
    for r in tops:
        if r["below_z_field6"] == "True":
            dropped += 1
            continue
        z = float(r["top_elev"])
        assert z <= collar_z[r["wellid"]], r
        kept.setdefault(r["wellid"], []).append((int(r["unit_order"]) - 1, r["top_elev"]))

    with open(os.path.join(HERE, "collars.csv"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["hole", "x", "y", "z", "wellname"])
        for c in collars:
            w.writerow([c["wellid"], c["x"], c["y"], c["collar_z"], c["wellname"]])
    with open(os.path.join(HERE, "tops.csv"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["hole", "unit", "elevation"])
        for c in collars:
            for u, z in sorted(kept.get(c["wellid"], [])):
                w.writerow([c["wellid"], units[u], z])

    # The reader's rules, in plain Python.
    contacts = zero = repairs = pairwise = 0
    largest = 0.0
    for c in collars:
        present = sorted((u, float(z)) for u, z in kept.get(c["wellid"], []))
        top = {}
        lowest = None
        for k, (u, z) in enumerate(present):
            if k and z > present[k - 1][1]:
                pairwise += 1
            if lowest is not None and z > lowest:
                assert z - lowest <= MAX_INVERSION
                repairs += 1
                largest = max(largest, z - lowest)
                z = lowest
            else:
                lowest = z
            top[u] = z
        for u in range(15):
            if u not in top:
                below = [p for p in present if p[0] > u]
                if below:
                    top[u] = top[below[0][0]]
        contacts += len(top)
        zero += sum(1 for u in range(14) if u in top and u + 1 in top and top[u] - top[u + 1] == 0.0)
    facts = {
        "holes": len(collars),
        "units": units,
        "dropped_below_total_depth": dropped,
        "contacts": contacts,
        "zero_thickness": zero,
        "repairs": repairs,
        "largest_repair_m": largest,
        "inversions_between_consecutive_tops": pairwise,
    }
    with open(os.path.join(HERE, "facts.json"), "w") as f:
        json.dump(facts, f, indent=2)
        f.write("\n")
    print(json.dumps(facts))


if __name__ == "__main__":
    main()
