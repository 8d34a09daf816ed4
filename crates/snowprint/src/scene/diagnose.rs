//! Turning byte spans into `file:line:` messages, and TOML/serde errors into sentences that say what
//! to do.

use std::fmt::Display;
use std::ops::Range;
use std::path::Path;

use crate::error::SnowError;

use super::raw::TABLES;

/// The text of a scene file and the name to print for it.
pub(super) struct Source<'a> {
    text: &'a str,
    file: String,
}

impl<'a> Source<'a> {
    pub(super) fn new(text: &'a str, path: &Path) -> Self {
        Self {
            text,
            file: path.display().to_string(),
        }
    }

    /// 1-based line of a byte offset.
    pub(super) fn line(&self, offset: usize) -> usize {
        let end = offset.min(self.text.len());
        self.text.as_bytes()[..end]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    }

    /// The source text of a span, on one line and at most about 60 characters, as the user wrote it.
    pub(super) fn quote(&self, span: &Range<usize>) -> String {
        let raw = self.text.get(span.clone()).unwrap_or("");
        let one_line = raw.split_whitespace().collect::<Vec<_>>().join(" ");
        if one_line.chars().count() > 60 {
            let cut: String = one_line.chars().take(57).collect();
            format!("{cut}...")
        } else {
            one_line
        }
    }

    /// `<file>:<line of span>: <what>; <todo>`.
    pub(super) fn error(
        &self,
        span: &Range<usize>,
        what: impl Display,
        todo: impl Display,
    ) -> SnowError {
        self.error_at_line(self.line(span.start), what, todo)
    }

    /// `<file>:<line>: <what>; <todo>`.
    pub(super) fn error_at_line(
        &self,
        line: usize,
        what: impl Display,
        todo: impl Display,
    ) -> SnowError {
        SnowError::Scene(format!("{}:{line}: {what}; {todo}", self.file))
    }

    /// The key whose value (or a part of it) starts at `offset`: the last `key =` on the same line
    /// before it, or the last component of a `[table]` / `[[table]]` header that starts there.
    fn key_before(&self, offset: usize) -> Option<KeyAt> {
        let head = self.text.get(..offset)?;
        let tail = self.text.get(offset..)?;
        let line_start = head.rfind('\n').map_or(0, |i| i + 1);
        let before = &head[line_start..];
        if let Some(eq) = before.rfind('=') {
            let key = before[..eq].trim_end();
            let start = key
                .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'))
                .map_or(0, |i| i + 1);
            let key = &key[start..];
            let kind = if before[eq + 1..].trim().is_empty() {
                KeyKind::Value
            } else {
                KeyKind::Inside
            };
            return (!key.is_empty()).then(|| KeyAt {
                key: key.to_owned(),
                kind,
            });
        }
        let rest = tail.lines().next().unwrap_or("").trim();
        if rest.starts_with('[') {
            let name = rest.trim_start_matches('[');
            let name = &name[..name.find(']').unwrap_or(name.len())];
            let last = name.rsplit('.').next().unwrap_or(name).trim();
            return (!last.is_empty()).then(|| KeyAt {
                key: last.to_owned(),
                kind: KeyKind::Header,
            });
        }
        None
    }
}

/// Where a value with the wrong type sits.
enum KeyKind {
    /// Right after `key =`.
    Value,
    /// Inside the value of `key =` (an array element or an inline table's field).
    Inside,
    /// A `[key]` header.
    Header,
}

/// The key a value belongs to.
struct KeyAt {
    key: String,
    kind: KeyKind,
}

