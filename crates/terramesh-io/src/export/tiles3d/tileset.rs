//! The `tileset.json` document.

use serde_json::{json, Map, Value};

use super::bounds::Aabb;
use super::{content_uri, has_content, Tile, TilesetOptions};

/// The tileset: asset 1.1, the tileset's geometric error, and the root with its transform;
/// `boxes` as from `tree_boxes` (pre-order). Subtrees without content are left out.
pub(crate) fn tileset_json(root: &Tile, boxes: &[Option<Aabb>], opts: &TilesetOptions) -> Value {
    let mut next = 0;
    let mut r = tile_json(root, boxes, &mut next).unwrap_or(Value::Null);
    r["transform"] = json!(opts.transform);
    json!({
        "asset": {
            "version": "1.1",
            "generator": concat!("terramesh ", env!("CARGO_PKG_VERSION")),
        },
        "extras": opts.extras,
        "geometricError": opts.geometric_error,
        "root": r,
    })
}

fn tile_json(t: &Tile, boxes: &[Option<Aabb>], next: &mut usize) -> Option<Value> {
    let b = boxes[*next];
    *next += 1;
    let children: Vec<Value> = t
        .children
        .iter()
        .filter_map(|c| tile_json(c, boxes, next))
        .collect();
    let b = b?;
    let mut m = Map::new();
    m.insert("boundingVolume".into(), json!({ "box": b.to_box() }));
    m.insert("geometricError".into(), json!(t.geometric_error));
    m.insert("refine".into(), json!("REPLACE"));
    if has_content(t) {
        m.insert("content".into(), json!({ "uri": content_uri(t.address) }));
    }
    if !children.is_empty() {
        m.insert("children".into(), Value::Array(children));
    }
    Some(Value::Object(m))
}
