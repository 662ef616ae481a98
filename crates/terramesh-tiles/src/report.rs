//! The merge's `report.html`: a map of the tiles (coloured by build time) and a table of each
//! tile's samples, mesh, grid nodes, timings and memory.

use std::fmt::Write;

use super::manifest::Manifest;
use super::merged::Merged;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Why the merge makes no `model.glb` (the report and `docs/scaling.md` say so).
pub(crate) const NO_GLB: &str = "model.glb is not merged: a GLB file is at most 4 GiB (its \
    chunk lengths are 32-bit) and a browser viewer loads it whole into memory, which a \
    region too large for one process exceeds; view the merged model.vtu (ParaView) or the \
    units' unit-*.stl and .ts instead, or build a part of the region in one piece for a \
    model.glb.";

/// The page, self-contained.
pub(crate) fn html(m: &Manifest, merged: &Merged) -> String {
    let total = |t: &super::manifest::Tile| {
        t.built.as_ref().and_then(|b| {
            b.seconds
                .iter()
                .find(|(k, _)| k == "total")
                .map(|(_, s)| *s)
        })
    };
    let slowest = m.tiles.iter().filter_map(total).fold(0.0, f64::max);
    let [sx, sy] = m.shape;
    let cell = 60.0;
    let (w, h) = (sx as f64 * cell, sy as f64 * cell);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">"
    );
    for t in &m.tiles {
        let [i, j] = t.index;
        let (x, y) = (i as f64 * cell, (sy - 1 - j) as f64 * cell);
        let s = total(t).unwrap_or(0.0);
        let f = if slowest > 0.0 { s / slowest } else { 0.0 };
        let shade = (230.0 - 150.0 * f) as u8;
        let _ = write!(
            svg,
            "<rect x=\"{x}\" y=\"{y}\" width=\"{cell}\" height=\"{cell}\" fill=\"rgb(255,{shade},{shade})\" stroke=\"#333\"><title>{id}: {s:.2} s</title></rect>\
             <text x=\"{tx}\" y=\"{ty}\" font-size=\"11\" text-anchor=\"middle\">{id}</text>\
             <text x=\"{tx}\" y=\"{ty2}\" font-size=\"10\" text-anchor=\"middle\">{s:.1} s</text>",
            id = esc(&t.id),
            tx = x + cell / 2.0,
            ty = y + cell / 2.0 - 4.0,
            ty2 = y + cell / 2.0 + 10.0,
        );
    }
    svg.push_str("</svg>");
    let mut rows = String::new();
    for t in &m.tiles {
        let Some(b) = &t.built else { continue };
        let secs: Vec<String> = b
            .seconds
            .iter()
            .map(|(k, s)| format!("{k} {s:.2}"))
            .collect();
        let _ = write!(
            rows,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.0}</td><td>{}</td><td>{:.0}</td></tr>",
            esc(&t.id),
            b.samples,
            b.vertices,
            b.triangles,
            b.grid_nodes,
            t.halo,
            esc(&secs.join(", ")),
            b.peak_rss as f64 / 1e6
        );
    }
    let model = match &merged.model {
        Some(g) => format!(
            "<p>Geological model: {} nodes, {} cells, {} boreholes' contacts in model.json. \
             {NO_GLB}</p>",
            g.nodes,
            g.cells,
            g.boreholes.len()
        ),
        None => String::new(),
    };
    let mut model = model;
    for s in &merged.not_merged {
        let _ = write!(
            model,
            "<p>Not merged: {} ({}).</p>",
            esc(&s.format),
            esc(&s.why)
        );
    }
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>Tiled DSM</title>\
         <style>body{{font-family:sans-serif;margin:2em}}td,th{{padding:2px 8px;border-bottom:1px solid #ddd}}</style></head><body>\
         <h1>Tiled DSM: {nt} tiles of {size} m</h1>\
         <p>{v} vertices, {tr} triangles, {sv} seam vertices (each once; largest difference between \
         two tiles' elevations at one: {d} m), planar area {a:.3} m²; merged in {ms:.2} s.</p>{model}\
         <h2>Tile map (north up; darker took longer)</h2>{svg}\
         <h2>Tiles</h2><table><tr><th>tile</th><th>samples</th><th>vertices</th><th>triangles</th>\
         <th>grid nodes</th><th>halo m</th><th>seconds</th><th>peak MB</th></tr>{rows}</table>\
         </body></html>\n",
        nt = m.tiles.len(),
        size = m.tile_size,
        v = merged.vertices,
        tr = merged.triangles,
        sv = merged.seam_vertices,
        d = merged.seam_max_difference,
        a = merged.area,
        ms = merged.seconds,
    )
}
