//! Reading a glTF 2.0 scene's triangles, in world coordinates.

use std::io::Read;
use std::path::{Path, PathBuf};

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::buffer::Source;
use ::gltf::json::validation::{Error as ValidationError, Validate};
use ::gltf::mesh::Mode;
use base64::engine::general_purpose::{GeneralPurpose, GeneralPurposeConfig};
use base64::engine::DecodePaddingMode;
use base64::Engine;
use glam::{DMat3, DMat4, DVec3};
use percent_encoding::percent_decode_str;

use super::super::{one_line, read_file, ReadStats};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;

/// Largest number of node instances visited in a scene walk: a guard against node graphs that
/// are not trees (a node listed as the child of several parents can multiply instances
/// exponentially).
const MAX_NODE_VISITS: usize = 1 << 20;

/// Largest number of vertices of a scene, over all instances of its meshes: 2^26 (1.5 GiB of
/// positions), far beyond what the remesher takes as input.
const MAX_SCENE_VERTICES: usize = 1 << 26;

/// Largest number of triangles of a scene, over all instances of its meshes (2^27).
const MAX_SCENE_TRIANGLES: usize = 1 << 27;

/// Largest number of components (elements × components per element) of an accessor without a
/// buffer view (all zeros plus sparse substitutes), which costs memory without costing file
/// size.
const MAX_VIEWLESS_COMPONENTS: usize = 1 << 24;

/// Parses the glTF or GLB file at `path` into the triangles of its scene, in world
/// coordinates.
pub(crate) fn read(path: &Path, stats: &mut ReadStats) -> Result<TriMesh> {
    let data = read_file(path)?;
    let parse_err = |message: String| Error::parse(path, None, message);
    check_glb_header(&data).map_err(parse_err)?;
    let ::gltf::Gltf { document, blob } = ::gltf::Gltf::from_slice_without_validation(&data)
        .map_err(|e| {
            parse_err(format!(
                "not a valid glTF 2.0 file: {}",
                one_line(&e.to_string())
            ))
        })?;
    validate(&document).map_err(parse_err)?;
    // The node hierarchy must be a set of trees (glTF 2.0, 3.5.3): a node listed as a child more
    // than once, by several parents or twice by one, would be instanced once per path, which
    // multiplies exponentially along a chain.
    let mut parents = vec![0usize; document.nodes().len()];
    for node in document.nodes() {
        for child in node.children() {
            parents[child.index()] += 1;
        }
    }
    if let Some(i) = parents.iter().position(|&p| p > 1) {
        return Err(parse_err(format!(
            "node {i} is listed as a child {} times (the node hierarchy must be a tree)",
            parents[i]
        )));
    }
    let buffers = load_buffers(path, &document, blob)?;
    // The nodes' transforms in f64, from the JSON (a GLB's JSON chunk; the header was checked).
    let transforms = match ::gltf::binary::Glb::from_slice(&data) {
        Ok(glb) => node_transforms(&glb.json),
        Err(_) => node_transforms(&data),
    };

    let mut walk = Walk {
        path,
        buffers: &buffers,
        positions: Vec::new(),
        triangles: Vec::new(),
        stats,
    };
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next());
    match scene {
        Some(scene) => {
            let mut on_path = vec![false; document.as_json().nodes.len()];
            let mut visits = 0usize;
            // Depth-first with an explicit stack: deep hierarchies cannot overflow the call
            // stack, and `on_path` finds cycles.
            enum Step<'a> {
                Enter(::gltf::Node<'a>, DMat4),
                Leave(usize),
            }
            let mut stack: Vec<Step> = scene
                .nodes()
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .map(|n| Step::Enter(n, DMat4::IDENTITY))
                .collect();
            while let Some(step) = stack.pop() {
                match step {
                    Step::Leave(i) => on_path[i] = false,
                    Step::Enter(node, parent) => {
                        let i = node.index();
                        if on_path[i] {
                            return Err(parse_err(format!(
                                "node {i} is its own ancestor (the node hierarchy has a cycle)"
                            )));
                        }
                        visits += 1;
                        if visits > MAX_NODE_VISITS {
                            return Err(parse_err(format!(
                                "the node hierarchy places more than {MAX_NODE_VISITS} nodes \
                                 (nodes with several parents?)"
                            )));
                        }
                        on_path[i] = true;
                        let local = transforms.get(i).copied().flatten().unwrap_or_else(|| {
                            let m = node.transform().matrix().map(|c| c.map(f64::from));
                            DMat4::from_cols_array_2d(&m)
                        });
                        let world = parent * local;
                        if let Some(mesh) = node.mesh() {
                            walk.add_mesh(&mesh, &world)?;
                        }
                        stack.push(Step::Leave(i));
                        let children: Vec<_> = node.children().collect();
                        for child in children.into_iter().rev() {
                            stack.push(Step::Enter(child, world));
                        }
                    }
                }
            }
        }
        None => {
            for mesh in document.meshes() {
                walk.add_mesh(&mesh, &DMat4::IDENTITY)?;
            }
        }
    }
    Ok(TriMesh::new(walk.positions, walk.triangles))
}

