//! glTF and GLB loading for mesh deformers, for files that may come from an untrusted mod.
//!
//! Only the triangles' positions are read. The loader never follows a buffer or image URI out of
//! the folder it was given (`root`): a relative URI is resolved against the file's folder, made
//! canonical (which follows `..` and symbolic links) and must still lie under the canonical root;
//! absolute paths and URIs with a scheme other than `data:` are refused. Node hierarchies are
//! checked to be trees before they are walked (a cycle would otherwise never end), and the sizes of
//! everything read are bounded ([`MAX_GLTF_NODES`] and the other limits below), so that a hostile
//! file gets one sentence, never a hang, a panic or unbounded memory.
//!
//! Accessors are read here, with checked arithmetic, rather than through the `gltf` crate's
//! reader, whose offset arithmetic assumes valid counts and strides.

use std::io::Read;
use std::path::{Path, PathBuf};

use glam::Mat4;

use super::Mesh;
use crate::error::{Result, SnowError};

pub(crate) mod accessors;
#[cfg(test)]
mod tests;
mod uri;

use accessors::{read_indices, read_positions};
use uri::{UriRefusal, follow_uri, quote_uri};

/// Most nodes a glTF file may have.
pub const MAX_GLTF_NODES: usize = 65_536;
/// Deepest node hierarchy accepted: a root node has depth 1.
pub const MAX_GLTF_DEPTH: usize = 128;
/// Most vertices a loaded mesh may have, counting each node that instances a mesh once more.
pub const MAX_GLTF_VERTICES: usize = 1 << 22;
/// Most triangles a loaded mesh may have, counting each node that instances a mesh once more.
pub const MAX_GLTF_TRIANGLES: usize = 1 << 22;
/// Largest glTF or GLB file, and largest external buffer file, that is read, bytes.
pub const MAX_GLTF_FILE_BYTES: u64 = 256 << 20;

/// The longest URI quoted in a message, characters (a data: URI can be megabytes).
pub(super) const QUOTE_CHARS: usize = 60;

impl Mesh {
    /// Load every triangle primitive of a glTF or GLB file, with node transforms applied, into one
    /// mesh in the file's frame (metres, +Y up as glTF defines). External buffers are read only
    /// from the file's own folder and below; `data:` URIs and a GLB's binary chunk are always fine.
    ///
    /// # Errors
    ///
    /// [`SnowError::MeshFile`] when the file cannot be read or is not a usable glTF (nodes that do
    /// not form trees, sizes beyond [`MAX_GLTF_NODES`] and the other limits, accessors that do not
    /// fit their buffers), [`SnowError::MeshUri`] for a URI that leads outside the folder,
    /// [`SnowError::InvalidMesh`] for out-of-range indices or non-finite positions.
    pub fn load_gltf(path: &Path) -> Result<Mesh> {
        let folder = parent_folder(path);
        Self::load_gltf_within(path, &folder)
    }

    /// As [`Mesh::load_gltf`], but the file and every external file it names must lie under
    /// `root` (for a scene: the scene file's folder), after `..` and symbolic links are followed.
    ///
    /// # Errors
    ///
    /// As [`Mesh::load_gltf`]; also [`SnowError::MeshFile`] when `path` itself is outside `root`.
    pub fn load_gltf_within(path: &Path, root: &Path) -> Result<Mesh> {
        let (bytes, folder, root) = read_within(path, root)?;
        parse(&bytes, path, Some((&folder, &root)))
    }

    /// Load a glTF or GLB file given as bytes. `name` names it in messages. `files` is `None` to read
    /// no file at all (only `data:` URIs and a GLB's binary chunk), or `(folder, root)`: relative
    /// URIs are resolved against `folder` and must lead to files under `root`.
    ///
    /// # Errors
    ///
    /// As [`Mesh::load_gltf`].
    pub fn from_gltf_slice(
        bytes: &[u8],
        name: &Path,
        files: Option<(&Path, &Path)>,
    ) -> Result<Mesh> {
        let files = canonical_files(name, files)?;
        parse(
            bytes,
            name,
            files.as_ref().map(|(f, r)| (f.as_path(), r.as_path())),
        )
    }
}