/// What a key's value must look like, and an example line, for messages about wrong types.
fn expectation(key: &str) -> Option<(&'static str, &'static str)> {
    Some(match key {
        "version" => ("the integer 1", "version = 1"),
        "capture" => (
            "a table",
            "a line [capture] followed by lines such as mode = \"depth\"",
        ),
        "surface" => (
            "a list of [[surface]] tables",
            "[[surface]] (two brackets) above the keys of each surface",
        ),
        "deformer" => (
            "a list of [[deformer]] tables",
            "[[deformer]] (two brackets) above the keys of each deformer",
        ),
        "budget" => (
            "a table",
            "a line [budget] followed by lines such as updates_per_frame = 2",
        ),
        "camera" => (
            "a table",
            "a line [camera] followed by target = [x, y, z] and keys = [{ t = 0.0, eye = [x, y, z] }]",
        ),
        "updates_per_frame" => ("a whole number of surfaces", "updates_per_frame = 2"),
        "pool_bytes" => ("a whole number of bytes", "pool_bytes = 2097152"),
        "active_distance" => ("a number of metres", "active_distance = 40.0"),
        "precision_bits" => ("the whole number 8, 16 or 32", "precision_bits = 16"),
        "zone" => ("a whole number", "zone = 1"),
        "player" => ("true or false", "player = true"),
        "target" => ("an array of 3 numbers", "target = [0.0, 6.0, 0.0]"),
        "fov_y_degrees" => ("a number of degrees", "fov_y_degrees = 50.0"),
        "eye" => ("an array of 3 numbers", "eye = [-12.0, 14.0, -12.0]"),
        "mode" => ("a string", "mode = \"depth\" or mode = \"mask\""),
        "ankle_height" => ("a number of metres", "ankle_height = 0.25"),
        "mask_depth" => ("a number", "mask_depth = 1.0"),
        "name" => ("a string", "name = \"roof\""),
        "center" => ("an array of 3 numbers", "center = [0.0, 10.0, 0.0]"),
        "size" => ("an array of 2 numbers", "size = [8.0, 6.0]"),
        "yaw_degrees" => ("a number of degrees", "yaw_degrees = 0.0"),
        "snow_depth" => ("a number of metres", "snow_depth = 0.3"),
        "replenish_rate" => ("a number", "replenish_rate = 0.0"),
        "material" => ("a string", "material = \"sand\""),
        "like" => ("a string", "like = \"sand\""),
        "repose_degrees" => ("a number of degrees", "repose_degrees = 34.0"),
        "relax_steps" => ("a whole number", "relax_steps = 8"),
        "settle_updates" => ("a whole number", "settle_updates = 120"),
        "compressibility" => ("a number from 0 to 1", "compressibility = 0.2"),
        "albedo" => ("an array of 3 numbers", "albedo = [0.5, 0.38, 0.24]"),
        "disturbed_albedo" => (
            "an array of 3 numbers",
            "disturbed_albedo = [0.6, 0.47, 0.31]",
        ),
        "roughness" => ("a number from 0 to 1", "roughness = 0.88"),
        "wet_roughness" => ("a number from 0 to 1", "wet_roughness = 0.3"),
        "grain" => ("a number from 0 to 1", "grain = 0.8"),
        "sparkle" => ("a number from 0 to 1", "sparkle = 0.8"),
        "wetness" => ("a number from 0 to 1", "wetness = 0.6"),
        "translucency" => ("a number from 0 to 1", "translucency = 0.0"),
        "water_depth" => ("a number of metres", "water_depth = 0.06"),
        "ground_from" => ("a number from 0 to 1", "ground_from = 0.92"),
        "shape" => ("a string", "shape = \"sphere\""),
        "radius" => ("a number of metres", "radius = 0.06"),
        "half_height" => ("a number of metres", "half_height = 0.08"),
        "half_extents" => ("an array of 3 numbers", "half_extents = [0.1, 0.05, 0.15]"),
        "path" => ("a string", "path = \"boot.glb\""),
        "keys" => (
            "an array of key tables",
            "keys = [ { t = 0.0, position = [0.0, 10.3, 0.0] } ], or as [[deformer.keys]] tables",
        ),
        "t" => ("a number of seconds", "t = 0.0"),
        "position" => ("an array of 3 numbers", "position = [0.0, 10.3, 0.0]"),
        "rotation_degrees" => (
            "an array of 3 numbers",
            "rotation_degrees = [90.0, 0.0, 0.0]",
        ),
        _ => return None,
    })
}

/// serde's name of an expected type, in plain words.
fn plain(expected: &str) -> &str {
    match expected {
        "f64" | "f32" => "a number",
        "i64" | "u32" | "i32" | "u64" => "an integer",
        "a sequence" => "an array",
        "a string" => "a string",
        "map" | "a map" => "a table",
        other if other.starts_with("struct ") => "a table",
        other => other,
    }
}

/// Words between backticks, in order.
fn backticked(msg: &str) -> Vec<&str> {
    msg.split('`').skip(1).step_by(2).collect()
}