/// Checks a GLB header's length field before `gltf` computes with it (it subtracts 12 from it
/// unchecked). Text glTF passes unchanged.
fn check_glb_header(data: &[u8]) -> std::result::Result<(), String> {
    if !data.starts_with(b"glTF") {
        return Ok(());
    }
    let word = |k: usize| {
        data.get(k..k + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err("truncated GLB header".to_string());
    };
    if version != 2 {
        return Err(format!("GLB version {version}, expected 2"));
    }
    if (length as usize) < 20 || length as usize > data.len() {
        return Err(format!(
            "GLB header gives a length of {length} bytes, but the file has {} bytes",
            data.len()
        ));
    }
    Ok(())
}

/// Required extensions that do not change how positions and indices are stored (or, for
/// `KHR_mesh_quantization`, only allow integer positions, which [`read_accessor`] decodes).
const HARMLESS_EXTENSIONS: [&str; 3] = ["KHR_mesh_quantization", "KHR_materials_", "KHR_texture_"];

/// The `gltf` crate's validation, except that a POSITION accessor without `min`/`max` (required
/// by the specification, but often missing in practice, and not needed here) is accepted, and so
/// are required extensions that do not affect geometry (materials, textures, lights,
/// quantization). Geometry compression (Draco, meshopt) is refused by name.
fn validate(document: &::gltf::Document) -> std::result::Result<(), String> {
    let root = document.as_json();
    for ext in &root.extensions_required {
        if let Some(message) = compression(ext) {
            return Err(message);
        }
        let harmless = HARMLESS_EXTENSIONS.iter().any(|h| ext.starts_with(h))
            || matches!(
                ext.as_str(),
                "KHR_lights_punctual" | "EXT_texture_webp" | "MSFT_texture_dds"
            );
        if !harmless {
            return Err(format!(
                "the file requires the glTF extension {}, which is not supported",
                one_line(ext)
            ));
        }
    }
    // gltf-json's own validation indexes the accessor of each primitive's POSITION without a
    // range check (it panics on an out-of-range index; found by the read_gltf fuzz target), so
    // the ranges of every primitive's accessors are checked first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let used = primitive
                .attributes
                .values()
                .chain(primitive.indices.as_ref())
                .map(|i| i.value());
            if let Some(i) = used.into_iter().find(|&i| i >= root.accessors.len()) {
                return Err(format!(
                    "invalid glTF: meshes[{m}].primitives[{p}] uses accessor {i}, but the file has {} accessors",
                    root.accessors.len()
                ));
            }
        }
    }
    // Compression that is used but not required leaves plain accessors as a fallback, which
    // are read; a primitive accessor without data (no buffer view, nothing sparse) in such a
    // file is one whose data only the compressed stream holds.
    if let Some(message) = root.extensions_used.iter().find_map(|e| compression(e)) {
        for mesh in &root.meshes {
            for primitive in &mesh.primitives {
                let used = primitive
                    .attributes
                    .values()
                    .chain(primitive.indices.as_ref())
                    .map(|i| &root.accessors[i.value()]);
                if used
                    .into_iter()
                    .any(|a| a.buffer_view.is_none() && a.sparse.is_none())
                {
                    return Err(message);
                }
            }
        }
    }
    let mut errors: Vec<(String, ValidationError)> = Vec::new();
    root.validate(root, ::gltf::json::Path::new, &mut |path, error| {
        errors.push((path().to_string(), error))
    });
    errors.retain(|(path, error)| match error {
        ValidationError::Missing => !(path.ends_with(".min") || path.ends_with(".max")),
        ValidationError::Unsupported => !path.starts_with("extensionsRequired"),
        _ => true,
    });
    match errors.first() {
        None => Ok(()),
        Some((path, error)) => Err(format!(
            "invalid glTF: {path} {}{}",
            match error {
                ValidationError::IndexOutOfBounds => "names an object the file does not have",
                ValidationError::Invalid => "has a value glTF 2.0 does not allow",
                ValidationError::Missing => "is missing",
                ValidationError::Oversize => "is too large",
                ValidationError::Unsupported => "names an extension this reader does not support",
            },
            if errors.len() > 1 {
                format!(" (and {} more problems)", errors.len() - 1)
            } else {
                String::new()
            }
        )),
    }
}