/// A glTF or GLB file that must lie under `root`: its bytes, its (canonical) folder and the
/// canonical root, for the readers of meshes and of skinned meshes.
pub(crate) fn read_within(path: &Path, root: &Path) -> Result<(Vec<u8>, PathBuf, PathBuf)> {
    let err = |reason: String, source: Option<std::io::Error>| SnowError::MeshFile {
        path: path.to_owned(),
        reason,
        source,
    };
    let canonical_root = canonical_folder(root).map_err(|e| {
        let reason = format!(
            "its allowed folder {} cannot be opened ({e}); check that the folder exists",
            root.display()
        );
        err(reason, Some(e))
    })?;
    let canonical = path.canonicalize().map_err(|e| {
        let reason = format!("cannot be opened ({e}); check the path and that the file exists");
        err(reason, Some(e))
    })?;
    if !canonical.starts_with(&canonical_root) {
        return Err(err(
            format!(
                "lies outside {}, the only folder meshes may be read from here; move the file into that folder",
                canonical_root.display()
            ),
            None,
        ));
    }
    let bytes = read_bounded(&canonical).map_err(|(reason, source)| err(reason, source))?;
    Ok((bytes, parent_folder(&canonical), canonical_root))
}

/// The folder of a file, `.` for a bare file name.
fn parent_folder(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    }
}

fn canonical_folder(root: &Path) -> std::io::Result<PathBuf> {
    if root.as_os_str().is_empty() {
        Path::new(".").canonicalize()
    } else {
        root.canonicalize()
    }
}

/// Why a file could not be read: a sentence, and the I/O error where there is one.
pub(super) type ReadFailure = (String, Option<std::io::Error>);

/// A whole file, refused beyond [`MAX_GLTF_FILE_BYTES`].
pub(super) fn read_bounded(path: &Path) -> std::result::Result<Vec<u8>, ReadFailure> {
    let io = |e: std::io::Error, what: &str, fix: &str| (format!("{what} ({e}); {fix}"), Some(e));
    let file = std::fs::File::open(path)
        .map_err(|e| io(e, "cannot be opened", "check the path and its permissions"))?;
    let meta = file
        .metadata()
        .map_err(|e| io(e, "cannot be read", "check the path and its permissions"))?;
    if !meta.is_file() {
        return Err((
            "is not a file; give the path of a glTF (.gltf) or GLB (.glb) file".into(),
            None,
        ));
    }
    if meta.len() > MAX_GLTF_FILE_BYTES {
        return Err((
            format!(
                "is {} bytes, more than the {MAX_GLTF_FILE_BYTES} bytes a mesh file may have; simplify the mesh",
                meta.len()
            ),
            None,
        ));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(MAX_GLTF_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| io(e, "cannot be read", "check the file"))?;
    if bytes.len() as u64 > MAX_GLTF_FILE_BYTES {
        return Err((
            format!(
                "is more than the {MAX_GLTF_FILE_BYTES} bytes a mesh file may have; simplify the mesh"
            ),
            None,
        ));
    }
    Ok(bytes)
}

/// The canonical form of `files`' root (see [`Mesh::from_gltf_slice`]).
pub(crate) fn canonical_files(
    name: &Path,
    files: Option<(&Path, &Path)>,
) -> Result<Option<(PathBuf, PathBuf)>> {
    let Some((folder, root)) = files else {
        return Ok(None);
    };
    let root = canonical_folder(root).map_err(|e| SnowError::MeshFile {
        path: name.to_owned(),
        reason: format!(
            "its allowed folder {} cannot be opened ({e}); check that the folder exists",
            root.display()
        ),
        source: Some(e),
    })?;
    Ok(Some((folder.to_owned(), root)))
}

/// A [`SnowError::MeshFile`] without an I/O source.
pub(crate) fn file_error(path: &Path, reason: String) -> SnowError {
    SnowError::MeshFile {
        path: path.to_owned(),
        reason,
        source: None,
    }
}

/// Parse a glTF or GLB file, validate it and read its buffers (bounded, URIs kept under the root).
pub(crate) fn open(
    bytes: &[u8],
    path: &Path,
    files: Option<(&Path, &Path)>,
) -> Result<(gltf::Document, Vec<Vec<u8>>)> {
    let err = |reason: String| file_error(path, reason);
    let not_gltf = |e: &dyn std::fmt::Display| {
        let e = e.to_string();
        let e = e.split_whitespace().collect::<Vec<_>>().join(" ");
        err(format!(
            "is not a valid glTF or GLB file ({e}); export it again as glTF 2.0"
        ))
    };
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| not_gltf(&e))?;
    validate(gltf.document.as_json()).map_err(|e| not_gltf(&e))?;
    let doc = &gltf.document;
    let uri_err = |what: String, uri: &str, (problem, fix): UriRefusal| SnowError::MeshUri {
        path: path.to_owned(),
        what,
        uri: quote_uri(uri),
        problem,
        fix,
    };

    // Images are never decoded, but a URI that leads outside the folder is refused all the same:
    // a file from an untrusted mod that names /etc/passwd is not a mesh to use.
    // (Read from the JSON: `gltf::Image::source` unwraps, and panics on an image with neither a
    // uri nor a bufferView, or a bufferView without a mimeType, which validation lets through.)
    for (i, image) in doc.as_json().images.iter().enumerate() {
        if let Some(uri) = &image.uri {
            follow_uri(uri, files, false).map_err(|r| uri_err(format!("image {i}"), uri, r))?;
        }
    }
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    let mut total: u64 = 0;
    for buffer in doc.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| {
                err(format!(
                    "buffer {} has no uri and the file has no GLB binary chunk; give the buffer a uri or save the file as GLB",
                    buffer.index()
                ))
            })?,
            gltf::buffer::Source::Uri(uri) => follow_uri(uri, files, true)
                .map_err(|r| uri_err(format!("buffer {}", buffer.index()), uri, r))?
                .unwrap_or_default(),
        };
        if (data.len() as u64) < buffer.length() as u64 {
            return Err(err(format!(
                "buffer {} holds {} bytes, fewer than its byteLength {}; fix the byteLength or the data",
                buffer.index(),
                data.len(),
                buffer.length()
            )));
        }
        total += data.len() as u64;
        if total > MAX_GLTF_FILE_BYTES {
            return Err(err(format!(
                "has more than {MAX_GLTF_FILE_BYTES} bytes of buffers; simplify the mesh"
            )));
        }
        buffers.push(data);
    }

    Ok((gltf.document, buffers))
}