/// Levenshtein distance, for "did you mean".
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diag = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (diag + usize::from(ca != cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diag = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// A list as prose: `a, b and c`.
fn prose(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => (*one).to_owned(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// One sentence for a TOML syntax error or a serde error raised while reading the file.
pub(super) fn toml_error(src: &Source<'_>, e: &toml::de::Error) -> SnowError {
    let span = e.span().unwrap_or(0..0);
    let line = src.line(span.start);
    let msg = e.message().trim();

    if msg.starts_with("unknown field") {
        let words = backticked(msg);
        if let Some((&key, expected)) = words.split_first() {
            let table = TABLES
                .iter()
                .find(|(_, fields)| *fields == expected)
                .map(|(name, _)| *name);
            let Some(table) = table else {
                return src.error_at_line(
                    line,
                    format!("unknown key \"{key}\""),
                    "remove it or fix its spelling (see docs/SCENES.md)",
                );
            };
            let what = format!("unknown key \"{key}\" {table}");
            let allowed = format!("the keys allowed there are {}", prose(expected));
            let homes: Vec<&str> = TABLES
                .iter()
                .filter(|(_, f)| f.contains(&key))
                .map(|(place, _)| *place)
                .collect();
            if homes == ["at the top level"] {
                return src.error_at_line(
                    line,
                    what,
                    format!("\"{key}\" belongs at the top level, so move it above the first [table] line"),
                );
            }
            if !homes.is_empty() {
                return src.error_at_line(
                    line,
                    what,
                    format!("\"{key}\" belongs {}, so move it there", homes.join(" or ")),
                );
            }
            let close = expected
                .iter()
                .map(|k| (distance(key, k), *k))
                .filter(|&(d, k)| {
                    d <= 2.max(k.len() / 3)
                        || (key.len() >= 3 && (k.starts_with(key) || key.starts_with(k)))
                })
                .min();
            return match close {
                Some((_, k)) => {
                    src.error_at_line(line, what, format!("did you mean \"{k}\"? ({allowed})"))
                }
                None => src.error_at_line(line, what, format!("remove it ({allowed})")),
            };
        }
    }

    if let Some(rest) = msg.strip_prefix("invalid type: ") {
        let found = match rest.split(", expected").next().unwrap_or(rest) {
            "map" => "a table",
            "sequence" => "an array",
            other => other,
        };
        if let Some(at) = src.key_before(span.start) {
            if let Some((want, example)) = expectation(&at.key) {
                let key = &at.key;
                let quote = src.quote(&span);
                let what = match at.kind {
                    KeyKind::Header => format!("the table {quote} is not {want} (found {found})"),
                    KeyKind::Value => format!("{key} = {quote} is not {want} (found {found})"),
                    KeyKind::Inside => {
                        let expected = rest.split(", expected ").nth(1).map_or(want, plain);
                        format!("{key} holds {quote}, which is {found} where {expected} belongs")
                    }
                };
                return src.error_at_line(line, what, format!("write it like {example}"));
            }
        }
        return src.error_at_line(
            line,
            format!("a value has the wrong type: {msg}"),
            "fix it as docs/SCENES.md describes",
        );
    }

    if msg.starts_with("missing field") {
        let key = backticked(msg).first().copied().unwrap_or("?");
        return src.error_at_line(
            line,
            format!("the table here has no \"{key}\""),
            format!("add {key} = ... (see docs/SCENES.md)"),
        );
    }

    if msg.starts_with("invalid length") {
        // A table written as an array (`budget = []`): serde speaks of "struct RawBudget with 4
        // elements", which means nothing to the user.
        if let Some(at) = src.key_before(span.start)
            && let Some((want, example)) = expectation(&at.key)
            && want == "a table"
        {
            let key = &at.key;
            return src.error_at_line(
                line,
                format!(
                    "{key} = {} is not {want} (found an array)",
                    src.quote(&span)
                ),
                format!("write it as {example}"),
            );
        }
    }

    if msg.starts_with("invalid value") || msg.starts_with("invalid length") {
        return src.error_at_line(
            line,
            format!("a value cannot be used ({msg}): {}", src.quote(&span)),
            "fix it as docs/SCENES.md describes",
        );
    }

    // Everything else is a syntax error from the TOML parser.
    let near = src.quote(&span);
    let near = if near.is_empty() {
        String::new()
    } else {
        format!(" (at {near})")
    };
    src.error_at_line(
        line,
        format!("this is not valid TOML: {msg}{near}"),
        "fix the syntax (strings in double quotes, arrays in [ ], one key = value per line)",
    )
}
