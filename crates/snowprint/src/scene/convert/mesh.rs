//! A mesh deformer's file: resolved within the scene's folder and loaded.

use std::path::{Path, PathBuf};

use crate::error::{Result, SnowError};
use crate::mesh::Mesh;
use crate::scene::SceneShape;
use crate::scene::diagnose::Source;
use crate::scene::raw::Str;
use crate::skin::SkinnedMesh;

/// Resolve and load a mesh deformer's file.
pub(super) fn mesh(src: &Source<'_>, path: &Str, who: &str, dir: &Path) -> Result<SceneShape> {
    let (resolved, root) = resolve(src, path, who, dir)?;
    let mesh = Mesh::load_gltf_within(&resolved, &root)
        .map_err(|e| load_error(src, path, who, &resolved, e))?;
    Ok(SceneShape::Mesh {
        path: resolved,
        mesh,
    })
}

/// Resolve and load an animated mesh deformer's file as a skinned mesh.
pub(super) fn skinned_mesh(
    src: &Source<'_>,
    path: &Str,
    who: &str,
    dir: &Path,
) -> Result<SkinnedMesh> {
    let (resolved, root) = resolve(src, path, who, dir)?;
    SkinnedMesh::load_gltf_within(&resolved, &root)
        .map_err(|e| load_error(src, path, who, &resolved, e))
}

/// A mesh path resolved against the scene's folder and checked to stay under it: the file and the
/// folder it may read from.
pub(super) fn resolve(
    src: &Source<'_>,
    path: &Str,
    who: &str,
    dir: &Path,
) -> Result<(PathBuf, PathBuf)> {
    let span = path.span();
    let written = path.get_ref();
    if written.trim().is_empty() {
        return Err(src.error(
            &span,
            format!("{who} has the empty path {}", src.quote(&span)),
            "set path to a glTF or GLB file, relative to the scene file's folder",
        ));
    }
    let resolved = dir.join(written);
    let folder = if dir.as_os_str().is_empty() {
        "the current folder".to_owned()
    } else {
        dir.display().to_string()
    };
    // A scene may come from an untrusted mod: it and its meshes read only under its own folder.
    let root = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let outside = || {
        src.error(
            &span,
            format!(
                "{who} has path {}, which leads outside the scene file's folder ({folder})",
                src.quote(&span)
            ),
            "a scene may read only files under its own folder, so copy the mesh there and give a path relative to the scene",
        )
    };
    // First as written, without asking the file system (so the answer for a path out of the
    // folder is the same whether its target exists): the path with its `..` resolved on the
    // folder's canonical form must stay under it.
    // (A folder that does not exist, as for a scene given as text, is taken as written.)
    let canonical_root = root
        .canonicalize()
        .or_else(|_| std::path::absolute(root))
        .unwrap_or_else(|_| root.to_path_buf());
    let mut lexical = canonical_root.clone();
    for c in Path::new(written.as_str()).components() {
        match c {
            std::path::Component::ParentDir => {
                lexical.pop();
            }
            std::path::Component::CurDir => {}
            other => lexical.push(other),
        }
    }
    if !lexical.starts_with(&canonical_root) {
        return Err(outside());
    }
    if !resolved.is_file() {
        let problem = if resolved.exists() {
            "is not a file"
        } else {
            "does not exist"
        };
        return Err(src.error(
            &span,
            format!(
                "{who} has path {}, but {} {problem}",
                src.quote(&span),
                resolved.display()
            ),
            format!(
                "mesh paths are relative to the scene file's folder ({folder}), so put the file there or fix the path"
            ),
        ));
    }
    // Then through the file system: a symbolic link inside the folder may lead out of it.
    let inside = resolved
        .canonicalize()
        .is_ok_and(|file| file.starts_with(&canonical_root));
    if !inside {
        return Err(outside());
    }
    Ok((resolved, root.to_path_buf()))
}

/// The loader's error as the scene's sentence, at the path's line.
pub(super) fn load_error(
    src: &Source<'_>,
    path: &Str,
    who: &str,
    resolved: &Path,
    e: SnowError,
) -> SnowError {
    let span = path.span();
    if let SnowError::MeshUri {
        what,
        uri,
        problem,
        fix,
        ..
    } = &e
    {
        return src.error(
            &span,
            format!(
                "{who} has path {}, but in {} {what} has uri {uri:?}, which {problem}",
                src.quote(&span),
                resolved.display()
            ),
            fix.replace("the mesh's folder", "the scene's folder"),
        );
    }
    let reason = match e {
        SnowError::MeshFile { reason, .. } | SnowError::InvalidMesh { reason, .. } => reason,
        other => other.to_string(),
    };
    let reason = reason.split_whitespace().collect::<Vec<_>>().join(" ");
    // The loader's reasons end with what to do after "; ": make that the hint.
    let (reason, fix) = match reason.split_once("; ") {
        Some((reason, fix)) => (reason.to_owned(), fix.to_owned()),
        None => (
            reason,
            "give it a valid glTF (.gltf) or GLB (.glb) file holding a closed triangle mesh"
                .to_owned(),
        ),
    };
    src.error(
        &span,
        format!(
            "{who} has path {}, but {} cannot be used as a mesh ({reason})",
            src.quote(&span),
            resolved.display()
        ),
        fix,
    )
}