fn parse(bytes: &[u8], path: &Path, files: Option<(&Path, &Path)>) -> Result<Mesh> {
    let err = |reason: String| file_error(path, reason);
    let (doc, buffers) = open(bytes, path, files)?;
    let doc = &doc;
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| err("has no scene; add a scene listing the mesh's nodes".into()))?;
    check_node_trees(doc).map_err(err)?;

    let mut mesh = Mesh::default();
    let mut visited = vec![false; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        // Trees were checked, so a node is met twice only when a scene lists it twice or lists a
        // node and one of its ancestors.
        let seen = &mut visited[node.index()];
        if *seen {
            return Err(err(format!(
                "scene {} reaches node {} twice (it lists the node, or one of its ancestors, more than once); list each node tree once",
                scene.index(),
                node.index()
            )));
        }
        *seen = true;
        let m = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(gm) = node.mesh() {
            for prim in gm.primitives() {
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    continue;
                }
                let Some(positions) = prim.get(&gltf::Semantic::Positions) else {
                    continue;
                };
                let what = format!("mesh {} primitive {}", gm.index(), prim.index());
                let pos = read_positions(&positions, &buffers)
                    .map_err(|e| err(format!("{what}: its POSITION accessor {e}")))?;
                let n = pos.len();
                let indices = match prim.indices() {
                    Some(a) => read_indices(&a, &buffers)
                        .map_err(|e| err(format!("{what}: its index accessor {e}")))?,
                    None => (0..n as u32).collect(),
                };
                if let Some(&i) = indices.iter().find(|&&i| i as usize >= n) {
                    return Err(err(format!(
                        "{what} has index {i}, out of range for its {n} vertices; fix the indices"
                    )));
                }
                let base = mesh.positions.len();
                if base + n > MAX_GLTF_VERTICES
                    || (mesh.indices.len() + indices.len()) / 3 > MAX_GLTF_TRIANGLES
                {
                    return Err(err(format!(
                        "holds more than {MAX_GLTF_VERTICES} vertices or {MAX_GLTF_TRIANGLES} triangles (counting every node that instances a mesh); simplify the mesh"
                    )));
                }
                mesh.positions
                    .extend(pos.into_iter().map(|p| m.transform_point3(p)));
                let first = mesh.indices.len();
                mesh.indices
                    .extend(indices.into_iter().map(|i| base as u32 + i));
                // A mirroring transform flips the winding; keep triangles outward-facing.
                if m.determinant() < 0.0 {
                    for tri in mesh.indices[first..].chunks_exact_mut(3) {
                        tri.swap(1, 2);
                    }
                }
            }
        }
        stack.extend(node.children().map(|c| (c, m)));
    }
    if mesh.indices.is_empty() {
        return Err(err(
            "holds no triangles; give it a mesh with a triangle primitive".into(),
        ));
    }
    mesh.validate(&path.display().to_string())?;
    Ok(mesh)
}

