//! Buffer and image URIs: `data:` URIs decoded, relative paths resolved and kept under the root,
//! everything else refused with its reason.

use std::path::{Component, Path, PathBuf};

use super::{QUOTE_CHARS, read_bounded};

/// A URI shortened for a message.
pub(super) fn quote_uri(uri: &str) -> String {
    if uri.chars().count() > QUOTE_CHARS {
        let cut: String = uri.chars().take(QUOTE_CHARS - 3).collect();
        format!("{cut}...")
    } else {
        uri.to_owned()
    }
}

/// Why a URI cannot be followed: (what is wrong, what to do).
pub(super) type UriRefusal = (String, String);

pub(super) const EMBED_OR_BESIDE: &str =
    "embed the data as a data: URI, or put the file in the mesh's folder and give a relative uri";

/// Bytes of a `data:` URI (base64 only, as glTF writes them).
pub(super) fn data_uri(uri: &str) -> std::result::Result<Vec<u8>, UriRefusal> {
    let rest = &uri["data:".len()..];
    let Some(comma) = rest.find(',') else {
        return Err((
            "is a data: URI without a comma before its data".into(),
            "write it as data:application/octet-stream;base64,<data>".into(),
        ));
    };
    if !rest[..comma].ends_with(";base64") {
        return Err((
            "is a data: URI that is not base64".into(),
            "write it as data:application/octet-stream;base64,<data>".into(),
        ));
    }
    decode_base64(&rest[comma + 1..]).ok_or_else(|| {
        (
            "is a data: URI whose base64 data is not valid".into(),
            "re-export the file, or check that the data was not cut or altered".into(),
        )
    })
}

/// Standard base64 with optional padding; ASCII whitespace is skipped.
pub(super) fn decode_base64(text: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    let mut padding = 0;
    for b in text.bytes() {
        let v = match b {
            b'A'..=b'Z' => b - b'A',
            b'a'..=b'z' => b - b'a' + 26,
            b'0'..=b'9' => b - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => {
                padding += 1;
                continue;
            }
            b if b.is_ascii_whitespace() => continue,
            _ => return None,
        };
        if padding > 0 {
            return None;
        }
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    (padding <= 2).then_some(out)
}

/// `%XX` escapes decoded (glTF URIs are URI references).
pub(super) fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// The file a relative URI names, checked to lie under `root` (canonical).
pub(super) fn resolve_file(
    uri: &str,
    folder: &Path,
    root: &Path,
) -> std::result::Result<PathBuf, UriRefusal> {
    let decoded = percent_decode(uri).ok_or_else(|| {
        (
            "has a malformed %-escape or is not UTF-8".to_owned(),
            "write it as a relative path with %XX escapes".to_owned(),
        )
    })?;
    if decoded.is_empty() || decoded.contains('\0') {
        return Err((
            "is empty or holds a NUL character".into(),
            EMBED_OR_BESIDE.into(),
        ));
    }
    let as_path = Path::new(&decoded);
    let absolute = decoded.starts_with('/')
        || decoded.starts_with('\\')
        || as_path.is_absolute()
        || as_path
            .components()
            .any(|c| matches!(c, Component::Prefix(_) | Component::RootDir));
    if absolute {
        return Err((
            "is an absolute path, and a mesh may read only files under its allowed folder".into(),
            EMBED_OR_BESIDE.into(),
        ));
    }
    let outside = |path: &Path| {
        (
            format!(
                "leads to {}, outside {}, the only folder this mesh may read from",
                path.display(),
                root.display()
            ),
            EMBED_OR_BESIDE.to_owned(),
        )
    };
    // First without touching the file system: `..` that climbs out of the root is refused whether
    // or not its target exists, so answers tell nothing about files outside the root.
    let folder = folder.canonicalize().map_err(|e| {
        (
            format!(
                "is relative to {}, which cannot be opened ({e})",
                folder.display()
            ),
            "check the mesh's folder".to_owned(),
        )
    })?;
    let mut lexical = PathBuf::new();
    for c in folder.join(as_path).components() {
        match c {
            Component::ParentDir => {
                lexical.pop();
            }
            Component::CurDir => {}
            other => lexical.push(other),
        }
    }
    if !lexical.starts_with(root) {
        return Err(outside(&lexical));
    }
    // Then through the file system: a symbolic link inside the root may still lead out of it.
    let canonical = lexical.canonicalize().map_err(|e| {
        (
            format!("names {}, which cannot be opened ({e})", lexical.display()),
            "put the file there or fix the uri".to_owned(),
        )
    })?;
    if !canonical.starts_with(root) {
        return Err(outside(&canonical));
    }
    Ok(canonical)
}

/// A URI that has a scheme (`file:`, `http:`), as opposed to a relative reference.
pub(super) fn scheme(uri: &str) -> Option<&str> {
    let colon = uri.find(':')?;
    let head = &uri[..colon];
    let is_scheme = head.len() > 1
        && head.starts_with(|c: char| c.is_ascii_alphabetic())
        && head
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    is_scheme.then_some(head)
}

/// Check (and for buffers, read) one URI.
pub(super) fn follow_uri(
    uri: &str,
    files: Option<(&Path, &Path)>,
    read: bool,
) -> std::result::Result<Option<Vec<u8>>, UriRefusal> {
    if uri.starts_with("data:") {
        return if read {
            data_uri(uri).map(Some)
        } else {
            Ok(None)
        };
    }
    if let Some(s) = scheme(uri) {
        return Err((
            format!("has the scheme {s}:, and only relative paths and data: URIs are read"),
            EMBED_OR_BESIDE.into(),
        ));
    }
    let Some((folder, root)) = files else {
        return Err((
            "names a file, and this mesh was given as bytes with no folder to read files from"
                .into(),
            "embed the data as a data: URI or a GLB binary chunk".into(),
        ));
    };
    let file = resolve_file(uri, folder, root)?;
    if !read {
        return Ok(None);
    }
    read_bounded(&file).map(Some).map_err(|(reason, _)| {
        (
            format!("names {}, which {reason}", file.display()),
            "fix the file or the uri".to_owned(),
        )
    })
}