/// The message for a geometry compression extension (Draco, meshopt), `None` for other
/// extensions.
fn compression(extension: &str) -> Option<String> {
    let kind = match extension {
        "KHR_draco_mesh_compression" => "Draco",
        "EXT_meshopt_compression" | "KHR_meshopt_compression" => "meshopt",
        _ => return None,
    };
    Some(format!(
        "the file uses {kind} compression ({}), which this reader does not decode; export it \
         without compression",
        one_line(extension)
    ))
}

/// Loads every buffer: the GLB binary chunk, data URIs, or files relative to the glTF file.
fn load_buffers(
    path: &Path,
    document: &::gltf::Document,
    mut blob: Option<Vec<u8>>,
) -> Result<Vec<Vec<u8>>> {
    let base = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut out = Vec::new();
    for buffer in document.buffers() {
        let i = buffer.index();
        let (what, data) = match buffer.source() {
            Source::Bin => (
                "GLB binary chunk".to_string(),
                blob.take().ok_or_else(|| {
                    BufferError::Invalid("the file has no binary chunk".to_string())
                }),
            ),
            Source::Uri(uri) if uri.starts_with("data:") => {
                ("embedded data URI".to_string(), decode_data_uri(uri))
            }
            Source::Uri(uri) => (
                format!("'{}'", one_line(uri)),
                read_uri(&base, uri, buffer.length()),
            ),
        };
        let mut data = data.map_err(|e| match e {
            BufferError::Io(io) => Error::io(
                path,
                std::io::Error::new(io.kind(), format!("buffer {i} ({what}): {io}")),
            ),
            BufferError::Invalid(message) => Error::parse(
                path,
                None,
                format!("buffer {i} ({what}): {}", one_line(&message)),
            ),
        })?;
        // Padded to four bytes, as the GLB binary chunk is.
        while data.len() % 4 != 0 {
            data.push(0);
        }
        if data.len() < buffer.length() {
            return Err(Error::parse(
                path,
                None,
                format!(
                    "buffer {i} holds {} bytes, but the file declares {}",
                    data.len(),
                    buffer.length()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// Why a buffer could not be loaded: its file could not be read, or its URI or data is bad.
enum BufferError {
    Io(std::io::Error),
    Invalid(String),
}

/// The bytes of a `data:[<media type>][;base64],<data>` URI (RFC 2397): base64 (padding
/// optional) or percent-encoded.
fn decode_data_uri(uri: &str) -> std::result::Result<Vec<u8>, BufferError> {
    let rest = uri.strip_prefix("data:").unwrap_or(uri);
    let (media, data) = rest
        .split_once(',')
        .ok_or_else(|| BufferError::Invalid("a data URI without a comma".to_string()))?;
    if media.ends_with(";base64") {
        BASE64_LENIENT
            .decode(data)
            .map_err(|e| BufferError::Invalid(format!("bad base64: {e}")))
    } else {
        Ok(percent_decode_str(data).collect())
    }
}

/// Standard base64 that accepts data with or without its `=` padding, as writers differ.
const BASE64_LENIENT: GeneralPurpose = GeneralPurpose::new(
    &base64::alphabet::STANDARD,
    GeneralPurposeConfig::new().with_decode_padding_mode(DecodePaddingMode::Indifferent),
);

/// Reads the file a buffer URI names: a percent-encoded path relative to `base` (the glTF
/// file's folder) or a `file:` URI; at most `length` bytes (the buffer's `byteLength`), and
/// only from a regular file (a device such as `/dev/zero` never ends, a FIFO may never open).
/// Other schemes (`http:`, ...) are refused.
fn read_uri(base: &Path, uri: &str, length: usize) -> std::result::Result<Vec<u8>, BufferError> {
    let (relative, encoded) = match uri.strip_prefix("file:") {
        Some(rest) => (false, rest.strip_prefix("//").unwrap_or(rest)),
        None if uri.contains(':') => {
            return Err(BufferError::Invalid(
                "unsupported URI scheme (only data:, file: and relative paths)".to_string(),
            ))
        }
        None => (true, uri),
    };
    let decoded = percent_decode_str(encoded)
        .decode_utf8()
        .map_err(|_| BufferError::Invalid("URI is not UTF-8 once percent-decoded".to_string()))?;
    let file = if relative {
        base.join(&*decoded)
    } else {
        PathBuf::from(&*decoded)
    };
    // The kind of file before it is opened (opening a FIFO waits for a writer).
    if !std::fs::metadata(&file).map_err(BufferError::Io)?.is_file() {
        return Err(BufferError::Invalid(
            "not a regular file (a folder, device, FIFO or socket)".to_string(),
        ));
    }
    let mut data = Vec::new();
    std::fs::File::open(&file)
        .and_then(|f| f.take(length as u64).read_to_end(&mut data))
        .map_err(BufferError::Io)?;
    Ok(data)
}

/// The triangles gathered so far in a scene walk.
struct Walk<'a, 's> {
    path: &'a Path,
    buffers: &'a [Vec<u8>],
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    stats: &'s mut ReadStats,
}

impl Walk<'_, '_> {
    /// Adds the triangle primitives of `mesh`, placed by `world`.
    fn add_mesh(&mut self, mesh: &::gltf::Mesh, world: &DMat4) -> Result<()> {
        let flip = DMat3::from_mat4(*world).determinant() < 0.0;
        for primitive in mesh.primitives() {
            let mode = primitive.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                self.stats.skipped_primitives += 1;
                continue;
            }
            let what = format!("mesh {} primitive {}", mesh.index(), primitive.index());
            let err = |message: String| Error::parse(self.path, None, format!("{what}: {message}"));
            let accessor = primitive
                .get(&::gltf::Semantic::Positions)
                .ok_or_else(|| err("no POSITION attribute".to_string()))?;
            if accessor.dimensions() != Dimensions::Vec3 {
                return Err(err(format!(
                    "POSITION accessor {} is {:?}, expected VEC3",
                    accessor.index(),
                    accessor.dimensions()
                )));
            }
            let coords =
                read_accessor(&accessor, self.buffers, Integers::AsFlagged).map_err(err)?;
            let count = accessor.count();
            let indices: Vec<u32> = match primitive.indices() {
                Some(ia) => {
                    // glTF 2.0, 3.7.2.1: SCALAR of unsigned 8-, 16- or 32-bit integers. A
                    // `normalized` flag (meaningless for indices) is ignored: the integers are
                    // the indices.
                    let kind = match ia.data_type() {
                        DataType::U8 | DataType::U16 | DataType::U32 => None,
                        DataType::I8 => Some("signed 8-bit integers"),
                        DataType::I16 => Some("signed 16-bit integers"),
                        DataType::F32 => Some("floating-point numbers"),
                    };
                    if let Some(kind) = kind {
                        return Err(err(format!(
                            "index accessor {} holds {kind}; glTF indices are unsigned 8-, 16- \
                             or 32-bit integers",
                            ia.index()
                        )));
                    }
                    if ia.dimensions() != Dimensions::Scalar {
                        return Err(err(format!(
                            "index accessor {} has {} components per element; glTF indices \
                             are single numbers (SCALAR)",
                            ia.index(),
                            ia.dimensions().multiplicity()
                        )));
                    }
                    let values = read_accessor(&ia, self.buffers, Integers::Raw).map_err(err)?;
                    let mut out = Vec::with_capacity(values.len());
                    for v in values {
                        // Unsigned 32-bit values read as f64 are exact integers.
                        let v = v as u64;
                        if v >= count as u64 {
                            return Err(Error::invalid_mesh(
                                self.path,
                                format!("{what}: index {v} is out of range for {count} vertices"),
                            ));
                        }
                        out.push(v as u32);
                    }
                    out
                }
                None => {
                    let n = u32::try_from(count)
                        .map_err(|_| err(format!("{count} vertices do not fit 32-bit indices")))?;
                    (0..n).collect()
                }
            };
            let base = self.positions.len();
            let total = base + count;
            // Instancing multiplies geometry without growing the file: the scene's vertices and
            // triangles, over all instances, are bounded.
            if total > MAX_SCENE_VERTICES
                || self.triangles.len() + indices.len() / 3 > MAX_SCENE_TRIANGLES
            {
                return Err(err(format!(
                    "the scene's instances add up to more than {MAX_SCENE_VERTICES} vertices or \
                     {MAX_SCENE_TRIANGLES} triangles"
                )));
            }
            if u32::try_from(total).is_err() {
                return Err(err(format!(
                    "the scene has more than {} vertices",
                    u32::MAX
                )));
            }
            self.positions.extend(
                coords
                    .chunks_exact(3)
                    .map(|c| world.transform_point3(DVec3::new(c[0], c[1], c[2]))),
            );
            self.stats.vertices_read += count;

            let base = base as u32;
            let before = self.triangles.len();
            let mut push = |a: u32, b: u32, c: u32| {
                let (b, c) = if flip { (c, b) } else { (b, c) };
                self.triangles.push([base + a, base + b, base + c]);
            };
            match mode {
                Mode::Triangles => {
                    for t in indices.chunks_exact(3) {
                        push(t[0], t[1], t[2]);
                    }
                }
                Mode::TriangleStrip => {
                    for k in 0..indices.len().saturating_sub(2) {
                        if k % 2 == 0 {
                            push(indices[k], indices[k + 1], indices[k + 2]);
                        } else {
                            push(indices[k], indices[k + 2], indices[k + 1]);
                        }
                    }
                }
                Mode::TriangleFan => {
                    for k in 1..indices.len().saturating_sub(1) {
                        push(indices[k], indices[k + 1], indices[0]);
                    }
                }
                _ => {}
            }
            self.stats.faces_read += self.triangles.len() - before;
        }
        Ok(())
    }
}

/// How [`read_accessor`] reads integer components.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Integers {
    /// Normalized where the accessor says so (positions).
    AsFlagged,
    /// As the integers they are, whatever the accessor's `normalized` flag (indices).
    Raw,
}

/// The components of `accessor` as `f64`, `count × components` flat, with bounds checked
/// against the buffers, byte strides followed, normalized integers mapped to [0, 1] or [-1, 1]
/// (with [`Integers::AsFlagged`]) and sparse substitutions applied.
fn read_accessor(
    accessor: &::gltf::Accessor,
    buffers: &[Vec<u8>],
    integers: Integers,
) -> std::result::Result<Vec<f64>, String> {
    let a = accessor.index();
    let ty = accessor.data_type();
    let csize = ty.size();
    let dims = accessor.dimensions().multiplicity();
    let elem = csize * dims;
    let count = accessor.count();
    let normalized = accessor.normalized() && integers == Integers::AsFlagged;
    let too_big = || format!("accessor {a} is larger than its buffer");

    let mut out = match accessor.view() {
        Some(view) => {
            let data = view_bytes(&view, buffers)?;
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                return Err(format!(
                    "accessor {a}: buffer view {} has a byte stride of {stride}, less than \
                     the element size {elem}",
                    view.index()
                ));
            }
            let offset = accessor.offset();
            if count > 0 {
                let end = stride
                    .checked_mul(count - 1)
                    .and_then(|x| x.checked_add(offset))
                    .and_then(|x| x.checked_add(elem))
                    .ok_or_else(too_big)?;
                if end > data.len() {
                    return Err(format!(
                        "accessor {a} reads bytes {offset}..{end} of buffer view {}, which has \
                         {} bytes",
                        view.index(),
                        data.len()
                    ));
                }
            }
            let mut out = Vec::with_capacity(count * dims);
            for i in 0..count {
                let start = offset + i * stride;
                for c in 0..dims {
                    out.push(component(&data[start + c * csize..], ty, normalized));
                }
            }
            out
        }
        None => {
            if count.saturating_mul(dims) > MAX_VIEWLESS_COMPONENTS {
                return Err(format!(
                    "accessor {a} has no buffer view and {count} elements"
                ));
            }
            vec![0.0; count * dims]
        }
    };

    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        let indices = sparse.indices();
        let isize = indices.index_type().size();
        let idata = view_bytes(&indices.view(), buffers)?;
        let ioff = indices.offset();
        let values = sparse.values();
        let vdata = view_bytes(&values.view(), buffers)?;
        let voff = values.offset();
        let fits = |off: usize, size: usize, len: usize| {
            n.checked_mul(size)
                .and_then(|x| x.checked_add(off))
                .is_some_and(|end| end <= len)
        };
        if !fits(ioff, isize, idata.len()) || !fits(voff, elem, vdata.len()) {
            return Err(format!(
                "accessor {a}: sparse data is larger than its buffer views"
            ));
        }
        for k in 0..n {
            let at = &idata[ioff + k * isize..];
            let i = match isize {
                1 => usize::from(at[0]),
                2 => usize::from(u16::from_le_bytes([at[0], at[1]])),
                _ => u32::from_le_bytes([at[0], at[1], at[2], at[3]]) as usize,
            };
            if i >= count {
                return Err(format!(
                    "accessor {a}: sparse index {i} is out of range for {count} elements"
                ));
            }
            for c in 0..dims {
                out[i * dims + c] =
                    component(&vdata[voff + k * elem + c * csize..], ty, normalized);
            }
        }
    }
    Ok(out)
}

/// The bytes of a buffer view, bounds-checked against its buffer.
fn view_bytes<'b>(
    view: &::gltf::buffer::View,
    buffers: &'b [Vec<u8>],
) -> std::result::Result<&'b [u8], String> {
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or_else(|| format!("buffer view {} names a missing buffer", view.index()))?;
    view.offset()
        .checked_add(view.length())
        .and_then(|end| buffer.get(view.offset()..end))
        .ok_or_else(|| {
            format!(
                "buffer view {} (bytes {}..+{}) lies outside buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                buffer.len()
            )
        })
}

