//! The library's layout rules, checked on its sources: no source file above [`MAX_FILE_LINES`]
//! lines, no function body above [`MAX_FN_LINES`] lines, and no import circle between the
//! library's top-level modules (`accumulate`, `capture`, `world`, `pool`, `render`, `manager`,
//! `scene`, `mesh`, ...). A file, function or import that must break a rule is listed below as an
//! exception, with its reason; an exception that is no longer needed fails the test too, so the
//! list only shrinks.
//!
//! The sources are read as text: comments, strings and character literals are blanked first
//! (keeping every line), then braces are counted. That is enough for this code base, and the
//! scanner is checked on hand-written snippets below.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Most lines in one source file of the library.
const MAX_FILE_LINES: usize = 800;
/// Most lines in one function body, from the line of its `{` to the line of its `}`.
const MAX_FN_LINES: usize = 150;

/// Files allowed above [`MAX_FILE_LINES`]: (path under `src/`, lines allowed, why).
const FILE_EXCEPTIONS: &[(&str, usize, &str)] = &[];

/// Functions allowed above [`MAX_FN_LINES`]: (path under `src/`, function, lines allowed, why).
const FN_EXCEPTIONS: &[(&str, &str, usize, &str)] = &[];

/// Imports allowed to close a circle: (from module, to module, why).
const IMPORT_EXCEPTIONS: &[(&str, &str, &str)] = &[];

fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Every `.rs` file under `dir`, sorted, as (path relative to `src/`, text).
fn rust_files(dir: &Path) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).expect("read a source folder") {
            let path = entry.expect("read a folder entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(src_dir()).expect("under src/");
                let text = std::fs::read_to_string(&path).expect("read a source file");
                out.push((rel.to_string_lossy().replace('\\', "/"), text));
            }
        }
    }
    out.sort();
    out
}

/// The source with comments, string literals and character literals replaced by spaces; newlines
/// are kept, so that line numbers stay true. Lifetimes (`'a`) are left as they are.
fn blank(src: &str) -> String {
    let c: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let keep_lines = |out: &mut String, s: &[char]| {
        for &ch in s {
            out.push(if ch == '\n' { '\n' } else { ' ' });
        }
    };
    let ident = |ch: char| ch.is_alphanumeric() || ch == '_';
    let mut i = 0;
    while i < c.len() {
        let at = |k: usize| c.get(i + k).copied().unwrap_or('\0');
        // Line comment.
        if at(0) == '/' && at(1) == '/' {
            let end = (i..c.len()).find(|&k| c[k] == '\n').unwrap_or(c.len());
            keep_lines(&mut out, &c[i..end]);
            i = end;
            continue;
        }
        // Block comment, nested as Rust nests them.
        if at(0) == '/' && at(1) == '*' {
            let (mut k, mut depth) = (i + 2, 1);
            while k < c.len() && depth > 0 {
                if c[k] == '/' && c.get(k + 1) == Some(&'*') {
                    depth += 1;
                    k += 2;
                } else if c[k] == '*' && c.get(k + 1) == Some(&'/') {
                    depth -= 1;
                    k += 2;
                } else {
                    k += 1;
                }
            }
            keep_lines(&mut out, &c[i..k]);
            i = k;
            continue;
        }
        // Raw string: r"..", r#".."#, br#".."# (not the end of an identifier such as `bar"`).
        let prev_ident = i > 0 && ident(c[i - 1]);
        let r_at = if at(0) == 'r' {
            Some(0)
        } else if at(0) == 'b' && at(1) == 'r' {
            Some(1)
        } else {
            None
        };
        if let (false, Some(r)) = (prev_ident, r_at) {
            let mut k = i + r + 1;
            let mut hashes = 0;
            while c.get(k) == Some(&'#') {
                hashes += 1;
                k += 1;
            }
            if c.get(k) == Some(&'"') {
                let mut end = k + 1;
                while end < c.len() {
                    if c[end] == '"' && (1..=hashes).all(|h| c.get(end + h) == Some(&'#')) {
                        end += 1 + hashes;
                        break;
                    }
                    end += 1;
                }
                keep_lines(&mut out, &c[i..end.min(c.len())]);
                i = end;
                continue;
            }
        }
        // String (a `b` or `c` prefix stays as an identifier character).
        if at(0) == '"' {
            let mut k = i + 1;
            while k < c.len() && c[k] != '"' {
                k += if c[k] == '\\' { 2 } else { 1 };
            }
            let end = (k + 1).min(c.len());
            keep_lines(&mut out, &c[i..end]);
            i = end;
            continue;
        }
        // Character literal ('x', '\n', '\u{7f}', '{'), told from a lifetime ('a).
        if at(0) == '\'' {
            let end = if at(1) == '\\' {
                (i + 3..c.len()).find(|&k| c[k] == '\'').map(|k| k + 1)
            } else if at(2) == '\'' {
                Some(i + 3)
            } else {
                None
            };
            if let Some(end) = end {
                keep_lines(&mut out, &c[i..end]);
                i = end;
                continue;
            }
        }
        out.push(c[i]);
        i += 1;
    }
    out
}

