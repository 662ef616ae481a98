#!/usr/bin/env python3
"""Writes the engineering objects of examples/structures/ (issue 32) over the faulted example's
synthetic site (examples/faulted/): a tunnel axis through fault F1 (tunnel.csv), a pit outline
(pit.wkt) and a dam's foundation block as a closed ASCII STL (dam.stl). Deterministic: run it
again and the files are identical.

    python3 examples/structures/make_objects.py
"""
from pathlib import Path

HERE = Path(__file__).resolve().parent


def box_stl(name, lo, hi):
    """A closed box, outward oriented, as ASCII STL."""
    def v(k):
        return [hi[i] if k >> i & 1 else lo[i] for i in range(3)]

    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    out = [f"solid {name}"]
    for q in quads:
        for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3])):
            out.append("facet normal 0 0 0\nouter loop")
            for k in t:
                out.append("vertex {} {} {}".format(*v(k)))
            out.append("endloop\nendfacet")
    out.append(f"endsolid {name}")
    return "\n".join(out) + "\n"


def main():
    # A 140 m tunnel at 80 m elevation, west to east at y = 300: it crosses F1 (trace from
    # (150, -50) to (190, 450), dipping 60 degrees east) near x = 218.
    (HERE / "tunnel.csv").write_text("x,y,z\n120,300,80\n260,300,80\n")
    # A 60 x 50 m pit, floor at 135 m (about 15 m deep), south of F3.
    (HERE / "pit.wkt").write_text("POLYGON ((60 40, 120 40, 120 90, 60 90, 60 40))\n")
    # A dam's block, 50 x 40 m, from 140 m (below the terrain, about 155 m there) to 170 m:
    # the part below the terrain replaces the rock; the part above is added on the terrain.
    (HERE / "dam.stl").write_text(box_stl("dam", [280.0, 60.0, 140.0], [330.0, 100.0, 170.0]))


if __name__ == "__main__":
    main()
