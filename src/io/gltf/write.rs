//! Writing one mesh with its normals as a glTF 2.0 asset: binary (`.glb`) or JSON with the
//! buffer embedded as a base64 data URI (`.gltf`).

use base64::engine::general_purpose::STANDARD as BASE64_STANDARD;
use base64::Engine;
use glam::DVec3;
use serde_json::json;

use crate::mesh::TriMesh;

/// The translation of the node that places the mesh: the centre of its bounding box rounded to
/// the nearest `f32` (so that readers which hold node transforms in `f32`, as the `gltf` crate
/// does, read it exactly). Positions are stored in `f32` relative to it, so their precision
/// depends on the mesh's size, not on how far from the origin it lies (UTM coordinates, 5e6).
fn origin(mesh: &TriMesh) -> DVec3 {
    let (lo, hi) = mesh.positions.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let centre = (0.5 * lo + 0.5 * hi).as_vec3().as_dvec3();
    if centre.is_finite() {
        centre
    } else {
        DVec3::ZERO
    }
}

/// A position as stored: `f32` relative to the node's translation `centre`.
fn relative(p: DVec3, centre: DVec3) -> glam::Vec3 {
    (p - centre).as_vec3()
}

/// `mesh` with its positions as a glTF reader reads them back from [`encode_glb`] or
/// [`encode_gltf`]: the stored `f32` offsets plus the node's translation, in `f64`.
pub(crate) fn as_written(mesh: &TriMesh) -> TriMesh {
    let centre = origin(mesh);
    let mut out = mesh.clone();
    for p in &mut out.positions {
        *p = relative(*p, centre).as_dvec3() + centre;
    }
    out
}

/// The glTF JSON (without the buffer's `uri`) and binary buffer of `mesh` with `normals`.
fn build(
    mesh: &TriMesh,
    normals: &[DVec3],
) -> std::result::Result<(serde_json::Value, Vec<u8>), String> {
    if mesh.positions.is_empty() || mesh.triangles.is_empty() {
        return Err(format!(
            "glTF cannot hold an empty mesh ({} vertices, {} triangles)",
            mesh.positions.len(),
            mesh.triangles.len()
        ));
    }
    let v = mesh.positions.len();
    let f = mesh.triangles.len();
    let pos_bytes = v * 12;
    let idx_bytes = f * 12;
    let total = 2 * pos_bytes + idx_bytes;
    if u32::try_from(total + 4096).is_err() {
        return Err(format!(
            "{total} bytes of vertex and index data is too much for glTF"
        ));
    }
    let mut bin = Vec::with_capacity(total);
    let centre = origin(mesh);
    let mut min = glam::Vec3::splat(f32::INFINITY);
    let mut max = glam::Vec3::splat(f32::NEG_INFINITY);
    for p in &mesh.positions {
        let p = relative(*p, centre);
        if !p.is_finite() {
            return Err(format!("position {p} does not fit in f32"));
        }
        min = min.min(p);
        max = max.max(p);
        for c in p.to_array() {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for n in normals {
        let n = n.as_vec3().normalize_or(glam::Vec3::Z);
        for c in n.to_array() {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        for i in t {
            bin.extend_from_slice(&i.to_le_bytes());
        }
    }
    // f32 bounds written as the f64 of the same value, so they match the data exactly.
    let bound = |b: glam::Vec3| b.to_array().map(f64::from).to_vec();
    let node = if centre == DVec3::ZERO {
        json!({ "mesh": 0 })
    } else {
        json!({ "mesh": 0, "translation": centre.to_array() })
    };
    let json = json!({
        "asset": { "version": "2.0", "generator": "spectral-remesh" },
        "scene": 0,
        "scenes": [ { "nodes": [0] } ],
        "nodes": [ node ],
        "meshes": [ {
            "primitives": [ {
                "attributes": { "POSITION": 0, "NORMAL": 1 },
                "indices": 2,
                "mode": 4
            } ]
        } ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": v, "type": "VEC3",
              "min": bound(min), "max": bound(max) },
            { "bufferView": 1, "componentType": 5126, "count": v, "type": "VEC3" },
            { "bufferView": 2, "componentType": 5125, "count": 3 * f, "type": "SCALAR" }
        ],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": pos_bytes, "target": 34962 },
            { "buffer": 0, "byteOffset": pos_bytes, "byteLength": pos_bytes, "target": 34962 },
            { "buffer": 0, "byteOffset": 2 * pos_bytes, "byteLength": idx_bytes,
              "target": 34963 }
        ],
        "buffers": [ { "byteLength": total } ]
    });
    Ok((json, bin))
}

/// The `.glb` bytes of `mesh`: header, JSON chunk padded with spaces, BIN chunk padded with
/// zeros.
pub(crate) fn encode_glb(
    mesh: &TriMesh,
    normals: &[DVec3],
) -> std::result::Result<Vec<u8>, String> {
    let (json, bin) = build(mesh, normals)?;
    let mut json = serde_json::to_vec(&json).map_err(|e| e.to_string())?;
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut bin = bin;
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let total32 = u32::try_from(total).map_err(|_| format!("{total} bytes is too much for GLB"))?;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&total32.to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    Ok(out)
}

/// The `.gltf` (JSON) bytes of `mesh`, its buffer embedded as a base64 data URI.
pub(crate) fn encode_gltf(
    mesh: &TriMesh,
    normals: &[DVec3],
) -> std::result::Result<Vec<u8>, String> {
    let (mut json, bin) = build(mesh, normals)?;
    json["buffers"][0]["uri"] = serde_json::Value::String(format!(
        "data:application/octet-stream;base64,{}",
        BASE64_STANDARD.encode(&bin)
    ));
    let mut out = serde_json::to_vec_pretty(&json).map_err(|e| e.to_string())?;
    out.push(b'\n');
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_output_is_standard_padded_base64() {
        assert_eq!(BASE64_STANDARD.encode([0u8, 1, 2, 255]), "AAEC/w==");
        assert_eq!(BASE64_STANDARD.encode(b"ab"), "YWI=");
    }
}