/// Line (from 1) of each char index of `text`.
fn line_of(text: &str, index: usize) -> usize {
    text[..index].matches('\n').count() + 1
}

/// The index of the `}` that closes the `{` at `open`, in blanked text.
fn closing(text: &[u8], open: usize) -> Option<usize> {
    let mut depth = 0usize;
    for (k, &b) in text.iter().enumerate().skip(open) {
        match b {
            b'{' => depth += 1,
            b'}' => {
                depth -= 1;
                if depth == 0 {
                    return Some(k);
                }
            }
            _ => {}
        }
    }
    None
}

/// A function with a body: its name, the line of `fn`, and the lines its body spans.
#[derive(Debug, PartialEq)]
struct Function {
    name: String,
    line: usize,
    body_lines: usize,
}

/// Every function with a body in blanked text (nested ones too). A signature ends at its `{`, or
/// at a `;` outside brackets (a declaration without a body, as in a trait).
fn functions(blanked: &str) -> Vec<Function> {
    let b = blanked.as_bytes();
    let ident = |x: u8| x.is_ascii_alphanumeric() || x == b'_';
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(k) = blanked[i..].find("fn") {
        let at = i + k;
        i = at + 2;
        if (at > 0 && ident(b[at - 1])) || b.get(at + 2).is_none_or(|&x| !x.is_ascii_whitespace()) {
            continue;
        }
        let name: String = blanked[at + 2..]
            .trim_start()
            .chars()
            .take_while(|&ch| ch.is_alphanumeric() || ch == '_')
            .collect();
        if name.is_empty() {
            continue;
        }
        let mut depth = 0i32;
        let mut open = None;
        for (j, &x) in b.iter().enumerate().skip(at) {
            match x {
                b'(' | b'[' => depth += 1,
                b')' | b']' => depth -= 1,
                b';' if depth == 0 => break,
                b'{' if depth == 0 => {
                    open = Some(j);
                    break;
                }
                _ => {}
            }
        }
        let Some(open) = open else { continue };
        let Some(close) = closing(b, open) else {
            continue;
        };
        out.push(Function {
            name,
            line: line_of(blanked, at),
            body_lines: line_of(blanked, close) - line_of(blanked, open) + 1,
        });
    }
    out
}