/// The `gltf` crate's validation, after the check its primitive hook skips: that hook indexes the
/// accessors with the POSITION attribute unchecked, and panics on an index out of range.
fn validate(root: &gltf::json::Root) -> std::result::Result<(), String> {
    use gltf::json::validation::{Checked, Validate};
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if let Some(a) = prim
                .attributes
                .get(&Checked::Valid(gltf::json::mesh::Semantic::Positions))
                && a.value() >= root.accessors.len()
            {
                return Err(format!(
                    "mesh {m} primitive {p} names POSITION accessor {}, but there are {} accessors",
                    a.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    let mut first = None;
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        if first.is_none() {
            first = Some(format!("{}: {error}", path()));
        }
    });
    first.map_or(Ok(()), Err)
}

/// Nodes form trees: no node is its own child or ancestor, none has two parents, none lies deeper
/// than [`MAX_GLTF_DEPTH`], and there are at most [`MAX_GLTF_NODES`].
pub(crate) fn check_node_trees(doc: &gltf::Document) -> std::result::Result<(), String> {
    let n = doc.nodes().len();
    if n > MAX_GLTF_NODES {
        return Err(format!(
            "has {n} nodes, more than the {MAX_GLTF_NODES} a mesh file may have; merge nodes or simplify the file"
        ));
    }
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for node in doc.nodes() {
        let p = node.index();
        for child in node.children() {
            let c = child.index();
            if c == p {
                return Err(format!(
                    "node {p} lists itself as its child, a cycle; glTF nodes must form trees, so remove that child"
                ));
            }
            if let Some(q) = parent[c] {
                return Err(format!(
                    "node {c} is a child of both node {q} and node {p}; glTF nodes must form trees, so give each node one parent"
                ));
            }
            parent[c] = Some(p);
        }
    }
    // Depth of every node, from its parent chain; `depth[i] == 0` is not yet known.
    let mut depth = vec![0usize; n];
    let mut on_path = vec![false; n];
    let mut path = Vec::new();
    for start in 0..n {
        let mut at = start;
        // Walk up to a node of known depth or a root, stopping at a cycle or too deep a chain.
        let known = loop {
            if depth[at] != 0 {
                break depth[at];
            }
            if on_path[at] {
                return Err(format!(
                    "node {at} is its own ancestor, a cycle of child links; glTF nodes must form trees, so remove the child link that closes the loop"
                ));
            }
            if path.len() > MAX_GLTF_DEPTH {
                return Err(format!(
                    "node {start} lies more than {MAX_GLTF_DEPTH} levels deep; flatten the node hierarchy"
                ));
            }
            on_path[at] = true;
            path.push(at);
            match parent[at] {
                Some(p) => at = p,
                None => break 0,
            }
        };
        for (k, &node) in path.iter().rev().enumerate() {
            depth[node] = known + k + 1;
            on_path[node] = false;
        }
        if depth[start] > MAX_GLTF_DEPTH {
            return Err(format!(
                "node {start} lies {} levels deep, more than {MAX_GLTF_DEPTH}; flatten the node hierarchy",
                depth[start]
            ));
        }
        path.clear();
    }
    Ok(())
}