/// One component at the start of `b` (which holds at least its size), little endian.
fn component(b: &[u8], ty: DataType, normalized: bool) -> f64 {
    match ty {
        DataType::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        DataType::U32 => {
            let v = f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
            if normalized {
                v / f64::from(u32::MAX)
            } else {
                v
            }
        }
        DataType::U16 => {
            let v = f64::from(u16::from_le_bytes([b[0], b[1]]));
            if normalized {
                v / 65535.0
            } else {
                v
            }
        }
        DataType::I16 => {
            let v = f64::from(i16::from_le_bytes([b[0], b[1]]));
            if normalized {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        DataType::U8 => {
            let v = f64::from(b[0]);
            if normalized {
                v / 255.0
            } else {
                v
            }
        }
        DataType::I8 => {
            let v = f64::from(b[0] as i8);
            if normalized {
                (v / 127.0).max(-1.0)
            } else {
                v
            }
        }
    }
}

/// The nodes' local transforms read from the file's JSON in `f64` (`None` where a node's
/// fields are not the numbers the specification asks for, which validation has refused already):
/// the `matrix` as stored, or `translation`, `rotation` and `scale` composed as T · R · S (glTF
/// 2.0 Sec. 3.5.3; the stored quaternion normalized). The `gltf` crate parses them into `f32`,
/// each number rounded by up to half its unit in the last place (2e-6 for a translation of 50):
/// faces of two nodes that touch or lie apart in the file came apart or into each other by that
/// much (mode5.gltf, whose matrices are written with 16 digits: 1704 crossing pairs read, where
/// trimesh reading the same numbers in `f64` finds 1120, and we now 1117). `json` is the file's
/// JSON (a GLB's JSON chunk).
fn node_transforms(json: &[u8]) -> Vec<Option<DMat4>> {
    let Ok(value) = serde_json::from_slice::<serde_json::Value>(json) else {
        return Vec::new();
    };
    let numbers = |v: Option<&serde_json::Value>, n: usize| -> Option<Vec<f64>> {
        let a = v?.as_array()?;
        (a.len() == n)
            .then(|| {
                a.iter()
                    .map(serde_json::Value::as_f64)
                    .collect::<Option<Vec<f64>>>()
            })
            .flatten()
    };
    let Some(nodes) = value.get("nodes").and_then(|n| n.as_array()) else {
        return Vec::new();
    };
    nodes
        .iter()
        .map(|node| {
            if node.get("matrix").is_some() {
                let m = numbers(node.get("matrix"), 16)?;
                return Some(DMat4::from_cols_slice(&m));
            }
            let or = |key: &str, n: usize, default: &[f64]| match node.get(key) {
                None => Some(default.to_vec()),
                v => numbers(v, n),
            };
            let t = or("translation", 3, &[0.0; 3])?;
            let r = or("rotation", 4, &[0.0, 0.0, 0.0, 1.0])?;
            let s = or("scale", 3, &[1.0; 3])?;
            let q = glam::DQuat::from_xyzw(r[0], r[1], r[2], r[3]);
            let q = if q.length_squared() > 0.0 {
                q.normalize()
            } else {
                glam::DQuat::IDENTITY
            };
            Some(DMat4::from_scale_rotation_translation(
                DVec3::from_slice(&s),
                q,
                DVec3::from_slice(&t),
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn invalid(r: std::result::Result<Vec<u8>, BufferError>) -> String {
        match r {
            Err(BufferError::Invalid(m)) => m,
            Err(BufferError::Io(e)) => panic!("an I/O error: {e}"),
            Ok(b) => panic!("decoded {b:?}"),
        }
    }

    #[test]
    fn data_uris_base64_with_or_without_padding_and_percent_encoded() {
        let ok = |uri: &str| decode_data_uri(uri).ok().unwrap();
        assert_eq!(
            ok("data:application/octet-stream;base64,AAEC/w=="),
            [0, 1, 2, 255]
        );
        assert_eq!(
            ok("data:application/octet-stream;base64,AAEC/w"),
            [0, 1, 2, 255]
        );
        assert_eq!(ok("data:;base64,"), Vec::<u8>::new());
        assert_eq!(
            ok("data:application/octet-stream,a%00b%FF"),
            [b'a', 0, b'b', 255]
        );
        assert!(invalid(decode_data_uri("data:;base64,A*==")).contains("base64"));
        assert!(invalid(decode_data_uri("data:nothing")).contains("comma"));
    }

    #[test]
    fn buffer_files_by_percent_encoded_relative_path_or_file_uri() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a b.bin"), [7u8, 8]).unwrap();
        let read = |uri: &str| read_uri(dir.path(), uri, 1 << 20).ok().unwrap();
        assert_eq!(read("a%20b.bin"), [7, 8]);
        let absolute = format!("file://{}/a%20b.bin", dir.path().display());
        assert_eq!(read(&absolute), [7, 8]);
        assert!(invalid(read_uri(dir.path(), "%FF%FE.bin", 4)).contains("UTF-8"));
        assert!(invalid(read_uri(dir.path(), "https://example.org/a.bin", 4)).contains("scheme"));
        assert!(matches!(
            read_uri(dir.path(), "missing.bin", 4),
            Err(BufferError::Io(_))
        ));
    }
}