/// Blanked text with every item under `#[cfg(test)]` blanked too (its `{...}` or up to its `;`).
fn without_test_items(blanked: &str) -> String {
    let mut b = blanked.as_bytes().to_vec();
    let mut from = 0;
    while let Some(k) = String::from_utf8_lossy(&b[from..]).find("#[cfg(test)]") {
        let at = from + k;
        from = at + 1;
        let semi = b[at..].iter().position(|&x| x == b';').map(|p| at + p);
        let brace = b[at..].iter().position(|&x| x == b'{').map(|p| at + p);
        let end = match (brace, semi) {
            (Some(o), Some(s)) if s < o => s,
            (Some(o), _) => closing(&b, o).unwrap_or(b.len() - 1),
            (None, Some(s)) => s,
            (None, None) => b.len() - 1,
        };
        for x in &mut b[at..=end] {
            if *x != b'\n' {
                *x = b' ';
            }
        }
    }
    String::from_utf8(b).expect("blanking keeps ASCII positions")
}

/// The library's top-level modules, from `mod` lines in `lib.rs`.
fn top_modules(lib: &str) -> Vec<String> {
    blank(lib)
        .lines()
        .filter_map(|l| {
            let l = l
                .trim()
                .trim_start_matches("pub ")
                .trim_start_matches("pub(crate) ");
            let name = l.strip_prefix("mod ")?.trim_end_matches(';').trim();
            Some(name.to_string())
        })
        .collect()
}

/// Names re-exported at the crate root (`pub use world::{SnowWorld, ...};`) and their module, so
/// that `crate::SnowWorld` counts as a use of `world`.
fn root_reexports(lib: &str, modules: &[String]) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for stmt in blank(lib).split(';') {
        let Some(path) = stmt.trim().strip_prefix("pub use ") else {
            continue;
        };
        let module: String = path
            .chars()
            .take_while(|&c| c.is_alphanumeric() || c == '_')
            .collect();
        if !modules.contains(&module) {
            continue;
        }
        // The names that end a path or follow `as`: the last word before `,`, `}` or the end.
        let mut words: Vec<(usize, &str)> = Vec::new();
        let mut start = None;
        for (k, ch) in path.char_indices().chain([(path.len(), ' ')]) {
            let w = ch.is_alphanumeric() || ch == '_';
            match (w, start) {
                (true, None) => start = Some(k),
                (false, Some(s)) => {
                    words.push((k, &path[s..k]));
                    start = None;
                }
                _ => {}
            }
        }
        for (end, word) in words {
            let next = path[end..].trim_start().chars().next();
            if matches!(next, None | Some(',') | Some('}')) && word != module {
                out.insert(word.to_string(), module.clone());
            }
        }
    }
    out
}

/// The top-level module a file under `src/` belongs to (`None` for `lib.rs`).
fn module_of(path: &str) -> Option<String> {
    let first = path.split('/').next()?;
    let name = first.trim_end_matches(".rs");
    (name != "lib").then(|| name.to_string())
}

/// The items of a `{...}` import group, split at its own commas only (`a::{X, Y}, b` is two).
fn top_level_items(group: &str) -> Vec<String> {
    let (mut items, mut depth, mut start) = (Vec::new(), 0, 0);
    for (k, ch) in group.char_indices() {
        match ch {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(group[start..k].trim().to_string());
                start = k + 1;
            }
            _ => {}
        }
    }
    items.push(group[start..].trim().to_string());
    items
}

/// One `crate::` reference from one module to another.
#[derive(Clone, Debug)]
struct Edge {
    at: String,
    text: String,
}

/// The modules each module reaches through `crate::<module>` (or `crate::<re-exported name>`),
/// outside tests: (from, to) -> first place it happens.
fn import_graph(
    files: &[(String, String)],
    modules: &[String],
    reexports: &BTreeMap<String, String>,
) -> BTreeMap<(String, String), Edge> {
    let mut edges = BTreeMap::new();
    for (path, text) in files {
        let Some(from) = module_of(path) else {
            continue;
        };
        if path.ends_with("/tests.rs") || path == "tests.rs" {
            continue;
        }
        let code = without_test_items(&blank(text));
        let mut i = 0;
        while let Some(k) = code[i..].find("crate::") {
            let at = i + k;
            i = at + 7;
            if at > 0 && {
                let p = code.as_bytes()[at - 1];
                p.is_ascii_alphanumeric() || p == b'_'
            } {
                continue;
            }
            let rest = &code[at + 7..];
            // `crate::{a::X, b}` names several modules at once.
            let group = if rest.starts_with('{') {
                let close = closing(rest.as_bytes(), 0).unwrap_or(rest.len() - 1);
                top_level_items(&rest[1..close])
            } else {
                vec![rest.to_string()]
            };
            for item in group {
                let name: String = item
                    .chars()
                    .take_while(|&c| c.is_alphanumeric() || c == '_')
                    .collect();
                let to = if modules.contains(&name) {
                    name
                } else if let Some(m) = reexports.get(&name) {
                    m.clone()
                } else {
                    continue;
                };
                if to == from {
                    continue;
                }
                let line = line_of(&code, at);
                let text = text.lines().nth(line - 1).unwrap_or("").trim().to_string();
                edges.entry((from.clone(), to)).or_insert(Edge {
                    at: format!("src/{path}:{line}"),
                    text,
                });
            }
        }
    }
    edges
}

/// The groups of modules that reach each other (two or more, sorted), each with the shortest
/// circle through each of its modules, as closed lists (first = last), without repeats.
fn circles(edges: &BTreeSet<(String, String)>) -> Vec<(Vec<String>, Vec<Vec<String>>)> {
    let nodes: BTreeSet<&String> = edges.iter().flat_map(|(a, b)| [a, b]).collect();
    let reach = |from: &String| {
        let mut seen = BTreeSet::from([from.clone()]);
        let mut stack = vec![from.clone()];
        while let Some(n) = stack.pop() {
            for (a, b) in edges {
                if *a == n && seen.insert(b.clone()) {
                    stack.push(b.clone());
                }
            }
        }
        seen
    };
    let mut done: BTreeSet<String> = BTreeSet::new();
    let mut out = Vec::new();
    for &n in &nodes {
        if done.contains(n) {
            continue;
        }
        let group: BTreeSet<String> = reach(n)
            .into_iter()
            .filter(|m| reach(m).contains(n))
            .collect();
        done.extend(group.iter().cloned());
        if group.len() < 2 {
            continue;
        }
        let mut found: Vec<Vec<String>> = Vec::new();
        let mut seen: BTreeSet<Vec<String>> = BTreeSet::new();
        for m in &group {
            let circle = shortest_circle(edges, &group, m);
            // The same circle found from another of its modules: compare as sorted edges.
            let mut key: Vec<String> = circle.windows(2).map(|w| w.join(">")).collect();
            key.sort();
            if seen.insert(key) {
                found.push(circle);
            }
        }
        out.push((group.into_iter().collect(), found));
    }
    out
}

/// The shortest way from `n` back to `n` inside `group` (breadth first), as a closed list.
fn shortest_circle(
    edges: &BTreeSet<(String, String)>,
    group: &BTreeSet<String>,
    n: &String,
) -> Vec<String> {
    let mut prev: BTreeMap<String, String> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([n.clone()]);
    let mut last = None;
    'walk: while let Some(m) = queue.pop_front() {
        for (a, b) in edges {
            if *a != m || !group.contains(b) {
                continue;
            }
            if b == n {
                last = Some(m.clone());
                break 'walk;
            }
            if !prev.contains_key(b) {
                prev.insert(b.clone(), m.clone());
                queue.push_back(b.clone());
            }
        }
    }
    let mut path = vec![n.clone()];
    let mut m = last.expect("every module of a group lies on a circle");
    while m != *n {
        path.push(m.clone());
        m = prev[&m].clone();
    }
    path.push(n.clone());
    path.reverse();
    path
}

#[test]
fn no_source_file_is_too_long() {
    let mut problems = Vec::new();
    let mut used = BTreeSet::new();
    for (path, text) in rust_files(&src_dir()) {
        let lines = text.lines().count();
        let allowed = match FILE_EXCEPTIONS.iter().find(|e| e.0 == path) {
            Some(e) => {
                used.insert(e.0);
                e.1
            }
            None => MAX_FILE_LINES,
        };
        if lines > allowed {
            problems.push(format!(
                "src/{path} has {lines} lines (at most {allowed}): split it into a folder with one \
                 file a concern (unit tests may go to a tests.rs beside it)"
            ));
        }
    }
    for e in FILE_EXCEPTIONS.iter().filter(|e| !used.contains(e.0)) {
        problems.push(format!(
            "FILE_EXCEPTIONS names src/{}, which no longer exists: remove the exception",
            e.0
        ));
    }
    assert!(problems.is_empty(), "\n{}\n", problems.join("\n"));
}

#[test]
fn no_function_is_too_long() {
    let mut problems = Vec::new();
    let mut used = BTreeSet::new();
    for (path, text) in rust_files(&src_dir()) {
        for f in functions(&blank(&text)) {
            let exception = FN_EXCEPTIONS.iter().find(|e| e.0 == path && e.1 == f.name);
            let allowed = exception.map_or(MAX_FN_LINES, |e| e.2);
            if let Some(e) = exception {
                used.insert((e.0, e.1));
            }
            if f.body_lines > allowed {
                problems.push(format!(
                    "src/{path}:{} fn {} has a body of {} lines (at most {allowed}): give its \
                     steps names as functions of their own",
                    f.line, f.name, f.body_lines
                ));
            }
        }
    }
    for e in FN_EXCEPTIONS.iter().filter(|e| !used.contains(&(e.0, e.1))) {
        problems.push(format!(
            "FN_EXCEPTIONS names fn {} in src/{}, which no longer exists: remove the exception",
            e.1, e.0
        ));
    }
    assert!(problems.is_empty(), "\n{}\n", problems.join("\n"));
}

#[test]
fn no_import_circle_between_modules() {
    let lib = std::fs::read_to_string(src_dir().join("lib.rs")).expect("read lib.rs");
    let modules = top_modules(&lib);
    assert!(
        modules.iter().any(|m| m == "manager") && modules.iter().any(|m| m == "world"),
        "the module list read from lib.rs looks wrong: {modules:?}"
    );
    let reexports = root_reexports(&lib, &modules);
    let graph = import_graph(&rust_files(&src_dir()), &modules, &reexports);
    let allowed: BTreeSet<(String, String)> = IMPORT_EXCEPTIONS
        .iter()
        .map(|e| (e.0.to_string(), e.1.to_string()))
        .collect();
    let edges: BTreeSet<(String, String)> = graph
        .keys()
        .filter(|e| !allowed.contains(*e))
        .cloned()
        .collect();
    let mut problems = Vec::new();
    for (group, found) in circles(&edges) {
        let mut text = format!(
            "import circle between {}: each of them reaches the others",
            group.join(", ")
        );
        for circle in found {
            text += &format!("\n  {}", circle.join(" -> "));
            for w in circle.windows(2) {
                let e = &graph[&(w[0].clone(), w[1].clone())];
                text += &format!("\n    {} -> {} at {}: {}", w[0], w[1], e.at, e.text);
            }
        }
        text += "\n  break the circles: move what both sides need into a lower module (or a \
                 module of its own), or pass it in as data from the caller";
        problems.push(text);
    }
    for e in IMPORT_EXCEPTIONS {
        if !graph.contains_key(&(e.0.to_string(), e.1.to_string())) {
            problems.push(format!(
                "IMPORT_EXCEPTIONS allows {} -> {}, which no longer happens: remove the exception",
                e.0, e.1
            ));
        }
    }
    assert!(problems.is_empty(), "\n{}\n", problems.join("\n"));
}

// The scanner itself, on snippets written by hand.

#[test]
fn blanking_keeps_lines_and_hides_braces_in_strings_chars_and_comments() {
    let src =
        "fn a() { let s = \"}{\"; let c = '{'; // }\n /* { /* } */ } */ let r = r#\"}\"#; }\n";
    let b = blank(src);
    assert_eq!(b.lines().count(), src.lines().count());
    assert_eq!(b.len(), src.len());
    assert_eq!(b.matches('{').count(), 1, "{b}");
    assert_eq!(b.matches('}').count(), 1, "{b}");
    // Lifetimes are not character literals; escaped quotes do not end a string.
    let b = blank("fn f<'a>(x: &'a str) -> char { let q = \"\\\"{\"; '\\'' }");
    assert!(b.contains("<'a>(x: &'a str)"), "{b}");
    assert_eq!(b.matches('{').count(), 1, "{b}");
    assert_eq!(b.matches('}').count(), 1, "{b}");
}

#[test]
fn functions_are_measured_from_brace_to_brace() {
    let src = "\
trait T {
    fn declared(&self, x: [u8; 4]);
}
fn outer(
    x: u32,
) -> u32 {
    let s = \"fn fake() {\";
    fn inner() {
    }
    x
}
struct S { f: fn(u32) -> u32 }
";
    let found = functions(&blank(src));
    assert_eq!(
        found,
        vec![
            Function {
                name: "outer".into(),
                line: 4,
                body_lines: 6
            },
            Function {
                name: "inner".into(),
                line: 8,
                body_lines: 2
            },
        ]
    );
}

#[test]
fn test_items_are_left_out_of_the_import_graph() {
    let code = "use crate::a::X;\n#[cfg(test)]\nmod tests {\n    use crate::b::Y;\n}\n#[cfg(test)]\nuse crate::c::Z;\nfn f() { crate::d::g() }\n";
    let kept = without_test_items(&blank(code));
    assert!(
        kept.contains("crate::a") && kept.contains("crate::d"),
        "{kept}"
    );
    assert!(
        !kept.contains("crate::b") && !kept.contains("crate::c"),
        "{kept}"
    );
    assert_eq!(kept.lines().count(), code.lines().count());
}

#[test]
fn circles_are_found_and_reported_with_their_edges() {
    let modules: Vec<String> = ["a", "b", "c", "d"].map(String::from).to_vec();
    let lib = "pub mod a;\npub mod b;\npub use c::{Thing, deep::Other as Renamed};\n";
    let reexports = root_reexports(lib, &modules);
    assert_eq!(reexports.get("Thing").map(String::as_str), Some("c"));
    assert_eq!(reexports.get("Renamed").map(String::as_str), Some("c"));
    let files = vec![
        // `Thing` inside `b::{...}` is b's own, not the root's re-export from c.
        (
            "a/mod.rs".to_string(),
            "use crate::{b::{X, Thing}, d};\n".to_string(),
        ),
        (
            "b.rs".to_string(),
            "fn f() {}\nuse crate::Thing;\n".to_string(),
        ),
        (
            "c/x.rs".to_string(),
            "// crate::a in a comment\nuse crate::a::Y;\n".to_string(),
        ),
        ("c/tests.rs".to_string(), "use crate::d::Z;\n".to_string()),
        (
            "d.rs".to_string(),
            "#[cfg(test)]\nuse crate::a::Y;\n".to_string(),
        ),
    ];
    let graph = import_graph(&files, &modules, &reexports);
    let edges: BTreeSet<(String, String)> = graph.keys().cloned().collect();
    let names: Vec<(&str, &str)> = edges
        .iter()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    assert_eq!(names, [("a", "b"), ("a", "d"), ("b", "c"), ("c", "a")]);
    assert_eq!(graph[&("b".into(), "c".into())].at, "src/b.rs:2");
    let found = circles(&edges);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, ["a", "b", "c"]);
    assert_eq!(found[0].1, [vec!["a", "b", "c", "a"]]);
}
